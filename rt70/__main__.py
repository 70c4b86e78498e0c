"""``python -m rt70`` runs the command line."""

import sys

from rt70.cli import main

sys.exit(main())
