"""Figures and the HTML report of ``hwpts control run`` (from recorded loop signals; never simulates)."""

from __future__ import annotations

import base64
import html

import numpy as np

from hwpts.reporting.figures import _png, _pyplot
from hwpts.reporting.html import _run_line

METRIC_LABELS = (
    ("rms_error_percent", "RMS error [%]", "{:.3f}"),
    ("max_error_percent", "max error [%]", "{:.2f}"),
    ("within_1_percent_share", "within ±1 %", "{:.3f}"),
    ("within_0_5_percent_share", "within ±0.5 %", "{:.3f}"),
    ("settling_time_s", "settling [s]", "{:.2f}"),
    ("overshoot_percent", "overshoot [%]", "{:.1f}"),
    ("peak_deviation_percent", "peak dev. [%]", "{:.2f}"),
    ("recovery_time_s", "recovery [s]", "{:.2f}"),
    ("valve_travel_v", "valve travel [V]", "{:.0f}"),
    ("valve_reversals", "reversals", "{:d}"),
    ("mode_switches_per_min", "switches/min", "{:.1f}"),
)


def _fmt(value, spec):
    if value is None:
        return "-"
    return spec.format(value)


def metric_table(summary: dict) -> str:
    """The metric table as plain text (the README shows it)."""
    head = ["controller"] + [label for _, label, _ in METRIC_LABELS] + ["step ms med/max"]
    rows = []
    for name, m in summary["controllers"].items():
        st = m["step_time_ms"]
        rows.append([name] + [_fmt(m[key], spec) for key, _, spec in METRIC_LABELS]
                    + [f"{st['median']:.3f}/{st['max']:.2f}"])
    widths = [max(len(r[i]) for r in [head] + rows) for i in range(len(head))]
    line = lambda r: "  ".join(c.ljust(w) if i == 0 else c.rjust(w) for i, (c, w) in enumerate(zip(r, widths)))
    return "\n".join([line(head), "-" * len(line(head))] + [line(r) for r in rows])


def loop_figure(runs: dict, title: str, window=None) -> bytes:
    """One column per controller: speed, valve command and its compensated version, pump speed, region."""
    plt = _pyplot()
    n = len(runs)
    fig, axes = plt.subplots(4, n, figsize=(3.6 * n + 1, 8.5), sharex=True, squeeze=False,
                             gridspec_kw={"height_ratios": [3, 2, 1.5, 1]})
    for j, (name, cols) in enumerate(runs.items()):
        t = cols["time_s"]
        sel = slice(None) if window is None else (t >= window[0]) & (t <= window[1])
        ax = axes[0, j]
        ax.plot(t[sel], cols["motor_a_speed_rpm"][sel], color="tab:blue", lw=0.8, label="motor A speed")
        ax.plot(t[sel], cols["setpoint_rpm"][sel], color="k", ls="--", lw=0.8, label="set-point")
        sp = cols["setpoint_rpm"][sel]
        ax.fill_between(t[sel], sp * 0.99, sp * 1.01, color="tab:green", alpha=0.15, lw=0, label="±1 %")
        unreach = cols["reachable"][sel] < 0.5
        if unreach.any():
            lo, hi = np.nanmin(cols["motor_a_speed_rpm"][sel]), np.nanmax(cols["motor_a_speed_rpm"][sel])
            ax.fill_between(t[sel], lo, hi, where=unreach, color="tab:red", alpha=0.08, lw=0, label="out of reach")
        ax.set_title(name, fontsize=10)
        if window is not None:
            ax.set_ylim(float(np.min(sp)) * 0.96, float(np.max(sp)) * 1.04)
        if j == 0:
            ax.set_ylabel("speed [r/min]")
            ax.legend(fontsize=7, loc="lower left")
        ax = axes[1, j]
        ax.plot(t[sel], cols["valve_command_v"][sel], color="tab:orange", lw=0.7, label="command")
        ax.plot(t[sel], cols["valve_compensated_v"][sel], color="tab:purple", lw=0.7, label="compensated (play output)")
        if j == 0:
            ax.set_ylabel("valve [V]")
            ax.legend(fontsize=7, loc="upper left")
        ax = axes[2, j]
        ax.plot(t[sel], cols["pump_speed_command_rpm"][sel], color="tab:gray", lw=0.7, label="command")
        ax.plot(t[sel], cols["pump_speed_rpm"][sel], color="tab:brown", lw=0.7, label="actual")
        if j == 0:
            ax.set_ylabel("pump [r/min]")
            ax.legend(fontsize=7, loc="lower left")
        ax = axes[3, j]
        region = cols["region"][sel]
        if np.all(region <= 0):
            ax.text(0.5, 0.5, "no modes", ha="center", va="center", transform=ax.transAxes, fontsize=8, color="#666")
        else:
            ax.step(t[sel], region, where="post", color="tab:red", lw=0.8)
        ax.set_ylim(-0.2, 4.2)
        if j == 0:
            ax.set_ylabel("region [-]")
        ax.set_xlabel("time [s]")
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    return _png(fig)


