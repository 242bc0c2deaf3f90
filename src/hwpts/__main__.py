"""``python -m hwpts`` runs the command-line interface."""

from hwpts.cli import entry

entry()
