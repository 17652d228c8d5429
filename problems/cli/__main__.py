"""``python -m appdyn.problems.cli ...`` runs the ``appdyn`` command line."""
import sys

from appdyn.problems.cli import main

sys.exit(main())
