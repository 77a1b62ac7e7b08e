"""``python -m neurohover``: the same command line as ``neurohover``."""

import sys

from .cli import main  # a Ctrl-C while it imports: the package's hook (neurohover/__init__.py) ends it with one line

sys.exit(main())
