"""``python -m planner`` runs the ``wobjcal`` command line."""

import sys

from planner.cli.main import main

sys.exit(main())
