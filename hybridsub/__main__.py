"""``python -m hybridsub`` runs the command line."""

import sys

from ._app.cli import main

if __name__ == "__main__":
    sys.exit(main())
