"""Sub-commands of the ``hwpts`` CLI, one module per command group.

Each module exposes ``register(subparsers)`` which adds its parser(s) and sets
``handler=`` to a function ``(args) -> int``. Handlers raise :class:`hwpts.errors.HwptsError`
subclasses for bad input; :func:`hwpts.cli.main` prints them as one line with exit status 2.
"""

from hwpts.commands import analysis as _analysis
from hwpts.commands import control as _control
from hwpts.commands import model as _model
from hwpts.commands import plant as _plant
from hwpts.commands import reproduce as _reproduce

COMMAND_MODULES = [_reproduce, _plant, _model, _analysis, _control]