def zoom_window(columns: dict, length: float = 60.0):
    """A window of ``length`` seconds where the set-point stays within reach and the pump speed varies
    most (for a readable zoom of a long record); None when the record is not longer than that."""
    t = columns["time_s"]
    if t[-1] <= length:
        return None
    best, best_score = None, -1.0
    for start in np.arange(0.0, t[-1] - length + 1e-9, length / 2):
        sel = (t >= start) & (t <= start + length)
        reach = columns["reachable"][sel]
        score = float(np.std(columns["pump_speed_command_rpm"][sel])) if reach.min() > 0.5 else -1.0
        if score > best_score:
            best, best_score = (float(start), float(start + length)), score
    return best


def render_control_report(summary: dict, figures: dict[str, bytes]) -> str:
    """The self-contained report of a control run."""
    esc = lambda x: html.escape(str(x))
    head = "".join(f"<th>{esc(label)}</th>" for _, label, _ in METRIC_LABELS) + "<th>step time median / max [ms]</th>"
    rows = []
    for name, m in summary["controllers"].items():
        cls = " class='best'" if name == summary.get("best") else ""
        st = m["step_time_ms"]
        cells = "".join(f"<td>{_fmt(m[k], s)}</td>" for k, _, s in METRIC_LABELS)
        rows.append(f"<tr{cls}><th>{esc(name)}</th>{cells}<td>{st['median']:.3f} / {st['max']:.2f}</td></tr>")
    figs = "".join(f"<figure><img alt='{esc(k)}' src='data:image/png;base64,{base64.b64encode(v).decode()}'>"
                   f"<figcaption>{esc(k)}</figcaption></figure>" for k, v in figures.items())
    notes = "".join(f"<li>{esc(s)}</li>" for s in summary.get("notes", []))
    record = f", record {summary['duration_s']:g} s" if summary.get("duration_s") is not None else ""
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>hwpts control: {esc(summary['scenario'])}</title>
<style>
body {{ font-family: system-ui, sans-serif; max-width: 1300px; margin: 2em auto; color: #222; line-height: 1.45; }}
table {{ border-collapse: collapse; margin: 0.8em 0; font-size: 0.9em; }} th, td {{ border: 1px solid #ccc; padding: 3px 8px; text-align: right; }}
tr.best {{ background: #e3f4e3; }}
figure {{ margin: 1.2em 0; }} img {{ max-width: 100%; border: 1px solid #ddd; }} figcaption {{ font-size: 0.8em; color: #666; }}
</style></head><body>
<h1>Speed control of the HWPTS: scenario {esc(summary['scenario'])}</h1>
<p>{esc(summary['description'])}. Set-point {summary['setpoint_rpm']:g} r/min, seed {summary['seed']}; model bank
{esc(summary['model']['source'])} ({summary['model']['n_regions']} regions, sample time {summary['model']['sample_time_s']:g} s,
valve play half-width {summary['model']['hysteresis_half_width_v']:g} V). Loop period {summary['sample_time_s'] * 1000:g} ms{record}.
Best model-based controller (lowest RMS error): <b>{esc(summary['best'])}</b>.</p>
{_run_line(summary)}
<h2>Metrics</h2>
<p>Errors of the true motor A speed in % of the set-point, over the time the set-point is within reach (pump fast enough for
at least {summary['reachable_hold_s']:g} s). A dash: the metric does not apply to this scenario.</p>
<table><thead><tr><th>controller</th>{head}</tr></thead><tbody>{''.join(rows)}</tbody></table>
<ul>{notes}</ul>
<h2>Figures</h2>{figs}
</body></html>
"""
