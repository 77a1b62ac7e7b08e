"""``python -m neurohover``: the same command line as ``neurohover``."""

import os
import sys

try:
    from .cli import main
except KeyboardInterrupt:  # Ctrl-C while the package imports: an interruption, not a traceback
    print("neurohover: interrupted", file=sys.stderr, flush=True)
    os._exit(130)  # as the package's hook does: a half-imported numba's exit handlers died by SIGINT (-2)

sys.exit(main())
