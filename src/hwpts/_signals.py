"""The signals that stop a run (stdlib's C module only: the console script imports this first)."""

import _signal


def interrupt_signals() -> tuple:
    """The signals that stop a run as Ctrl-C does: SIGINT, SIGTERM and SIGHUP (the terminal
    closed; POSIX only), but not a SIGHUP the process ignores (started under ``nohup``: the
    terminal closing is to leave the run alone). The console script, :func:`hwpts.cli.main` and
    the Dask cluster's start use this one list."""
    return tuple(getattr(_signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(_signal, name)
                 and not (name == "SIGHUP" and _signal.getsignal(_signal.SIGHUP) == _signal.SIG_IGN))
