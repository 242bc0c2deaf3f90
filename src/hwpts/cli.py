"""The ``hwpts`` command line: a thin layer with one error boundary.

Each sub-command lives in :mod:`hwpts.commands` (one module per command group) and registers
its parser and handler. :func:`main` parses, dispatches and turns every library error into one
line on stderr with exit status 2 (no traceback).
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import threading
from collections.abc import Sequence

from hwpts import __version__
from hwpts.errors import HwptsError, UsageError

EXIT_OK = 0
EXIT_USAGE = 2


class ArgumentParser(argparse.ArgumentParser):
    """An argparse parser whose errors are one line, raised rather than printed."""

    def error(self, message: str):  # noqa: D102 - argparse hook
        raise UsageError(f"{self.prog}: {message}")


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


def _check_outputs(args) -> None:
    """An output that is one of the command's inputs is refused (it would destroy the input)."""
    out = getattr(args, "out", None)
    if out is None or str(out) == "-":
        return
    target = os.path.realpath(out)
    for name in INPUT_ARGS:
        source = getattr(args, name, None)
        if source is not None and os.path.realpath(source) == target:
            raise UsageError(f"--out {str(out)!r} is the {name} file {str(source)!r}: writing it would destroy "
                             f"the input; choose another output path")


def _sigterm(signum, frame):  # pragma: no cover - exercised in a subprocess test
    raise KeyboardInterrupt


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status (0 ok, 2 bad argument, input or failure).

    SIGTERM is handled as Ctrl-C: the run stops, temporary files and staging folders are removed,
    earlier outputs stay intact, exit status 130 and one line.
    """
    parser = build_parser()
    previous = None
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, _sigterm)
    try:
        args = parser.parse_args(argv)
        _check_outputs(args)
        return int(args.handler(args) or EXIT_OK)
    except HwptsError as error:
        print(f"hwpts: error: {error}", file=sys.stderr)
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
    except KeyboardInterrupt:
        print("hwpts: interrupted", file=sys.stderr)
        return 130
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
