"""``python -m hwpts`` runs the command-line interface."""

import sys

from hwpts.cli import main

sys.exit(main())
