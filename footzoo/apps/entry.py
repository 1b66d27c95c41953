"""The ``footzoo`` console script: :func:`footzoo.apps.cli.main`, with Ctrl-C handled from the first instant.

The command line imports numpy, pandas and the readers as it starts; a Ctrl-C then (the user changed their
mind) ends the command with exit code 130 and one line, as it does once the command runs, not with a
traceback through the import machinery.
"""

from __future__ import annotations

import sys


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``footzoo`` console script; returns the exit code (130: interrupted)."""
    try:
        from .cli import main as run

        return run(argv)
    except KeyboardInterrupt:
        print("footzoo: interrupted", file=sys.stderr)
        return 130
