"""Command line: ``neurohover COMMAND --help`` for each command.

One module per group of commands (``flying``: fly, demo, bench; ``learning``: evolve, learn-model,
build-policies; ``agents``: compete; ``evaluate``: evaluate-agent; ``reproduce``: reproduce, results,
wins, report; ``plots``: plot), each with a ``register(subparsers)``; the options several commands
share live in ``options``, which imports no command (no cycle); ``app`` builds the parser and runs ``main``.
"""

from .app import build_parser, main

__all__ = ["build_parser", "main"]
