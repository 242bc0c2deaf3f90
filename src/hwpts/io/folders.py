"""Output folders written as a whole: a run fills a staging folder that replaces the target at the
end, so a failed run leaves an earlier complete one intact and two runs never mix their files."""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import tempfile
from pathlib import Path

from hwpts.errors import DataError
from hwpts.io.atomic import check_utf8_path, commit_allowed, point_of_no_return, umask_mode


def check_replaceable(path: str | os.PathLike, schema: str, marker: str = "summary.json") -> None:
    """Refuse a target that exists and is not empty, unless it is an earlier run of ``schema``."""
    if not str(path).strip():  # Path("") is the current folder
        raise DataError("--out: expected an output folder's path, got an empty one")
    check_utf8_path(path)
    out = Path(path)
    if out.is_symlink():
        raise DataError(f"--out {str(out)!r}: is a symbolic link; hwpts never replaces a link, give the path "
                        f"of a folder")
    here = os.path.realpath(os.getcwd())
    where = os.path.realpath(out)
    if here == where or here.startswith(where.rstrip(os.sep) + os.sep):
        raise DataError(f"--out {str(out)!r}: is (or holds) the current folder, which a run replaces as a whole; "
                        f"give a folder beside it")
    if not out.exists():
        return
    if not out.is_dir():
        kind = "a file" if out.is_file() else "a device, pipe or socket, not a file"
        raise DataError(f"--out {str(out)!r}: exists and is {kind}, expected a folder")
    if not any(out.iterdir()):
        return
    try:
        found = json.loads((out / marker).read_text(encoding="utf-8")).get("schema")
    except (OSError, ValueError, AttributeError):
        found = None
    if found != schema:
        raise DataError(
            f"--out {str(out)!r}: the folder exists and holds files that are not an earlier hwpts run "
            f"(no {marker} with schema {schema!r}); choose another folder or empty it"
        )
    try:  # the files the earlier run wrote
        written = set(json.loads((out / MANIFEST).read_text(encoding="utf-8")))
    except (OSError, ValueError, TypeError):
        # no list (a copy made with `cp -r run/* copy/` leaves the hidden file behind, or a run of
        # an old version): nothing tells the run's files from the user's, so nothing is replaced
        raise DataError(f"--out {str(out)!r}: an earlier run's folder without its list of files ({MANIFEST}), so "
                        f"its files cannot be told from others; a run replaces the folder as a whole: "
                        f"choose another folder, or delete this one") from None
    extra = sorted(name for name in _files(out) if name not in written and name != MANIFEST)
    if extra:
        shown = ", ".join(extra[:3]) + (f" and {len(extra) - 3} more" if len(extra) > 3 else "")
        raise DataError(f"--out {str(out)!r}: an earlier run's folder that also holds files it did not write "
                        f"({shown}); a run replaces the folder as a whole: move them or choose another folder")


MANIFEST = ".hwpts-files"  # the files a run wrote in its folder (JSON list of relative paths)


def _files(folder: Path) -> list[str]:
    """Relative paths of the files and folders under ``folder``."""
    return [str(p.relative_to(folder)) for p in folder.rglob("*")]


PID_FILE = ".hwpts-pid"  # the process writing a staging folder


def _alive(pid: int) -> bool:
    from hwpts.io.atomic import process_alive

    return process_alive(pid)


def _remove_stale_stages(out: Path) -> None:
    """Staging folders of ``out`` left by a run that was killed (its process is gone)."""
    for stale in out.parent.glob(f".{out.name}.new-*"):
        try:
            pid = int((stale / PID_FILE).read_text(encoding="utf-8").strip())
        except (OSError, ValueError):
            pid = None
        if pid is None or not _alive(pid):
            shutil.rmtree(stale, ignore_errors=True)
    for stale in out.parent.glob(f".{out.name}.old-*"):
        shutil.rmtree(stale, ignore_errors=True)


@contextlib.contextmanager
def staged_folder(path: str | os.PathLike, schema: str):
    """Yield a fresh staging folder beside ``path``; on success it replaces ``path`` as a whole."""
    out = Path(path)
    check_replaceable(out, schema)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        _remove_stale_stages(out)
        stage = Path(tempfile.mkdtemp(prefix=f".{out.name}.new-", dir=out.parent))
        (stage / PID_FILE).write_text(str(os.getpid()), encoding="utf-8")
    except OSError as error:
        raise DataError(f"--out {str(out)!r}: cannot write there ({error.strerror or error})") from None
    try:
        yield stage
    except BaseException:
        with point_of_no_return():  # removed whole: a second Ctrl-C inside rmtree left the stage behind
            shutil.rmtree(stage, ignore_errors=True)
        raise
    # the target is moved aside and the stage moved in as one step: a signal in between would
    # leave no folder at `out` (and the next run would delete the one moved aside)
    with point_of_no_return():
        try:
            commit_allowed()
            (stage / PID_FILE).unlink()
            (stage / MANIFEST).write_text(json.dumps(sorted(_files(stage))), encoding="utf-8")
            os.chmod(stage, umask_mode(0o777))
        except OSError as error:  # a full disk at the last file: said as the folder, not as stdout
            shutil.rmtree(stage, ignore_errors=True)
            raise DataError(f"--out {str(out)!r}: cannot write there ({error.strerror or error})") from None
        except BaseException:
            shutil.rmtree(stage, ignore_errors=True)
            raise
        old = None
        if out.exists():
            old = Path(tempfile.mkdtemp(prefix=f".{out.name}.old-", dir=out.parent))
            os.rmdir(old)
            os.replace(out, old)
        os.replace(stage, out)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
