"""Shared fixtures of the identification tests: the real-data folder (skips when absent)."""

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def data_dir() -> Path:
    """``$HWPTS_DATA_DIR`` or ``../shared/data`` beside the checkout."""
    return Path(os.environ.get("HWPTS_DATA_DIR", REPO.parent / "shared" / "data"))


@pytest.fixture
def real_data():
    def get(*parts):
        path = data_dir().joinpath(*parts)
        if not path.exists():
            pytest.skip(f"real data {'/'.join(parts)} not found under {data_dir()} (set HWPTS_DATA_DIR)")
        return path

    return get
