"""What every subcommand shares (qzs.cli.common): strict JSON, ``--set`` pairs, bounded
integers, and the exit code chosen by the error's class, never by its message."""
import argparse
import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from qzs.cli.common import EXIT_CODES, integer_at_least, jsonable, run_handler, settings
from qzs.errors import (CaseError, DataError, FitError, MissingDependencyError,
                        ParameterError, SimulationError, Terminated, WriteError)


@dataclass
class _Point:
    x: float
    label: str


def test_jsonable_gives_strict_json_of_the_same_values():
    value = {"nan": math.nan, "inf": np.float64(np.inf), "count": np.int64(3),
             "flag": np.bool_(True), "array": np.array([1.5, np.nan]), "path": Path("a/b.nc"),
             "point": _Point(x=2.0, label="p"), 7: (1, {2}), "z": 1 + 2j}
    plain = jsonable(value)
    assert plain == {"nan": None, "inf": None, "count": 3, "flag": True, "array": [1.5, None],
                     "path": "a/b.nc", "point": {"x": 2.0, "label": "p"}, "7": [1, [2]],
                     "z": [1.0, 2.0]}
    assert json.loads(json.dumps(plain, allow_nan=False)) == plain
    assert type(plain["count"]) is int and type(plain["flag"]) is bool


def test_set_pairs_split_at_the_first_equals_sign():
    assert settings([" mass = 7 ", "excitation.kind=a=b"]) == {"mass": "7",
                                                               "excitation.kind": "a=b"}
    with pytest.raises(ParameterError, match="--set expects NAME=VALUE, got 'mass'"):
        settings(["mass"])


def test_integer_at_least_names_the_bound_and_the_value():
    parse = integer_at_least(8)
    assert parse("8") == 8
    for text, shown in (("7", "got 7"), ("x", "got 'x'"), ("8.5", "got '8.5'")):
        with pytest.raises(argparse.ArgumentTypeError, match=f"must be an integer >= 8, {shown}"):
            parse(text)


@pytest.mark.parametrize("error, code", [
    (SimulationError("diverged"), 1), (FitError("no fit"), 1),
    (WriteError("run.nc", "No space left on device"), 1),  # a DataError, yet a failed run
    (OSError(13, "Permission denied", "out.nc"), 1), (MemoryError(), 1),
    (ParameterError("bad"), 2), (CaseError(2, "bad"), 2), (DataError("bad log"), 2),
    (MissingDependencyError("zarr", "cluster", "sweeps"), 2),
    (KeyboardInterrupt(), 130), (Terminated(15), 143)])
def test_the_exit_code_follows_the_errors_class(error, code, capsys):
    def handler(args):
        raise error

    assert run_handler(handler, argparse.Namespace()) == code
    assert code in EXIT_CODES
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("qzs: ") and "Traceback" not in err


@pytest.mark.parametrize("argv, words, foreign", [
    (["simulate"], ["--sample-rate", "--out"], []),
    (["sweep", "s.toml"], ["batch_size", "time_series"], ["--sample-rate", "--out"]),
    (["response"], ["--range", "--workers"], ["--sample-rate", "--out"]),
    (["hexapod", "transmissibility"], ["--workers"], ["--out"]),
    (["params"], ["close other programs"], ["--sample-rate", "--out"]),
])
def test_the_out_of_memory_hint_names_the_commands_own_options(monkeypatch, capsys, argv,
                                                                words, foreign):
    """It used to tell sweep and response users to use --sample-rate and --out."""
    from qzs.cli import HANDLERS, main

    def handler(args):
        raise MemoryError()

    monkeypatch.setitem(HANDLERS, argv[0], handler)
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert err.startswith("qzs: error: out of memory; ") and err.count("\n") == 1
    for word in words:
        assert word in err, (word, err)
    for word in foreign:
        assert word not in err, (word, err)


def test_the_frequency_axis_option_takes_log_or_linear_and_defaults_to_the_setting(capsys):
    from qzs.cli.common import add_frequency_axis_option

    parser = argparse.ArgumentParser()
    add_frequency_axis_option(parser)
    assert parser.parse_args([]).frequency_axis is None   # FIGURES["frequency_scale"], log
    assert parser.parse_args(["--frequency-axis", "linear"]).frequency_axis == "linear"
    with pytest.raises(SystemExit) as stop:
        parser.parse_args(["--frequency-axis", "semilog"])
    assert stop.value.code == 2 and "invalid choice: 'semilog'" in capsys.readouterr().err


def _fake_compile(module="qzs.engine.fake"):
    """numba's compile events, as a kernel of ``module`` compiling would send them."""
    from numba.core import event

    def kernel():
        pass

    kernel.__module__ = module
    data = {"dispatcher": argparse.Namespace(py_func=kernel)}
    event.start_event("numba:compile", data=data)
    event.end_event("numba:compile", data=data)


