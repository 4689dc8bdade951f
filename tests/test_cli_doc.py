"""docs/workflows/command-line.md keeps its promises: read from the page, checked against the parser.

The page promises the exit codes (its table), which subcommands take ``--json`` (its list),
the output options of every subcommand that writes (its table: ``--out``, ``--plot``, then
``--json``, ``--quiet`` and ``--overwrite`` on each), one overwrite policy (an existing output
is refused without ``--overwrite``), and that output paths (``--out``, ``--plot``,
``--toml``) are checked before any work starts, on every subcommand that has them. Each promise is parsed out of the page's text, so that
editing the page or the parser without the other fails here. (SIGTERM's cleanup is checked
in tests/test_cli_contract.py and tests/engine/test_driver.py.)
"""
import argparse
import os
import re
import time
from pathlib import Path

import pytest

from qzs.cli import build_parser, main
from qzs.cli.common import EXIT_CODES

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "workflows" / "command-line.md"
DATA = ROOT / "examples" / "data"
#: A bad output path must fail within this [s], once Python's imports are warm.
AT_ONCE = 2.0


def page():
    return PAGE.read_text(encoding="utf-8")


def bullet(starts):
    """The page's contract bullet that starts with ``starts``, as one line of text."""
    items = re.split(r"\n- ", page().split("Every subcommand keeps one contract:", 1)[1])
    found = [" ".join(item.split()) for item in items if item.lstrip("- ").startswith(starts)]
    assert len(found) == 1, f"no single bullet starting with {starts!r} on {PAGE}"
    return found[0]


def commands(parser=None, prefix=()):
    """``(command path, parser)`` of every subcommand that takes options of its own."""
    parser = parser or build_parser()
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                if any(isinstance(a, argparse._SubParsersAction) for a in sub._actions):
                    yield from commands(sub, (*prefix, name))
                else:
                    yield " ".join((*prefix, name)), sub


def options(parser):
    return {option for action in parser._actions for option in action.option_strings}


# ---------------------------------------------------------------- exit codes
def test_the_exit_code_table_is_the_parsers():
    table = {int(code): text for code, text in
             re.findall(r"^\| (\d+) \| (.+?) \|$", page(), flags=re.MULTILINE)}
    assert set(table) == set(EXIT_CODES)
    assert "bad input" in table[2] and "Ctrl-C" in table[130] and "SIGTERM" in table[143]


# ---------------------------------------------------------------- --json
def test_the_json_list_is_every_subcommand_with_json():
    text = bullet("`--json` (on ")
    listed = set(re.findall(r"`([a-z][a-z -]*)`", text.split(")", 1)[0]))
    having = {name for name, parser in commands() if "--json" in options(parser)}
    assert listed == having, (f"on the page, not in the parser: {sorted(listed - having)}; "
                              f"in the parser, not on the page: {sorted(having - listed)}")


def test_the_frequency_axis_list_is_every_subcommand_that_draws_frequency():
    text = bullet("`--frequency-axis` (on ")
    listed = set(re.findall(r"`([a-z][a-z -]*)`", text.split(")", 1)[0]))
    having = {name for name, parser in commands() if "--frequency-axis" in options(parser)}
    assert listed == having, (f"on the page, not in the parser: {sorted(listed - having)}; "
                              f"in the parser, not on the page: {sorted(having - listed)}")


