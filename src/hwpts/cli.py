"""The ``hwpts`` command line: a thin layer with one error boundary.

Each sub-command lives in :mod:`hwpts.commands` (one module per command group) and registers
its parser and handler. :func:`main` parses, dispatches and turns every library error into one
line on stderr with exit status 2 (no traceback).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import re
import shlex
import signal
import sys
import threading
import warnings
from collections.abc import Sequence

from hwpts import __version__
from hwpts.errors import HwptsError, UsageError
from hwpts.io.atomic import COMMITTING as _COMMITTING
from hwpts.io.atomic import INTERRUPTED as _INTERRUPTED  # set by SIGINT/SIGTERM (stdlib only: --help stays fast)

EXIT_OK = 0
EXIT_USAGE = 2
_INTERRUPTED_FRAMES: list = []  # see _run: interrupted runs' exceptions, kept until the process ends
_SETTLED = threading.Event()  # the run has its status (outputs settled): a later signal is not raised


_GIVEN = "_given_options"  # the namespace's record of the options given, dropped after parsing


class _StoreOnce(argparse._StoreAction):
    """argparse's ``store`` for an option given at most once: a second ``--out`` (or ``--na``) is
    refused rather than silently replacing the first, as a second ``--input`` of the same column is.
    Options meant to repeat use ``append``."""

    def __call__(self, parser, namespace, values, option_string=None):
        if option_string is not None:
            given = getattr(namespace, _GIVEN, None)
            if given is None:
                given = set()
                setattr(namespace, _GIVEN, given)
            if self.dest in given:
                first, then = (str(v) if isinstance(v, os.PathLike) else v
                               for v in (getattr(namespace, self.dest), values))
                parser.error(f"{'/'.join(self.option_strings)} is given twice ({first!r}, then {then!r}); "
                             f"give it once")
            given.add(self.dest)
        super().__call__(parser, namespace, values, option_string)


class ArgumentParser(argparse.ArgumentParser):
    """An argparse parser whose errors are one line, raised rather than printed, and whose options
    that take one value are given at most once."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.register("action", None, _StoreOnce)
        self.register("action", "store", _StoreOnce)

    def error(self, message: str):  # noqa: D102 - argparse hook
        """Raise the parse error as a :class:`UsageError` (one line, exit 2) instead of printing usage."""
        command = self.prog.split(" ", 1)[1] if " " in self.prog else ""  # "hwpts identify" -> "identify"
        raise UsageError(f"{command}: {message}" if command else message)


