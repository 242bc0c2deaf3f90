"""The ``hwpts`` command line: a thin layer with one error boundary.

Each sub-command lives in :mod:`hwpts.commands` (one module per command group) and registers
its parser and handler. :func:`main` parses, dispatches and turns every library error into one
line on stderr with exit status 2 (no traceback).
"""

from __future__ import annotations

import argparse
import sys
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


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status (0 ok, 2 bad argument, input or failure)."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        return int(args.handler(args) or EXIT_OK)
    except HwptsError as error:
        print(f"hwpts: error: {error}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt:
        print("hwpts: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:
        return EXIT_OK


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
