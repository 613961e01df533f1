"""The ``phaseimpact`` console script: a Ctrl-C while the command line is still being imported ends
like one during a command (one line, exit 130), not with a traceback from the import machinery."""

import sys


def main() -> int:
    try:
        from .cli import main as command_line
    except KeyboardInterrupt:
        print("phaseimpact: interrupted", file=sys.stderr)
        return 130
    return command_line()
