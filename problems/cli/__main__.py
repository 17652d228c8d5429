"""``python -m problems.cli ...`` runs the ``appdyn`` command line."""
import sys

from problems.cli import main

sys.exit(main())
