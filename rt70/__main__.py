"""``python -m rt70`` runs the command line."""

import sys

from rt70.cli.main import main

if __name__ == "__main__":  # guarded: benchmark workers are started with "spawn"
    sys.exit(main())
