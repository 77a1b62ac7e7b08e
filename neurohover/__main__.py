"""``python -m neurohover``: the same command line as ``neurohover``."""

import sys

from .cli import main

sys.exit(main())