def test_every_command_that_runs_kernels_names_real_families_and_real_commands():
    from qzs.cli import build_parser
    from qzs.cli.common import KERNEL_FAMILIES
    from qzs.engine.compiling import ENTRY_KERNELS

    commands = build_parser()._subparsers._group_actions[0].choices
    for name, families in KERNEL_FAMILIES.items():
        command, _, sub = name.partition(" ")
        assert command in commands, name
        if sub:
            assert sub in commands[command]._subparsers._group_actions[0].choices, name
        assert families and set(families) <= set(ENTRY_KERNELS), name
    for command in ("simulate", "paper", "study", "sweep", "response", "design", "experiment",
                    "app"):
        assert command in KERNEL_FAMILIES, command


@pytest.mark.parametrize("namespace, said", [
    (dict(command="simulate", quiet=False, json=False), "ticking"),
    (dict(command="simulate", quiet=True, json=False), "line"),
    (dict(command="hexapod", hexapod_command="simulate", json=True, quiet=False), "line"),
    (dict(command="hexapod", hexapod_command="linear"), "nothing"),  # runs no kernel
    (dict(command="params"), "nothing"),
])
def test_a_compile_inside_a_command_is_said_on_stderr_only(capsys, namespace, said):
    def handler(args):
        _fake_compile()
        print("result")
        return 0

    assert run_handler(handler, argparse.Namespace(**namespace)) == 0
    out, err = capsys.readouterr()
    assert out == "result\n"  # stdout is the command's alone (--json stays one JSON object)
    if said == "nothing":
        assert err == ""
    else:
        assert err.startswith("qzs: compiling the kernels once (about ")
        assert err.count("\n") == 1
        assert err.endswith("s)\n")  # no seconds: the compile took none


def _warning_handler(*warnings_to_raise):
    import warnings

    def handler(args):
        for message, category in warnings_to_raise:
            warnings.warn(message, category, stacklevel=1)
        print("result")
        return 0
    return handler


@pytest.mark.parametrize("namespace", [dict(command="params"),  # no kernel: no compile notice
                                       dict(command="simulate", quiet=False, json=False)])
def test_a_warning_inside_a_command_is_one_qzs_warning_line(capsys, namespace):
    """No category, no source file, no line number, no source text; lines joined."""
    from qzs.errors import DataWarning

    handler = _warning_handler(("3 non-finite samples\nof 1000 dropped", DataWarning),
                               ("invalid value encountered in divide", RuntimeWarning))
    assert run_handler(handler, argparse.Namespace(**namespace)) == 0
    out, err = capsys.readouterr()
    assert out == "result\n"
    assert err.splitlines() == ["qzs: warning: 3 non-finite samples of 1000 dropped",
                                "qzs: warning: invalid value encountered in divide"]
    assert "test_common.py" not in err and "Warning" not in err and "warnings.warn" not in err


def test_the_warning_display_is_python_s_again_after_the_command(capsys):
    import warnings

    before = warnings.showwarning
    run_handler(_warning_handler(), argparse.Namespace(command="params"))
    assert warnings.showwarning is before


def _silent_for(seconds, said=None):
    import time

    def handler(args):
        if said:
            print(said)
        time.sleep(seconds)
        return 0
    return handler


@pytest.mark.parametrize("quiet, first, notices", [(False, None, 1), (False, "progress", 0),
                                                   (True, None, 0)])
def test_a_command_silent_past_the_delay_says_it_has_started_once(capsys, monkeypatch, quiet,
                                                                  first, notices):
    """Silent for 0.4 s with a delay of 0.05 s: one notice on stderr, never on stdout (JSON
    stays clean), none after the command spoke first, none with --quiet or --json."""
    import argparse

    from qzs.cli import common

    monkeypatch.setattr(common, "START_NOTICE_DELAY", 0.05)
    args = argparse.Namespace(command="params", quiet=quiet, json=False)
    assert run_handler(_silent_for(0.4, first), args) == 0
    out, err = capsys.readouterr()
    assert err.count("qzs params: starting") == notices and "starting" not in out
    assert sys.stdout is not None and type(sys.stdout).__name__ != "_Watched"  # restored


def _progress_after(silence, open_for):
    """A handler silent for ``silence`` [s], then with a progress bar on stderr for
    ``open_for`` [s] (as the step search's bar: qzs.engine.progress.progress_bar)."""
    import time

    from qzs.engine.progress import progress_bar  # imported before the command starts

    def handler(args):
        time.sleep(silence)
        bar = progress_bar(total=2, desc="choosing dt", unit="run")
        bar.update(1)
        time.sleep(open_for)
        bar.update(1)
        bar.close()
        return 0
    return handler


