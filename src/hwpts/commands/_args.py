"""Argument types shared by the sub-commands: each rejects bad values with a message naming what
was expected and what was received (argparse prefixes the argument's name)."""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

from hwpts.text import plain_float, plain_int


def finite_float(text: str) -> float:
    """A finite real number."""
    try:
        value = plain_float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return value


def non_negative_float(text: str) -> float:
    """A finite real number >= 0."""
    value = finite_float(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a number >= 0, got {text!r}")
    return value


def integer(text: str) -> int:
    """An integer (its range is checked where it is used)."""
    try:
        return plain_int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None


def non_negative_int(text: str) -> int:
    """An integer >= 0."""
    try:
        value = plain_int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 0, got {text!r}")
    return value


def positive_int(text: str) -> int:
    """An integer >= 1."""
    try:
        value = plain_int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {text!r}")
    return value


def grid(text: str) -> tuple[float, float, int]:
    """START:STOP:N, an increasing grid of N >= 1 points (START == STOP only when N == 1)."""
    parts = text.split(":")
    if len(parts) != 3:
        raise argparse.ArgumentTypeError(f"expected START:STOP:N, got {text!r}")
    start, stop = finite_float(parts[0]), finite_float(parts[1])
    try:
        count = plain_int(parts[2])
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number of points N in START:STOP:N, got {parts[2]!r}") from None
    if count < 1:
        raise argparse.ArgumentTypeError(f"empty grid: N must be >= 1, got {text!r}")
    if stop < start:
        raise argparse.ArgumentTypeError(f"reversed grid: STOP must be >= START, got {text!r}")
    if count > 1 and stop == start:
        raise argparse.ArgumentTypeError(f"{count} points need STOP > START, got {text!r}")
    if count == 1 and stop != start:
        raise argparse.ArgumentTypeError(f"one point needs START == STOP, got {text!r}")
    return start, stop, count


def output_file(text: str) -> Path | str:
    """A path to write a file at (not an existing folder); ``-`` is standard output."""
    if text == "-":
        return text
    path = Path(text)
    try:
        folder = path.is_dir()
    except OSError as error:  # a name too long for the file system
        raise argparse.ArgumentTypeError(f"cannot write {text!r} ({error.strerror or error})") from None
    if folder:
        raise argparse.ArgumentTypeError(f"expected a file path, got {text!r}, which is a folder")
    return path


def file_with_suffix(*suffixes: str, stdout: bool = False):
    """An argument type: a file path ending in one of ``suffixes`` (case-insensitive), not an
    existing folder; ``-`` (standard output) too when ``stdout``."""
    def check(text: str) -> Path | str:
        if stdout and text == "-":
            if sys.stdout is None:  # started with standard output closed (>&-): said before any work
                raise argparse.ArgumentTypeError("standard output is closed; give a file name")
            return text
        if not text.strip():
            raise argparse.ArgumentTypeError("expected a file path, got an empty string")
        path = output_file(text)
        if not text.lower().endswith(tuple(s.lower() for s in suffixes)):
            what = " or ".join(suffixes) + (" (or - for standard output)" if stdout else "")
            raise argparse.ArgumentTypeError(f"expected a {what} file name, got {text!r}")
        return path
    check.__name__ = "file"
    return check


def _finite(obj):
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_finite(v) for v in obj]
    if hasattr(obj, "item") and hasattr(obj, "dtype"):  # numpy scalars
        return _finite(obj.item())
    return obj


def shown_path(path) -> str:
    """An output path as "wrote ..." names it: ``-`` is "to standard output"."""
    from hwpts.io.datasets import is_stdout

    return "to standard output" if is_stdout(path) else str(path)


def json_text(obj, indent: int | None = 2) -> str:
    """Strict JSON for standard output: a value that is not a finite number (a diverged fit) is
    ``null``, never ``NaN`` or ``Infinity``, which JSON does not have."""
    return json.dumps(_finite(obj), indent=indent, allow_nan=False)
