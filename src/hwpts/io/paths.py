"""Input paths checked before they are opened: a missing path, a folder, a FIFO or a device (reading one
could block forever) and an operating-system error (permission, loop of links, name too long) each
become a :class:`DataError` naming the path."""

from __future__ import annotations

import os
import stat
from pathlib import Path

from hwpts.errors import DataError


def check_input_file(path: str | os.PathLike, what: str = "", expected: str = "a file") -> Path:
    """``path`` as a :class:`Path` if it names a regular file (through links) that exists.

    ``what`` prefixes the path in messages (``"model "``); ``expected`` says what the path should be
    (``"a .json model file"``).
    """
    p = Path(path)
    try:
        mode = os.stat(p).st_mode
    except FileNotFoundError:
        raise DataError(f"{what}{str(p)!r}: no such file") from None
    except OSError as error:
        raise DataError(f"{what}{str(p)!r}: cannot read ({error.strerror or error})") from None
    except ValueError as error:  # an embedded NUL byte
        raise DataError(f"{what}{str(p)!r}: not a valid path ({error})") from None
    if stat.S_ISDIR(mode):
        raise DataError(f"{what}{str(p)!r}: is a folder, expected {expected}")
    if not stat.S_ISREG(mode):
        raise DataError(f"{what}{str(p)!r}: is a FIFO, device or socket, expected {expected} "
                        f"(hwpts reads regular files)")
    return p


def read_error(p: Path, error: OSError, what: str = "") -> DataError:
    """The :class:`DataError` for an operating-system error while reading ``p``."""
    return DataError(f"{what}{str(p)!r}: cannot read ({error.strerror or error})")
