"""Atomic file output: write to a temporary file in the target folder, then rename.

A failed run leaves no half-written file behind (the command-line contract).
"""

from __future__ import annotations

import contextlib
import os
import stat
import tempfile
import threading
from pathlib import Path

from hwpts.errors import DataError
from hwpts.text import shown_text


INTERRUPTED = threading.Event()
"""Set by the command line's SIGINT/SIGTERM handler: no output is committed once it is set."""


COMMITTING = threading.Event()
"""Set while a commit runs (:func:`point_of_no_return`): the handler then records a signal
without raising it."""


@contextlib.contextmanager
def point_of_no_return():
    """The steps of a commit that must all happen once begun (a folder moved aside and its
    replacement moved in): a SIGINT/SIGTERM arriving inside is recorded in :data:`INTERRUPTED` but
    not raised, so the commit completes instead of leaving the target missing; a later
    :func:`commit_allowed` still refuses the next output. The first step inside should be
    :func:`commit_allowed` (a signal that came before the commit began stops it)."""
    COMMITTING.set()
    try:
        yield
    finally:
        COMMITTING.clear()


def commit_allowed() -> None:
    """Raise ``KeyboardInterrupt`` if the run was interrupted (an interrupt swallowed by a library
    callback must not let the run write its outputs after the user asked it to stop)."""
    if INTERRUPTED.is_set():
        raise KeyboardInterrupt


def umask_mode(base: int = 0o666) -> int:
    """``base`` with the process umask applied (what ``open()`` would create)."""
    mask = os.umask(0)
    os.umask(mask)
    return base & ~mask


def check_output_path(path: str | os.PathLike, what: str = "--out") -> Path:
    """Refuse an output that is a folder, a symbolic link, a device or a FIFO (never replaced), or
    whose path is not UTF-8 text (:func:`check_utf8_path`)."""
    check_utf8_path(path, what)
    target = Path(path)
    try:
        link = target.is_symlink()
        mode = target.stat().st_mode if target.exists() else None
    except OSError as error:  # a name too long, a folder we may not search
        raise DataError(f"{what} {str(target)!r}: cannot write there ({error.strerror or error})") from None
    if link:
        raise DataError(f"{what} {str(target)!r}: is a symbolic link; hwpts never replaces a link, "
                        f"give the path of a regular file")
    if mode is not None:
        if stat.S_ISDIR(mode):
            raise DataError(f"{what} {str(target)!r}: is a folder, expected a file path")
        if not stat.S_ISREG(mode):
            raise DataError(f"{what} {str(target)!r}: is a device, FIFO or socket, not a regular file; "
                            f"hwpts never replaces one")
    return target


def check_utf8_path(path: str | os.PathLike, what: str = "--out") -> None:
    """Refuse an output path holding bytes that are not UTF-8 (a name typed in another encoding):
    its name goes into reports and summaries, which are UTF-8 text (a traceback before)."""
    text = os.fspath(path)
    if isinstance(text, bytes):
        text = os.fsdecode(text)
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        raise DataError(f"{what} '{shown_text(text)}': the path holds bytes that are not UTF-8; give a UTF-8 "
                        f"path") from None


def process_alive(pid: int) -> bool:
    """Whether a process ``pid`` exists (one we may not signal counts as alive)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True


def _temporary_head(target: Path, end: str) -> str:
    """The start of ``target``'s temporary names: its name (cut short so that the whole temporary
    name stays within 255 bytes, a long but valid name was refused), then the process id."""
    room = 255 - len(end.encode()) - 40  # ".", ".", the pid, mkstemp's 8 characters, a margin
    name = target.name
    while name and len(name.encode()) > room:
        name = name[:-1]
    return f".{name}."


def _remove_created(folders) -> None:
    """Remove the folders a failed or stopped write created (deepest first; a folder that holds
    something else now stays)."""
    for folder in reversed(folders):
        with contextlib.suppress(OSError):
            folder.rmdir()


def _remove_stale_temporaries(target: Path, end: str) -> None:
    """Temporary files of ``target`` left by a run that was killed (SIGKILL, power loss): their
    name carries the writer's process id; those whose process is gone are removed."""
    head = _temporary_head(target, end)
    for stale in target.parent.glob(f"{glob_escape(head)}*{glob_escape(end)}"):
        pid_text = stale.name[len(head):].split(".", 1)[0]
        if pid_text.isdigit() and int(pid_text) != os.getpid() and not process_alive(int(pid_text)):
            with contextlib.suppress(OSError):
                stale.unlink()


def glob_escape(text: str) -> str:
    """``text`` with the glob metacharacters escaped."""
    import glob

    return glob.escape(text)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike, suffix: str | None = None, argument: str = "--out"):
    """Yield a temporary path beside ``path``; on success rename it onto ``path``.

    On any exception (Ctrl-C and SIGTERM included) the temporary file is removed and ``path`` is
    left untouched. The file gets the permissions ``open()`` would give it (the umask's). A path
    that is a folder, a link, a device or a FIFO is refused; an operating-system error becomes a
    :class:`DataError` naming the path (as the command's ``argument``).
    """
    target = check_output_path(path, argument)
    end = suffix if suffix is not None else target.suffix + ".tmp"
    blocker = next((a for a in target.parents if a.exists() or a.is_symlink()), None)
    if blocker is not None and not blocker.is_dir():
        raise DataError(f"{argument} {str(target)!r}: expected a path in a folder, got {str(blocker)!r}, which is a file")
    created = [a for a in reversed(target.parents) if not (a.exists() or a.is_symlink())]
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        _remove_stale_temporaries(target, end)
        fd, tmp = tempfile.mkstemp(prefix=f"{_temporary_head(target, end)}{os.getpid()}.", suffix=end,
                                   dir=target.parent)
        os.close(fd)
    except OSError as error:
        _remove_created(created)
        raise DataError(f"{argument} {str(target)!r}: cannot write there ({error.strerror or error})") from None
    except BaseException:
        _remove_created(created)
        raise
    try:
        yield Path(tmp)
        with point_of_no_return():
            commit_allowed()
            os.chmod(tmp, umask_mode())
            os.replace(tmp, target)
    except OSError as error:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        _remove_created(created)
        raise DataError(f"{argument} {str(target)!r}: cannot write there ({error.strerror or error})") from None
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        _remove_created(created)
        raise


def write_text_atomic(path: str | os.PathLike, text: str, before_commit=None, argument: str = "--out") -> None:
    """Write ``text`` to ``path`` atomically (UTF-8). ``before_commit()``, when given, runs once the
    text is written and before the rename: if it fails (or the run is interrupted in it) ``path``
    is left as it was (what a command prints about the file belongs there). ``argument`` names
    the path in an error."""
    with atomic_path(path, argument=argument) as tmp:
        tmp.write_text(text, encoding="utf-8")
        if before_commit is not None:
            before_commit()


def write_bytes_atomic(path: str | os.PathLike, data: bytes, argument: str = "--out") -> None:
    """Write ``data`` to ``path`` atomically (errors name the path as the command's ``argument``)."""
    with atomic_path(path, argument=argument) as tmp:
        tmp.write_bytes(data)
