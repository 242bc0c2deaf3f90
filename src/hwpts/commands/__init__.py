"""Sub-commands of the ``hwpts`` CLI, one module per command group.

Each module exposes ``register(subparsers)`` which adds its parser(s) and sets
``handler=`` to a function ``(args) -> int``. Handlers raise :class:`hwpts.errors.HwptsError`
subclasses for bad input; :func:`hwpts.cli.main` prints them as one line with exit status 2.
"""

from hwpts.commands import plant as _plant

COMMAND_MODULES = [_plant]
from hwpts.commands import model as _model; COMMAND_MODULES.append(_model)  # noqa: E702 - identify/validate/predict