def build_parser() -> ArgumentParser:
    """The full parser with every sub-command registered."""
    from hwpts.commands import COMMAND_MODULES

    parser = ArgumentParser(
        prog="hwpts",
        description=(
            "Piecewise affine identification of a hydraulic wind power transfer system. "
            "Speeds in r/min, valve command in volts, time in seconds."
        ),
    )
    parser.add_argument("--version", action="version", version=f"hwpts {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=ArgumentParser)
    subparsers.required = True
    for module in COMMAND_MODULES:
        module.register(subparsers)
    return parser


INPUT_ARGS = ("data", "model", "inputs")  # arguments that name files a command reads


OUTPUT_ARGS = ("out", "plot")  # arguments that name files a command writes


def _check_stdout(args) -> None:
    """A command whose result is what it prints (``validate``, ``residuals``, ``plant steady-state``)
    refuses to run with standard output closed (``>&-``: Python then prints to nothing), unless it
    writes a figure too; the commands that write files run, their result being the files."""
    command = getattr(args, "prints_result", None)
    if command and sys.stdout is None and getattr(args, "plot", None) is None:
        raise UsageError(f"{command}: standard output is closed (>&-), and the result is printed there; "
                         f"run it with standard output open" + (" or give --plot FILE.png" if hasattr(args, "plot")
                                                                else ""))


def _same_file(a, b) -> bool:
    """Whether the paths ``a`` and ``b`` are one file (a hard link is another name of it: an
    output written there replaces the name only, and the link to the input is lost)."""
    try:
        return os.path.samefile(a, b)
    except (OSError, TypeError, ValueError):  # either missing (a new output), or not a path
        return False


def _check_outputs(args) -> None:
    """An output that is one of the command's inputs is refused (it would destroy the input), and
    so is an input path that is not UTF-8 (as an output path is: its name goes into summaries and
    reports, which are UTF-8 text; it was read and its name written as a lone surrogate, which a
    strict JSON reader refuses)."""
    from hwpts.io.atomic import check_utf8_path

    for name in INPUT_ARGS:
        source = getattr(args, name, None)
        if source is not None:
            check_utf8_path(source, f"--{name}" if name == "inputs" else name.upper())
    for flag in OUTPUT_ARGS:
        out = getattr(args, flag, None)
        if out is None or str(out) == "-":
            continue
        target = os.path.realpath(out)
        for name in INPUT_ARGS:
            source = getattr(args, name, None)
            if source is None:
                continue
            where = os.path.realpath(source)
            if where == target or _same_file(source, out):
                link = "" if where == target else "a hard link to "
                raise UsageError(f"--{flag} {str(out)!r} is {link}the {name} file {str(source)!r}: writing it would "
                                 f"destroy the input; choose another output path")
            if where.startswith(target.rstrip(os.sep) + os.sep):
                # an output folder is replaced as a whole: the input inside it would be deleted
                raise UsageError(f"--{flag} {str(out)!r} holds the {name} file {str(source)!r}: the folder is "
                                 f"replaced as a whole, which would delete it; choose another output folder")


def _interrupt(signum, frame):  # pragma: no cover - exercised in a subprocess test
    _INTERRUPTED.set()
    if _COMMITTING.is_set() or _SETTLED.is_set():  # inside a commit, or the run is over: recorded,
        return  # raised by no one (the commit completes; the status stands)
    raise KeyboardInterrupt


def _quiet_interrupts(hook):
    """An unraisable-exception hook that stays silent about the interrupt.

    A signal that arrives inside a C callback (numba compiling a kernel, for example) raises
    ``KeyboardInterrupt`` where Python can only print it as "Exception ignored ..." with a
    traceback; the run then fails with a secondary error that :func:`main` reports as interrupted.
    """
    def quiet(unraisable):
        if isinstance(unraisable.exc_value, KeyboardInterrupt) or _INTERRUPTED.is_set():
            return
        hook(unraisable)
    return quiet


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status (0 ok, 2 bad argument, input or failure).

    SIGTERM and SIGHUP (the terminal closed) are handled as Ctrl-C: the run stops, temporary files
    and staging folders are removed, earlier outputs stay intact, exit status 130 and one line.
    """
    previous: dict = {}
    hook = sys.unraisablehook
    _INTERRUPTED.clear()
    for stream in (sys.stdout, sys.stderr):
        # a file name's bytes that are not UTF-8 (kept as surrogates) printed escaped (\\udcff), not as a
        # UnicodeEncodeError where the terminal's encoding is strict UTF-8
        reconfigure = getattr(stream, "reconfigure", None)
        if callable(reconfigure):
            with contextlib.suppress(ValueError, OSError, io.UnsupportedOperation):
                reconfigure(errors="backslashreplace")
    if threading.current_thread() is threading.main_thread():
        from hwpts._signals import interrupt_signals

        for sig in interrupt_signals():
            previous[sig] = signal.signal(sig, _interrupt)
        sys.unraisablehook = _quiet_interrupts(hook)
    _SETTLED.clear()
    try:
        return _run(argv)
    finally:
        _SETTLED.set()  # restoring the handlers below is no place for a KeyboardInterrupt
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        sys.unraisablehook = hook
        _INTERRUPTED.clear()  # (_SETTLED stays set until the next run: the console script's handlers read it)


# options whose value may start with a minus sign (a negative coefficient, a slice from the end):
# argparse takes "--hyperplane -1,0,2.8" for two options; the value is attached as "--hyperplane=-1,0,2.8"
NEGATIVE_VALUE_OPTIONS = ("--hyperplane", "--rows")


def _attach_negative_values(argv: Sequence[str]) -> list[str]:
    """``[..., "--hyperplane", "-1,0,2.8", ...]`` -> ``[..., "--hyperplane=-1,0,2.8", ...]`` (a value
    that starts with a minus sign and a digit, or with ``-.`` or ``-:``); other tokens unchanged."""
    out: list[str] = []
    tokens = list(argv)
    i = 0
    while i < len(tokens):
        token = tokens[i]
        nxt = tokens[i + 1] if i + 1 < len(tokens) else None
        if token in NEGATIVE_VALUE_OPTIONS and nxt is not None and len(nxt) > 1 and nxt[0] == "-" \
                and (nxt[1].isdigit() or nxt[1] in ".:"):
            out.append(f"{token}={nxt}")
            i += 2
            continue
        out.append(token)
        i += 1
    return out


def _run(argv: Sequence[str] | None) -> int:
    """Parse and dispatch; every failure becomes one line and an exit status. The parser is built
    here, after the signal handlers are in place: building it imports the command modules (numpy
    and more), and a Ctrl-C or SIGTERM in that time is an interrupt like any other."""
    args, before = None, {}
    try:
        given = list(sys.argv[1:] if argv is None else argv)
        args = build_parser().parse_args(_attach_negative_values(given))
        vars(args).pop(_GIVEN, None)
        args.command_line = shlex.join(["hwpts", *given])
        before = _outputs(args)
        _check_outputs(args)
        _check_stdout(args)
        with warnings.catch_warnings(record=True) as caught:
            # a library warning is one line after a run that succeeded (Python's two lines, with a
            # source path, came before the error line of one that failed: three lines for one error)
            warnings.simplefilter("default")
            status = int(args.handler(args) or EXIT_OK)
        for message in _warning_lines([w.message for w in caught
                                       if not issubclass(w.category, (DeprecationWarning, PendingDeprecationWarning))]):
            print(message, file=sys.stderr)
        _SETTLED.set()  # a signal from here on arrives after the run: its status stands
    except BaseException as error:
        if isinstance(error, KeyboardInterrupt) or (_INTERRUPTED.is_set() and isinstance(error, Exception)):
            # the interrupted frames stay referenced until the process ends: freeing them runs the
            # destructors of whatever they held, and a compiler (LLVM under numba) stopped mid-way
            # can crash there (exit -11 right after this line, seen once under SIGTERM)
            _INTERRUPTED_FRAMES.append(error)
            written = _written_since(args, before)
            # a stop that lands after an output was committed cannot undo it: say so
            print(_one_line("hwpts: interrupted" + (f" after writing {', '.join(written)}" if written else "")),
                  file=sys.stderr)
            return 130
        if _stdout_failed(error):
            # the report printed after the outputs were committed (a full disk behind stdout): the
            # line names the stream, and the files that are complete all the same
            written = _written_since(args, before)
            print(_one_line(f"hwpts: error: standard output: cannot write ({error.strerror or error})"
                            + (f"; {', '.join(written)} {'was' if len(written) == 1 else 'were'} written in full"
                               if written else "")), file=sys.stderr)
            return EXIT_USAGE
        return _report(error)
    return status


_GLYPH = re.compile(r"Glyph (\d+) .*missing from font\(s\) (.+?)\.?$")


def _warning_lines(messages) -> list[str]:
    """The warnings of a run that succeeded, one line each, each once; matplotlib's glyph warnings
    (one per character a figure's font cannot draw: four lines for a file named 模型.json) in one."""
    lines, glyphs, fonts = [], [], []
    for message in messages:
        match = _GLYPH.match(str(message))
        if match:
            glyphs.append(chr(int(match.group(1))))
            fonts.append(match.group(2))
            if len(glyphs) == 1:
                lines.append(None)  # the place of the glyph line
        else:
            lines.append(_one_line(f"hwpts: warning: {message}"))
    if glyphs:
        chars = "".join(dict.fromkeys(glyphs))
        lines[lines.index(None)] = _one_line(
            f"hwpts: warning: the figures' font ({', '.join(dict.fromkeys(fonts))}) cannot draw {chars!r} (a name in a "
            f"title or label): shown as boxes; install a font that has them (for Chinese, Japanese or Korean e.g. "
            f"Noto Sans CJK, which hwpts then uses)")
    return list(dict.fromkeys(lines))


def _stdout_failed(error: BaseException) -> bool:
    """Whether ``error`` is a failed write to standard output (not a closed pipe, which is no error:
    ``| head``): an OSError that names no file, of the kinds a write fails with (a full disk or
    device, an I/O error). Files are written through :mod:`hwpts.io.atomic`, which names them."""
    import errno

    return (isinstance(error, OSError) and not isinstance(error, BrokenPipeError) and error.filename is None
            and error.errno in (errno.ENOSPC, errno.EIO, errno.EDQUOT, errno.EFBIG))


def _outputs(args) -> dict:
    """``{path: (inode, mtime)}`` of the command's outputs (``--out``, ``--plot``) as they are now
    (``None`` for one that does not exist)."""
    found = {}
    for name in ("out", "plot"):
        value = getattr(args, name, None)
        if value is None or str(value) == "-":
            continue
        try:
            st = os.stat(value)
            found[str(value)] = (st.st_ino, st.st_mtime_ns)
        except (OSError, ValueError):
            found[str(value)] = None
    return found


def _written_since(args, before: dict) -> list[str]:
    """The outputs that changed since ``before`` (:func:`_outputs`): a run stopped after its
    commit has a complete file there, and the user should know it."""
    if args is None:
        return []
    now = _outputs(args)
    return [path for path, state in now.items() if state is not None and state != before.get(path)]


def _one_line(text: str) -> str:
    """``text`` on one line: a line break inside a value (an argument or file name holding one)
    written as ``\\n``, so that an error stays the one line the contract promises."""
    return text.replace("\r", "\\r").replace("\n", "\\n")


def _report(error: BaseException) -> int:
    """One line on stderr for a known failure; anything else is re-raised (a bug: keep its traceback)."""
    try:
        raise error
    except HwptsError as error:
        print(f"hwpts: error: {_one_line(str(error))}", file=sys.stderr)
        return EXIT_USAGE
    except OSError as error:
        if isinstance(error, BrokenPipeError):
            return EXIT_OK
        where = f"{error.filename!s}: " if error.filename else ""
        print(f"hwpts: error: {where}{error.strerror or error}", file=sys.stderr)
        return EXIT_USAGE
    except MemoryError:
        print("hwpts: error: not enough memory for this run; use a smaller grid or fewer samples", file=sys.stderr)
        return EXIT_USAGE
    except (ArithmeticError, ValueError) as error:
        import numpy as np

        if not isinstance(error, (ArithmeticError, np.linalg.LinAlgError)):
            raise
        # a numerical failure (singular or non-convergent linear algebra, overflow): one line
        print(f"hwpts: error: numerical failure ({type(error).__name__}: {error}); check the data's scale "
              f"and the options (e.g. --ridge)", file=sys.stderr)
        return EXIT_USAGE


def finish(status: int) -> None:  # pragma: no cover - the console script's exit (hwpts._console)
    """Exit with ``status`` once the streams are flushed and Python's exit handlers have run,
    without the native libraries' teardown (``os._exit``): every output and temporary file is
    settled by then. That teardown crashed now and then on a fast exit, the run's thread pools
    still starting: after the one line of a bad argument, ``terminate called without an active
    exception`` and status 134 instead of 2 (2 of 40 runs of one command on a busy machine). After
    an interrupt (130) the exit handlers are skipped too: a signal that landed inside a compiled
    library (LLVM compiling a numba kernel) can leave it in a state that crashes them."""
    import atexit

    if status != 130:
        try:
            atexit._run_exitfuncs()
        except BaseException:  # noqa: BLE001 - an exit handler's failure must not change the status
            pass
    for stream in (sys.stdout, sys.stderr):
        try:
            if stream is not None:
                stream.flush()
        except (OSError, ValueError):  # a closed or full stream: nothing more can be said
            pass
    os._exit(status)