@pytest.mark.parametrize("silence", [0.0, 0.5])
def test_the_start_notice_never_comes_after_a_progress_bar_on_stderr(capsys, monkeypatch,
                                                                      silence):
    """stderr as the user reads it: a progress bar drawn at once (the command spoke, on
    stderr) and open long past the delay is never followed by "starting ..."; a command
    silent past the delay says it has started, once, before its bar."""
    import argparse

    from qzs.cli import common

    monkeypatch.setattr(common, "START_NOTICE_DELAY", 0.2)
    args = argparse.Namespace(command="simulate", quiet=False, json=False)
    assert run_handler(_progress_after(silence, 0.6), args) == 0
    out, err = capsys.readouterr()
    notice = "qzs simulate: starting"
    assert "choosing dt" in err and out == ""
    assert err.count(notice) == 1 if silence else err.count(notice) <= 1
    if notice in err:
        assert err.index(notice) < err.index("choosing dt"), err


def test_a_quick_command_prints_no_start_notice(capsys):
    import argparse

    args = argparse.Namespace(command="params", quiet=False, json=False)
    assert run_handler(_silent_for(0.0), args) == 0
    import time

    time.sleep(1.2)  # past the real delay: the notice was cancelled, not merely late
    assert "starting" not in capsys.readouterr().err


# ---------------------------------------------------------------- outputs named or not
def output_parser():
    """A command with a default store (named anew) and a default figure (replaced)."""
    from qzs.cli.common import add_output_options

    parser = argparse.ArgumentParser()
    add_output_options(parser, out=dict(metavar="STORE.zarr", default="runs.zarr",
                                        unnamed="rename", help="the store"),
                       plot=dict(default="figure.png", help="the figure"))
    return parser


def test_an_output_the_user_named_is_refused_and_a_default_one_replaced_or_named_anew(
        tmp_path, monkeypatch, capsys):
    from qzs.cli.common import check_output, output_name
    from qzs.errors import OutputPathError

    monkeypatch.chdir(tmp_path)
    (tmp_path / "figure.png").write_text("old")
    (tmp_path / "runs.zarr").mkdir()
    (tmp_path / "runs.zarr" / "kept").write_text("hours of work")
    args = output_parser().parse_args([])
    assert check_output(args, "--plot", args.plot, suffixes=(".png",)) == Path("figure.png")
    assert check_output(args, "--out", args.out, suffixes=(".zarr",),
                        directory=True) == Path("runs-2.zarr")
    assert "runs.zarr exists; writing runs-2.zarr (--out names another)" in capsys.readouterr().err
    assert output_name(args, "--out", args.out, directory=True,   # --resume: the default
                       resume=True) == (Path("runs.zarr"), False)
    # the same names, given by the user: refused, and replaced only with --overwrite
    args = output_parser().parse_args(["--out", "runs.zarr", "--plot", "figure.png"])
    for option, path, directory in (("--plot", "figure.png", False),
                                    ("--out", "runs.zarr", True)):
        with pytest.raises(OutputPathError, match=f"--overwrite to replace") as error:
            check_output(args, option, path, suffixes=None, directory=directory)
        assert (error.value.argument, error.value.value) == (option, path)
    args = output_parser().parse_args(["--plot", "figure.png", "--overwrite"])
    assert check_output(args, "--plot", "figure.png", suffixes=(".png",)) == Path("figure.png")
    args = output_parser().parse_args(["--overwrite"])   # the default store, replaced as asked
    assert check_output(args, "--out", args.out, suffixes=(".zarr",),
                        directory=True) == Path("runs.zarr")
    assert (tmp_path / "runs.zarr" / "kept").read_text() == "hours of work"


def test_a_default_output_without_a_policy_is_a_programming_error():
    from qzs.cli.common import add_output_options

    with pytest.raises(ValueError, match="unnamed"):
        add_output_options(argparse.ArgumentParser(),
                           out=dict(metavar="DIR", default="results", help="folder"))


@pytest.mark.parametrize("argv, families", [
    (["simulate"], ("single",)),
    (["simulate", "--set", "compensation.fraction=0.8"], ("single_blocks",)),
    (["simulate", "--set", "pi_kp=80", "--set", "dither.amplitude=2"], ("single_blocks",)),
    (["simulate", "--controller", "{blocks}"], ("single_blocks",)),
    (["simulate", "--config", "{blocks}"], ("single_blocks",)),
    (["simulate", "--config", "{blocks}", "--controller", "{plain}"], ("single",)),
    (["simulate", "--controller", "{missing}"], ("single",)),
    (["sweep", "x.toml"], ("single", "batch")),
])
def test_a_controller_with_blocks_names_the_blocks_kernel(tmp_path, argv, families):
    """The compile notice's estimate counts the kernel the run will compile: a controller
    with blocks runs ``lanes.run_single_blocks``, not ``run_single``."""
    from qzs.cli import build_parser
    from qzs.cli.common import kernel_families

    (tmp_path / "blocks.toml").write_text("[controller.linear]\nnum = [1.0]\nden = [1.0, 2.0]\n")
    (tmp_path / "plain.toml").write_text("[controller]\npi_kp = 60\n")
    paths = {key: str(tmp_path / f"{key}.toml") for key in ("blocks", "plain", "missing")}
    args = build_parser().parse_args([a.format(**paths) for a in argv])
    assert kernel_families(args) == families
