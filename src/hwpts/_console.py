"""The ``hwpts`` console script's first code: signal handlers before any import that takes time.

:func:`hwpts.cli.main` handles Ctrl-C, SIGTERM and SIGHUP as an interrupt (exit status 130, one line), but
only once the command line's modules are imported: a signal in the first ~50 ms, while Python
imports them, ended the process with a traceback (SIGINT) or silently with -15 (SIGTERM). Here
both raise :class:`KeyboardInterrupt` from the first line of the script on, and after the run the
process ignores them while it exits (the outputs are settled by then: a signal between main's
return and that point is recorded by main's flag and not raised, so it cannot turn the run's
status into 130 beside a complete output). What is left is Python's
own start (about 15 ms here), where a SIGINT ends the process with status -2 and a message from
the interpreter.
"""

import os
import sys

import _signal  # the C module: ``signal`` imports ``enum`` first, 10 ms more of the window

from hwpts._signals import interrupt_signals


def _interrupt(signum, frame):
    # ``hwpts.cli`` may be in sys.modules half imported (a signal in its first milliseconds):
    # without its ``_SETTLED`` yet the run has not begun, and the signal interrupts it
    settled = getattr(sys.modules.get("hwpts.cli"), "_SETTLED", None)
    if settled is not None and settled.is_set():  # the run is over (main restored this handler):
        return  # its status stands
    raise KeyboardInterrupt


def _interrupted() -> None:
    sys.stderr.write("hwpts: interrupted\n")
    sys.stderr.flush()
    os._exit(130)


def entry() -> None:  # pragma: no cover - the console script, exercised in subprocess tests
    """Install the handlers, import and run :func:`hwpts.cli.main`, exit with its status."""
    try:
        handled = interrupt_signals()
        for sig in handled:
            _signal.signal(sig, _interrupt)
        from hwpts.cli import finish, main

        status = main()  # main restores these handlers, which then leave a late signal alone (_interrupt)
        for sig in handled:
            _signal.signal(sig, _signal.SIG_IGN)
    except KeyboardInterrupt:
        _interrupted()
    finish(status)
