"""The command table (phaseimpact/cli/commands.py): the parser is built from it, and a new command is one
module and one entry. The example of the table's guide is run as written: its module and its entry are
read from the guide, added, run through ``main`` and removed."""

import argparse
import contextlib
import json
import re
import textwrap
import types

from _cli import run

from phaseimpact.cli import COMMANDS, JSON_SCHEMA_VERSION, Command, build_parser, commands


@contextlib.contextmanager
def added(command: Command):
    """``command`` in the table inside, the table as it was after (later tests build the parser)."""
    before = list(COMMANDS)
    COMMANDS.append(command)
    try:
        yield
    finally:
        COMMANDS[:] = before


def guide_example() -> tuple[types.ModuleType, Command]:
    """The guide's module, executed as ``phaseimpact/cli/greeting.py`` would be, and its table entry."""
    code = textwrap.dedent(commands.__doc__.split("::\n", 1)[1])
    module_code, entry_code = code.split("# in COMMANDS\n")
    module = types.ModuleType("phaseimpact.cli.greeting")
    module.__package__ = "phaseimpact.cli"  # its relative imports are those of a module of the package
    exec(compile(module_code, "greeting.py", "exec"), module.__dict__)
    entry = eval(entry_code.strip().rstrip(","), {"Command": Command, "greeting": module})
    return module, entry


def _subcommands(parser) -> dict:
    return next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices


def test_the_parser_has_the_tables_commands_in_its_order_each_running_its_run():
    commands_ = _subcommands(build_parser())
    assert list(commands_) == [command.name for command in COMMANDS]
    assert all(commands_[c.name].get_default("func") is c.run for c in COMMANDS)


def test_the_guides_example_is_one_module_and_one_entry_that_runs_through_main():
    module, entry = guide_example()
    assert (entry.name, entry.add, entry.run, entry.integrates) == ("greet", module.add_greet, module.run_greet, False)
    with added(entry):
        code, out, err = run(["greet", "--name", "Abrate", "--json"])
        assert (code, err) == (0, "")
        assert json.loads(out) == {"schema_version": JSON_SCHEMA_VERSION, "command": "greet",
                                   "greeting": "hello, Abrate"}
        assert run(["greet"]) == (0, "hello, world\n", "")
        code, out, _ = run(["--help"])
        assert code == 0 and re.search(r"greet\s+print a greeting", out)
        # its options are checked like every other command's: an unknown one is refused, exit 2
        code, _, err = run(["greet", "--names", "x"])
        assert code == 2 and "unrecognized arguments: --names x" in err
        greet = _subcommands(build_parser())["greet"]
        assert greet.description == "Print a greeting." and greet.epilog is None  # it takes no --set
    code, _, err = run(["greet"])
    assert code == 2 and "command = 'greet' is out of range" in err  # removed with the context
    assert [c.name for c in COMMANDS].count("greet") == 0


def test_a_command_that_takes_set_lists_the_settable_quantities():
    parsers = _subcommands(build_parser())
    with_set = [name for name, p in parsers.items() if any(a.dest == "set" for a in p._actions)]
    assert "params" in with_set and "cases" not in with_set
    assert all(parsers[name].epilog.startswith("Settable with --set NAME=VALUE") for name in with_set)
    assert all(p.epilog is None for name, p in parsers.items() if name not in with_set)
