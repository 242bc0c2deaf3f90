import pytest
from hypothesis import settings

# `make test` (and CI) draws the same examples every run, so a pass or a failure is reproducible;
# `pytest --hypothesis-profile=explore` draws fresh ones to look for new failures (how the
# one-in-1,000 miss of the alternating segmenter's fixed four starts was found)
settings.register_profile("default", derandomize=True, print_blob=True)
settings.register_profile("explore", derandomize=False, print_blob=True)
settings.load_profile("default")


def _drop_stale_numba_caches() -> None:
    """Empty numba's on-disk caches of the package when any of its sources changed.

    numba checks only the file of a cached function: a constant or a compiled helper it calls from
    another module (valve.py's MAKEUP_ONSET_PA and makeup_shape, used by dynamics.py's kernels; the parameter
    indices of parameters.py) can change and the cached kernel still runs the old one (a session
    saw an edit do nothing until the cache was deleted). A clean clone, as CI's, has no cache; this
    is for a working copy. Every source file is hashed: which ones a kernel depends on is not said."""
    import hashlib
    import os
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent / "src" / "hwpts"
    if not root.is_dir() or os.environ.get("NUMBA_CACHE_DIR"):  # (a folder of the user's: not ours to empty)
        return
    digest = hashlib.sha256(b"".join(p.read_bytes() for p in sorted(root.rglob("*.py")))).hexdigest()
    stamp = root / "__pycache__" / "numba-sources.sha256"
    try:
        if stamp.exists() and stamp.read_text() == digest:
            return
        for cached in [*root.rglob("*.nbi"), *root.rglob("*.nbc")]:
            cached.unlink()
        stamp.parent.mkdir(parents=True, exist_ok=True)
        stamp.write_text(digest)
    except (OSError, ValueError):  # a read-only checkout: numba caches elsewhere (hwpts._numba_cache_dir)
        pass


_drop_stale_numba_caches()

from hwpts.cli import main  # noqa: E402 - after the stale caches are gone, before numba compiles


@pytest.fixture(scope="session")
def quick_run(tmp_path_factory):
    """One ``hwpts reproduce --quick`` shared by the end-to-end and report tests (about 10 s)."""
    out = tmp_path_factory.mktemp("reproduce") / "results"
    status = main(["reproduce", "--quick", "--out", str(out), "--seed", "0"])
    assert status == 0
    return out
