"""``python -m bmc_functions``: the command line (see :mod:`bmc_functions.cli`)."""

import sys

from .cli import main

sys.exit(main())
