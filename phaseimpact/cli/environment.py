"""The installation: shell completion (``completion``) and the engine's compiled cache (``warmup``)."""

from __future__ import annotations

import argparse

from ..settings import SETTABLE
from . import _options as options
from ._common import EXIT_OK, _print_json


def add_completion(p) -> None:
    p.add_argument("shell", choices=("bash", "zsh"), help="the shell")


def run_completion(args) -> int:
    import shtab

    parser = args.parser
    preamble = _complete_values(parser)
    script = shtab.complete(parser, shell=args.shell, root_prefix="phaseimpact", preamble=preamble)
    if args.shell == "bash":
        # "--set NAME=" is followed by its value, not by a space: shtab's function runs its helpers in a
        # subshell, where compopt has no effect, so a wrapper says it after them
        script += ("\n_phaseimpact() {\n  _shtab_phaseimpact \"$@\"\n"
                   "  [[ ${#COMPREPLY[@]} -gt 0 && ${COMPREPLY[0]} == *= ]] && compopt -o nospace 2>/dev/null\n"
                   "  return 0\n}\ncomplete -o bashdefault -F _phaseimpact phaseimpact\n")
    print(script)
    return EXIT_OK


def _complete_values(parser) -> dict:
    """Tell shtab what each value completes to (an action's ``complete``): files for paths, the shipped
    cases and ``.toml`` files for ``--case``, the laws and ``.py`` files for ``check-law``, ``.py`` files
    for ``--law-file``, ``NAME=`` for ``--set``. Returns the shell functions this needs, by shell."""
    from ..case import list_cases
    from ..model import REGISTRY

    cases, laws = " ".join(c["name"] for c in list_cases()), " ".join(REGISTRY)
    names = " ".join(f"{name}=" for name in SETTABLE)
    kinds = {  # dest -> (bash function, zsh action); bash functions named *_file complete as file names
        "case": ("_phaseimpact_compgen_case_file", "_phaseimpact_case"),
        "set": ("_phaseimpact_compgen_setting", "_phaseimpact_setting"),
        "law_file": ("_phaseimpact_compgen_py_file", "_files -g '*.py'"),
        "law": ("_phaseimpact_compgen_law_file", "_phaseimpact_law_or_file"),
        "out": ("_shtab_compgen_files", "_files"), "archive": ("_shtab_compgen_files", "_files"),
        "curve": ("_shtab_compgen_files", "_files"),
    }
    for command in next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices.values():
        for action in command._actions:
            if action.dest in kinds and not (action.dest == "law" and action.option_strings):  # --law: choices
                bash, zsh = kinds[action.dest]
                action.complete = {"bash": bash, "zsh": zsh}
    bash = f"""
_phaseimpact_compgen_case_file() {{
  compgen -W "{cases}" -- "$1"; compgen -d -- "$1"; compgen -f -X '!*.toml' -- "$1"
}}
_phaseimpact_compgen_py_file() {{
  compgen -d -- "$1"; compgen -f -X '!*.py' -- "$1"
}}
_phaseimpact_compgen_law_file() {{
  compgen -W "{laws}" -- "$1"; compgen -d -- "$1"; compgen -f -X '!*.py' -- "$1"
}}
_phaseimpact_compgen_setting() {{
  compgen -W "{names}" -- "$1"
}}
"""
    zsh = f"""
_phaseimpact_case() {{
  _alternative 'cases:shipped case:({cases})' 'files:case file:_files -g "*.toml"'
}}
_phaseimpact_law_or_file() {{
  _alternative 'laws:law:({laws})' 'files:law file:_files -g "*.py"'
}}
_phaseimpact_setting() {{
  compadd -S '' -- {names}
}}
"""
    return {"bash": bash, "zsh": zsh}


def add_warmup(p) -> None:
    options.json_option(p)


def run_warmup(args) -> int:
    from ..integrate.precompile import warmup

    out = warmup()
    if args.json:
        _print_json(args, out)
    elif out["cache"] is None:
        print(f"compiled in {out['seconds']:.1f} s for this process only: nothing is cached ({out['reason']})")
    else:
        done = "compiled" if out["compiled"] else "already compiled; loaded"
        print(f"{done} in {out['seconds']:.1f} s; cache: {out['cache']} ({out['source']}; {out['files']} files, "
              f"{out['bytes'] / 1e6:.1f} MB)")
    return EXIT_OK
