"""``python -m hwpts`` runs the command-line interface."""

from hwpts._console import entry

if __name__ == "__main__":
    entry()
