"""The report opened in a real browser (headless Chromium): figures decoded, table laid out, page not blank."""

import re
import shutil
import subprocess

import pytest

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
pytestmark = pytest.mark.skipif(CHROMIUM is None, reason="needs Debian's chromium (`.ci/run` installs it when missing)")

PROBE = """<script>
window.addEventListener('load', () => {
  const imgs = [...document.images];
  const ok = imgs.filter(i => i.complete && i.naturalWidth > 0).length;
  const table = document.getElementById('fit-table');
  const rows = table ? table.querySelectorAll('tbody tr').length : 0;
  const height = table ? Math.round(table.getBoundingClientRect().height) : 0;
  const width = document.documentElement.clientWidth;
  const widest = Math.max(...[...document.querySelectorAll('table')].map(t => Math.ceil(t.getBoundingClientRect().right)));
  const version = (document.getElementById('hwpts-version') || {}).textContent || '';
  const created = (document.getElementById('created') || {}).textContent || '';
  document.body.setAttribute('data-probe', `images=${ok}/${imgs.length};rows=${rows};table_height=${height};` +
    `widest=${widest};width=${width};scroll=${document.documentElement.scrollWidth};version=${version};created=${created}`);
});
</script>"""

FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--hide-scrollbars", "--virtual-time-budget=10000"]


def _chromium(tmp_path, *args):
    profile = tmp_path / "profile"
    return subprocess.run([CHROMIUM, *FLAGS, f"--user-data-dir={profile}", *args],
                          capture_output=True, text=True, timeout=120)


def test_report_renders_its_figures_and_table(quick_run, tmp_path):
    page = tmp_path / "report.html"
    page.write_text((quick_run / "report.html").read_text().replace("</body>", PROBE + "</body>"))
    dom = _chromium(tmp_path, "--window-size=1000,1600", "--dump-dom", page.as_uri()).stdout
    probe = re.search(r'data-probe="images=(\d+)/(\d+);rows=(\d+);table_height=(\d+);widest=(\d+);width=(\d+);'
                      r'scroll=(\d+);version=([^;]*);created=([^"]*)"', dom)
    assert probe, "the page did not finish loading"
    loaded, total, rows, height, widest, width, scroll = map(int, probe.groups()[:7])
    version, created = probe.groups()[7:]
    assert total == 9 and loaded == total, "a figure failed to decode"
    assert rows >= 6 and height > 100
    assert widest <= width and scroll <= width, f"a table is wider than the page ({widest} px > {width} px)"
    from hwpts import __version__

    assert version == __version__ and re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", created)


def test_report_screenshot_is_not_blank(quick_run, tmp_path):
    import matplotlib.image as mpimg

    shot = tmp_path / "shot.png"
    _chromium(tmp_path, f"--screenshot={shot}", "--window-size=1200,2400", (quick_run / "report.html").as_uri())
    assert shot.exists(), "chromium wrote no screenshot"
    pixels = mpimg.imread(shot)[..., :3]
    assert pixels.shape[0] >= 2000 and pixels.shape[1] >= 1100
    assert pixels.std() > 0.05  # text, table and figures, not a blank page
    assert (pixels.mean(axis=2) < 0.5).mean() > 0.005  # some dark ink