# ---------------------------------------------------------------- output paths
#: The arguments each subcommand needs besides its output path, and a valid name for each
#: output option (the check under test is the folder's, not the extension's).
NEEDS = {
    "simulate": [],
    "paper": ["--quick"],
    "study": ["stiction", "--quick"],
    "experiment": [str(DATA / "experiment.csv"), "--map", str(DATA / "experiment_map.toml"),
                   "--no-simulation"],
    "sweep": ["pi_vs_stiction"],
    "sweep-plot": ["{tmp}/missing.zarr"],
    "sweep-export": ["{tmp}/missing.zarr"],
    "params": [],
    "hexapod linear": [],
    "hexapod simulate": [],
    "hexapod transmissibility": [],
    "hexapod study": ["--quick"],
    "design": ["--quick"],
    "response": [],
    "optimize": ["isolation_vs_effort"],
    "sensitivity": ["isolation_vs_effort"],
    "export controller": [],
    "export fmu": [],
}
NAMES = {"--toml": "p.toml", "--plot": "figure.png", "sweep --out": "store.zarr",
         "simulate --out": "run.nc", "hexapod simulate --out": "run.nc",
         "response --out": "response.nc", "sweep-plot --out": "figure.png",
         "sweep-export --out": "sweep.mat", "export controller --out": "controller.c",
         "export fmu --out": "isolator.fmu"}


def promised_options():
    return re.findall(r"`(--[a-z]+)`", bullet("output paths (").split(")", 1)[0])


def output_cases():
    promised = promised_options()
    for name, parser in commands():
        for option in sorted(options(parser) & set(promised)):
            yield name, option


def test_the_page_names_the_output_options():
    assert promised_options() == ["--out", "--plot", "--toml"]
    having = {name for name, _ in output_cases()}
    assert having == set(NEEDS), ("every subcommand with an output option needs a line in "
                                  f"NEEDS: {sorted(having ^ set(NEEDS))}")
    assert "`paper` and `study` too" in bullet("output paths (")


@pytest.mark.parametrize("command, option", list(output_cases()),
                         ids=[f"{c} {o}" for c, o in output_cases()])
def test_every_output_path_is_checked_before_any_work(tmp_path, monkeypatch, capsys, command,
                                                      option):
    """A path under a file (it cannot be created): exit 2 at once, the option named, the
    folder as it was."""
    blocker = tmp_path / "a-file"
    blocker.write_text("in the way")
    monkeypatch.chdir(tmp_path)
    name = NAMES.get(f"{command} {option}", NAMES.get(option, "out"))
    argv = [*command.split(), *[a.replace("{tmp}", str(tmp_path)) for a in NEEDS[command]],
            option, str(blocker / name)]
    if "--quiet" in options(dict(commands())[command]):
        argv.append("--quiet")
    before = sorted(os.listdir(tmp_path))
    main(argv)  # Python's imports, once
    capsys.readouterr()
    began = time.perf_counter()
    code = main(argv)
    elapsed = time.perf_counter() - began
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.startswith(f"qzs: error: {option} ") and "is a file, not a folder" in err, err
    assert err.count("\n") == 1
    assert elapsed < AT_ONCE, f"{argv} took {elapsed:.2f} s to fail"
    assert sorted(os.listdir(tmp_path)) == before


# ---------------------------------------------------------------- output options, overwrite
WRITES = ("--out", "--plot")


def output_rows():
    """The page's table: command -> (its --out cell, its --plot cell, what becomes of a
    default output that exists)."""
    rows = re.findall(r"^\s*\| `([a-z][a-z -]*)` \|([^|\n]*)\|([^|\n]*)\|([^|\n]*)\|\s*$",
                      page(), flags=re.MULTILINE)
    return {name: (out.strip(), plot.strip(), fate.strip()) for name, out, plot, fate in rows}


def output_table():
    """The page's table: command -> (takes --out, takes --plot)."""
    return {name: (bool(out), bool(plot)) for name, (out, plot, _) in output_rows().items()}


def test_the_output_table_is_every_subcommand_that_writes_with_what_it_writes():
    table = output_table()
    having = {name: ("--out" in options(parser), "--plot" in options(parser))
              for name, parser in commands() if set(WRITES) & options(parser)}
    assert len(table) >= 15
    assert table == having, ({k: (table.get(k), having.get(k)) for k in set(table) | set(having)
                              if table.get(k) != having.get(k)})


#: The page's words for each policy of qzs.cli.common.UNNAMED.
FATES = {"replaced": "replace", "named anew": "rename"}


