"""``python -m neurohover``: the same command line as ``neurohover``."""

import sys

try:
    from .cli import main
except KeyboardInterrupt:  # Ctrl-C while the package imports: an interruption, not a traceback
    print("neurohover: interrupted", file=sys.stderr)
    sys.exit(130)

sys.exit(main())
