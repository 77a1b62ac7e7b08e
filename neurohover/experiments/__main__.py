"""``python -m neurohover.experiments reproduce|results|report ...`` (same as ``neurohover ...``)."""

import sys

from ..cli import main

sys.exit(main())
