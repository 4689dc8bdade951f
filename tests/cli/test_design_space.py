"""``qzs optimize`` and ``qzs sensitivity`` (qzs.cli.design_space): files written, plans
printed, bad input refused with one line and exit 2, Ctrl-C keeping the generations."""
import pytest
import tomli_w

from qzs.cli import main

pytest.importorskip("pymoo")

PROBLEM = {
    "problem": {"name": "cli"},
    "variables": {"viscous_damping": {"low": 10.0, "high": 500.0},
                  "pi_kp": {"low": 1.0, "high": 1000.0, "scale": "log"}},
    "parameters": {"damping_gain": 0.0},
    "objectives": [{"metric": "linear_transmissibility_at", "frequency": 1.0},
                   {"metric": "linear_transmissibility_at", "frequency": 12.0}],
    "optimizer": {"population": 8, "generations": 2, "seed": 1},
}


@pytest.fixture
def problem_file(tmp_path):
    path = tmp_path / "cli.toml"
    path.write_text(tomli_w.dumps(PROBLEM))
    return path


def test_optimize_writes_the_store_and_every_result_file(problem_file, tmp_path, capsys):
    from qzs.workflows.design_space.result import OUTPUT_FILES

    out = tmp_path / "out"
    assert main(["optimize", str(problem_file), "--out", str(out), "--quiet"]) == 0
    printed = capsys.readouterr().out
    assert "16 designs evaluated in 2 generations" in printed
    assert sorted(p.name for p in out.iterdir()) == sorted([*OUTPUT_FILES, "cli.zarr"])
    # again: the store is in the way, and --resume continues it with nothing to evaluate
    assert main(["optimize", str(problem_file), "--out", str(out), "--quiet"]) == 2
    assert "--resume" in capsys.readouterr().err
    assert main(["optimize", str(problem_file), "--out", str(out), "--quiet", "--resume",
                 "--generations", "3"]) == 0
    assert "24 designs evaluated in 3 generations (8 now" in capsys.readouterr().out


def test_a_dry_run_prints_the_plan_and_writes_nothing(problem_file, tmp_path, capsys):
    assert main(["optimize", str(problem_file), "--dry-run", "--out", str(tmp_path / "o")]) == 0
    assert "8 designs x 2 generations" in capsys.readouterr().out
    assert not (tmp_path / "o").exists()


