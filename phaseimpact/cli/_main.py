"""``main``: the law files, the parser, the command, and every way a run ends as one line and an exit code."""

from __future__ import annotations

import os
import re
import signal
import sys
import threading

from ._case import _setting_names
from ._common import EXIT_BROKEN_PIPE, EXIT_FAILURE, EXIT_USAGE, _stopped
from .commands import build_parser, find


def _load_law_files(argv) -> tuple[list, dict]:
    """Run the files of ``--law-file FILE.py`` (they register laws with phaseimpact.define_law);
    return ``argv`` without them, so that every command takes them (``plot`` and ``info`` of an
    archive of a user law too), and ``{path: names of the laws it defines}``."""
    rest, i, files = [], 0, {}
    while i < len(argv):
        arg = argv[i]
        if arg == "--":
            rest.extend(argv[i:])
            break
        path = arg.split("=", 1)[1] if arg.startswith("--law-file=") else (
            argv[i + 1] if arg == "--law-file" and i + 1 < len(argv) else None)
        if path is None:
            rest.append(arg)
            i += 1
            continue
        from ..model.userlaw import load_law_file

        files[path] = load_law_file(path)
        i += 1 if arg.startswith("--law-file=") else 2
    return rest, files


def _law_of_files(args, files: dict) -> None:
    """``--law-file`` without ``--law``: the file's one law (unless the case names a user law); a
    shipped law of the case, paper by default, would silently ignore the file."""
    from ..model import LAWS

    if not files or not hasattr(args, "law") or args.command == "check-law" or args.law is not None \
            or "law" in _setting_names(args):
        return
    defined = [name for names in files.values() for name in names]
    case = getattr(args, "case", None)
    if case is not None and case.impact["law"] not in LAWS:
        return
    from ..model.userlaw import single_law

    args.law = single_law(defined, " and ".join(files), "--law NAME")


_ANSI_ESCAPE = re.compile(r"\x1b\[[0-9;]*[A-Za-z]")


class _StandardOutput:
    """``sys.stdout`` for a command: a failed write names the standard output (``> /dev/full``: the disk
    is full, but no file of ours); characters its encoding lacks are written as escapes
    (``PYTHONIOENCODING=ascii``), not an error half way through the output."""

    def __init__(self, stream):
        self._stream = stream

    def write(self, text: str) -> int:
        try:
            return self._stream.write(text)
        except UnicodeEncodeError as error:
            return self._stream.write(text.encode(error.encoding, "backslashreplace").decode(error.encoding))
        except BrokenPipeError:
            raise
        except OSError as error:
            raise OSError(error.errno, error.strerror or str(error), "standard output") from None

    def flush(self) -> None:
        try:
            self._stream.flush()
        except BrokenPipeError:
            raise
        except OSError as error:
            raise OSError(error.errno, error.strerror or str(error), "standard output") from None

    def __getattr__(self, name):
        return getattr(self._stream, name)


def main(argv=None) -> int:
    # Ctrl-C and SIGTERM, wherever they arrive (compiled runs included): one line, exit 130 or 143
    previous_term = signal.getsignal(signal.SIGTERM)
    try:
        argv = list(sys.argv[1:] if argv is None else argv)
        if any(arg == "--law-file" or arg.startswith("--law-file=") for arg in argv):
            from .. import _signals  # a law file compiles (seconds): Ctrl-C and SIGTERM end it with one line

            _signals.install_command_line()
        parsed, law_files = _load_law_files(argv)  # before the parser: its --law choices include the file's laws
        parser = build_parser()
        args = parser.parse_args(parsed)
        args.argv = argv
        args.parser = parser  # the completion script is written from the parser that read the command
        _law_of_files(args, law_files)
        if find(args.command).integrates:  # _signals imports numba (0.2 s): only where runs are stopped
            from .. import _signals

            _signals.install_command_line()
        stdout, sys.stdout = sys.stdout, _StandardOutput(sys.stdout)
        try:
            code = args.func(args)
            sys.stdout.flush()  # a full standard output fails here, named, not at the interpreter's exit
        finally:
            sys.stdout = stdout
        return code
    except ValueError as error:  # one line, without the colour escapes numba puts in its messages
        print(f"phaseimpact: error: {_ANSI_ESCAPE.sub('', str(error))}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt as stop:
        if not getattr(stop, "reported", False):
            print(f"phaseimpact: {_stopped(stop)}", file=sys.stderr)
        from .. import _signals

        return _signals.exit_code(stop)
    except BrokenPipeError:  # the reader of stdout went away (| head): nothing more to say
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError, AttributeError):
            pass
        return EXIT_BROKEN_PIPE
    except OSError as error:  # the disk, not the input: full, gone, permissions changed under us
        print(f"phaseimpact: error: {error}", file=sys.stderr)
        return EXIT_FAILURE
    finally:
        if previous_term is not None and threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGTERM, previous_term)  # main() called in-process (tests) leaves it as it was
