"""``python -m neurohover.experiments reproduce|results|report ...`` (same as ``neurohover ...``)."""

import sys

from ..commands_reproduce import main

sys.exit(main())
