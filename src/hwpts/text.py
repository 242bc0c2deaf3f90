"""Numbers written as text, read by one rule wherever hwpts reads them (command-line arguments,
CSV cells, hyperplanes). Python's ``float`` and ``int`` also read ``"1_000"`` as 1000 and
non-ASCII digits such as ``"\u0663"`` (an Arabic-Indic three) as 3; no CSV writer or command line
hwpts serves means either, so both are refused here (``ValueError``). And file names shown as text."""

from __future__ import annotations

import re

_INTEGER = re.compile(r"\s*[+-]?[0-9]+\s*")


def plain_float(text) -> float:
    """A real number in Python's float syntax (``"1e-3"``, ``" -2.5 "``, ``"inf"``), without
    digit-group underscores or non-ASCII characters."""
    text = str(text).strip()  # surrounding spaces of any kind (a no-break space after a number)
    if "_" in text or not text.isascii():
        raise ValueError(text)
    return float(text)


def plain_int(text) -> int:
    """An integer written as ASCII digits with an optional sign (surrounding spaces allowed)."""
    if not _INTEGER.fullmatch(str(text)):
        raise ValueError(text)
    return int(text)


def shown_text(text: str) -> str:
    """``text`` as it can be written and drawn: bytes of a file name that are not UTF-8 (kept by
    Python as surrogates, which a UTF-8 writer and matplotlib's font renderer refuse) as ``\\xNN``."""
    return text.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