def test_a_bad_problem_file_is_one_line_and_exit_2(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    bad = dict(PROBLEM, variables={"pi_kpp": {"low": 1.0, "high": 2.0}})
    path.write_text(tomli_w.dumps(bad))
    assert main(["optimize", str(path), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "[variables] pi_kpp" in err and "not a parameter" in err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("option", ["--workers", "--generations", "--population"])
def test_counts_below_one_are_refused(problem_file, option, capsys):
    assert main(["optimize", str(problem_file), option, "0"]) == 2
    assert f"argument {option}: must be an integer >= 1, got 0" in capsys.readouterr().err


def _interrupt_the_second_generation(monkeypatch):
    """Ctrl-C while the search evaluates its second generation (the first is kept)."""
    from qzs.workflows.design_space import evaluation, optimizer

    calls = []

    def interrupted(*args, **kwargs):
        calls.append(None)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return evaluation.evaluate(*args, **kwargs)

    monkeypatch.setattr(optimizer, "evaluate", interrupted)


def test_ctrl_c_keeps_the_complete_generations_and_says_how_to_resume(problem_file, tmp_path,
                                                                      capsys, monkeypatch):
    _interrupt_the_second_generation(monkeypatch)
    out = tmp_path / "out"
    assert main(["optimize", str(problem_file), "--out", str(out), "--quiet"]) == 130
    err = capsys.readouterr().err
    assert "1 complete generation(s) are kept" in err and "--resume" in err


def test_sensitivity_writes_the_indices_and_their_figure(problem_file, tmp_path, capsys):
    out = tmp_path / "sens"
    assert main(["sensitivity", str(problem_file), "--method", "morris", "--samples", "4",
                 "--out", str(out), "--quiet"]) == 0
    from qzs.workflows.design_space.sensitivity import SENSITIVITY_FILES

    assert sorted(p.name for p in out.iterdir()) == sorted(SENSITIVITY_FILES)
    printed = capsys.readouterr().out
    assert "viscous_damping" in printed and "pi_kp" in printed


def test_sensitivity_refuses_a_base_count_that_is_not_a_power_of_two(problem_file, tmp_path,
                                                                      capsys):
    assert main(["sensitivity", str(problem_file), "--samples", "100",
                 "--out", str(tmp_path / "s")]) == 2
    assert "power of two" in capsys.readouterr().err
    assert not (tmp_path / "s").exists()


@pytest.mark.parametrize("population", ["3", "1"])
def test_a_population_below_the_files_minimum_is_refused_by_the_flag_too(problem_file, tmp_path,
                                                                         population, capsys):
    out = tmp_path / "o"
    assert main(["optimize", str(problem_file), "--population", population,
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "--population" in err and population in err
    assert ">= 4" in err and not out.exists()


def test_a_variable_outside_the_parameters_valid_range_is_refused(tmp_path, capsys):
    path = tmp_path / "mass.toml"
    bad = dict(PROBLEM, variables={**PROBLEM["variables"], "mass": {"low": -6.4, "high": 6.4}})
    path.write_text(tomli_w.dumps(bad))
    out = tmp_path / "o"
    assert main(["optimize", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "[variables] mass" in err and "-6.4" in err
    assert "valid range" in err and "positive" in err and not out.exists()


def test_a_problem_of_absurdly_long_runs_is_refused_before_any_run_or_store(tmp_path, capsys):
    path = tmp_path / "long.toml"
    long = dict(PROBLEM, objectives=[{"metric": "transmissibility_at", "frequency": 1.0},
                                     {"metric": "peak_stroke"}], analysis={"duration": 1e9})
    path.write_text(tomli_w.dumps(long))
    out = tmp_path / "o"
    assert main(["optimize", str(path), "--out", str(out), "--quiet"]) == 2
    # refused before the step's probes: its samples exceed the memory, as a simulation's
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "a 1e+09 s run at 1000 Hz keeps" in err, err
    assert "[analysis] duration" in err and "shorten the runs" in err
    assert not out.exists()
    # the same duration with linear metrics only simulates nothing: no refusal
    from qzs.workflows.design_space.optimizer import check_run_length
    from qzs.workflows.design_space.problem import load_problem

    linear = tmp_path / "linear.toml"
    linear.write_text(tomli_w.dumps(dict(PROBLEM, analysis={"duration": 1e9})))
    check_run_length(load_problem(linear))


def test_a_dry_run_speaks_in_units_and_words_and_simulates_nothing_for_linear_metrics(
        tmp_path, capsys):
    from qzs.model.registry import unit_of

    path = tmp_path / "exc.toml"
    document = dict(PROBLEM, variables={**PROBLEM["variables"],
                                        "excitation.amplitude": {"low": 0.001, "high": 0.01}},
                    uncertain={"mass": {"values": [5.0, 10.0, 15.0]},
                               "stiction_force": {"distribution": "uniform", "low": 5.0,
                                                  "high": 15.0}})
    path.write_text(tomli_w.dumps(document))
    assert main(["optimize", str(path), "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert "{" not in out and "'values'" not in out  # no Python dict
    amplitude = next(line for line in out.splitlines() if "excitation.amplitude" in line)
    assert amplitude.split()[-2] == unit_of("excitation.amplitude", "chirp") == "m"
    assert "5, 10, 15 kg" in out and "uniform 5 .. 15 N" in out
    # every metric is linear: no excitation, duration or step to describe
    assert "excitation," not in out and "dt" not in out and "no simulation" in out
    # a simulated metric brings them back
    document["objectives"] = [{"metric": "transmissibility_at", "frequency": 1.0},
                              {"metric": "linear_transmissibility_at", "frequency": 12.0}]
    path.write_text(tomli_w.dumps(document))
    assert main(["optimize", str(path), "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert "excitation," in out and "dt" in out and "no simulation" not in out


def test_a_resume_with_another_seed_is_one_line_naming_the_flag_and_both_values(
        problem_file, tmp_path, capsys, monkeypatch):
    """Exit 2 before any evaluation, the line naming --seed, the stored 1 and the asked 9;
    the store is left as it was; an interrupted search started with --seed says to resume
    with it."""
    from qzs.workflows.design_space import optimizer
    from qzs.workflows.design_space.store import stored_generations

    out = tmp_path / "out"
    assert main(["optimize", str(problem_file), "--out", str(out), "--quiet",
                 "--generations", "1"]) == 0
    capsys.readouterr()
    evaluate = optimizer.evaluate
    monkeypatch.setattr(optimizer, "evaluate", pytest.fail)
    assert main(["optimize", str(problem_file), "--out", str(out), "--quiet", "--resume",
                 "--generations", "2", "--seed", "9"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "--seed" in err and "= 9" in err and "--seed 1" in err
    assert stored_generations(out / "cli.zarr") == 1
    monkeypatch.setattr(optimizer, "evaluate", evaluate)

    _interrupt_the_second_generation(monkeypatch)
    seeded = tmp_path / "seeded"
    assert main(["optimize", str(problem_file), "--out", str(seeded), "--quiet",
                 "--seed", "9"]) == 130
    assert "--resume --seed 9" in capsys.readouterr().err
    monkeypatch.setattr(optimizer, "evaluate", evaluate)
    assert main(["optimize", str(problem_file), "--out", str(seeded), "--quiet", "--resume",
                 "--seed", "9"]) == 0


def test_the_default_folder_is_named_anew_for_a_search_and_replaced_for_indices(
        problem_file, tmp_path, monkeypatch, capsys):
    """optimize's folder holds its store (resumable work): kept, the new one cli-2/;
    sensitivity's indices are made again: cli-sensitivity/ replaced."""
    monkeypatch.chdir(tmp_path)
    search = [ "optimize", str(problem_file), "--quiet", "--generations", "1"]
    assert main(search) == 0, capsys.readouterr().err
    assert main(search) == 0, capsys.readouterr().err
    assert (tmp_path / "cli" / "cli.zarr").is_dir() and (tmp_path / "cli-2" / "cli.zarr").is_dir()
    assert "cli exists; writing cli-2 (--out names another)" in capsys.readouterr().err
    indices = ["sensitivity", str(problem_file), "--method", "morris", "--samples", "2",
               "--quiet"]
    assert main(indices) == 0, capsys.readouterr().err
    (tmp_path / "cli-sensitivity" / "older.txt").write_text("an older run's file")
    assert main(indices) == 0, capsys.readouterr().err
    assert not (tmp_path / "cli-sensitivity-2").exists()
    assert main([*indices, "--out", "cli-sensitivity"]) == 2
    assert "--out 'cli-sensitivity' exists" in capsys.readouterr().err
