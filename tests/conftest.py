import pytest

from hwpts.cli import main


@pytest.fixture(scope="session")
def quick_run(tmp_path_factory):
    """One ``hwpts reproduce --quick`` shared by the end-to-end and report tests (about 10 s)."""
    out = tmp_path_factory.mktemp("reproduce") / "results"
    status = main(["reproduce", "--quick", "--out", str(out), "--seed", "0"])
    assert status == 0
    return out