def test_what_becomes_of_a_default_output_is_the_pages_and_the_helps():
    """Every output with a default (in the parser, or "default ..." in the page's cell, made
    by the command) declares what becomes of an existing one; the page's last column and
    the option's help say the same, and an output without a default says nothing."""
    from qzs.cli.common import UNNAMED

    parsers = dict(commands())
    for name, (out, plot, fate) in output_rows().items():
        declared = parsers[name].get_default("unnamed_outputs")
        help_texts = {action.option_strings[0]: action.help
                      for action in parsers[name]._actions if action.option_strings}
        with_default = {option for option, cell in (("--out", out), ("--plot", plot))
                        if "default" in cell and "default none" not in cell}
        assert set(declared) == with_default, name
        for option in with_default:
            assert parsers[name].get_default(option.strip("-")) is None or option in declared
        assert {FATES.get(fate)} == (set(declared.values()) or {None}), (name, fate, declared)
        for option, policy in declared.items():
            phrase = ("replaced if it exists" if option == "--plot" else UNNAMED[policy])
            assert phrase in " ".join(help_texts[option].split()), (name, option)


def test_every_subcommand_that_writes_takes_every_output_option_once():
    """--json, --quiet and --overwrite wherever --out or --plot is, from one declaration."""
    from qzs.cli.common import OUTPUT_OPTIONS

    assert "`--overwrite`" in bullet("the output options are spelled")
    for name, parser in commands():
        if set(WRITES) & options(parser):
            missing = set(OUTPUT_OPTIONS) - set(WRITES) - options(parser)
            assert not missing, f"qzs {name} lacks {sorted(missing)}"
            help_texts = {action.option_strings[0]: action.help for action in parser._actions
                          if action.option_strings}
            assert help_texts["--overwrite"].startswith("replace an existing output that you "
                                                        "named"), name
            if "--plot" in help_texts:
                assert "'none' for no figure" in help_texts["--plot"], name


def test_plot_none_draws_no_figure(tmp_path, monkeypatch, capsys):
    """Refused by `hexapod linear` and `hexapod simulate` before (a file named 'none')."""
    from qzs.cli.common import figure_path

    monkeypatch.chdir(tmp_path)
    for command in ("simulate", "response", "hexapod linear", "hexapod simulate"):
        args = build_parser().parse_args([*command.split(), "--plot", "none"])
        assert figure_path(args) is None, command
        assert figure_path(build_parser().parse_args([*command.split(), "--plot", "f.png"])) \
            == "f.png"
    assert main(["hexapod", "linear", "--plot", "none", "--json"]) == 0, capsys.readouterr().err
    assert "plot" not in capsys.readouterr().out and os.listdir(tmp_path) == []


@pytest.mark.parametrize("command, option", list(output_cases()),
                         ids=[f"{c} {o}" for c, o in output_cases()])
def test_an_existing_output_is_refused_without_overwrite(tmp_path, monkeypatch, capsys, command,
                                                        option):
    """One policy: what exists (a file, a folder holding anything) is kept, the message names
    the option, the path and --overwrite; before any work (the same bound as above)."""
    monkeypatch.chdir(tmp_path)
    name = NAMES.get(f"{command} {option}", NAMES.get(option, "out"))
    path = tmp_path / name
    folder = name == "out" or name.endswith(".zarr")
    if folder:
        path.mkdir()
        (path / "keep.txt").write_text("mine")
    else:
        path.write_text("mine")
    argv = [*command.split(), *[a.replace("{tmp}", str(tmp_path)) for a in NEEDS[command]],
            option, str(path)]
    if "--quiet" in options(dict(commands())[command]):
        argv.append("--quiet")
    began = time.perf_counter()
    code = main(argv)
    elapsed = time.perf_counter() - began
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.startswith(f"qzs: error: {option} {str(path)!r} exists"), err
    assert "--overwrite" in err and err.count("\n") == 1
    assert elapsed < 30 * AT_ONCE, f"{argv} took {elapsed:.2f} s to fail"
    kept = path / "keep.txt" if folder else path
    assert kept.read_text() == "mine"
    assert sorted(os.listdir(tmp_path)) == [name]
