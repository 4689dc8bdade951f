"""`qzs simulate`: --duration as in the API, unused options refused, --json, summary warnings."""
import json
import os

import numpy as np
import pytest

from qzs import Chirp, ControllerParameters, IsolatorParameters, RandomExcitation, Sine, simulate
from qzs.analysis.summary import run_warnings
from qzs.cli import main
from qzs.iotools import read_result, save_config
from qzs.iotools.cf_layout import from_file_layout


@pytest.mark.parametrize("flags, excitation", [
    ([], Chirp()),
    (["--excitation-duration", "60"], Chirp(duration=60.0)),
    (["--excitation", "random", "--seed", "3"], RandomExcitation(seed=3)),
])
def test_cli_and_api_give_the_same_base_motion_for_the_same_duration(tmp_path, flags, excitation):
    """`--duration 5` is 5 s of simulated time, as `simulate(..., duration=5)`: the same base
    motion sample for sample (the chirp is not squeezed into the 5 s)."""
    out = tmp_path / "run.nc"
    assert main(["simulate", *flags, "--duration", "5", "--sample-rate", "100", "--out", str(out),
                 "--plot", "none", "--quiet", "--dt", "1e-4"]) == 0
    api = simulate(excitation, duration=5.0, sample_rate=100.0, dt=1e-4)
    data = read_result(out)
    np.testing.assert_array_equal(data["base_displacement"].values, api.base_displacement)
    np.testing.assert_array_equal(data["relative_position"].values, api.relative_position)


def test_a_cut_chirp_says_which_band_it_covered(capsys):
    assert main(["simulate", "--duration", "30", "--sample-rate", "100", "--plot", "none",
                 "--quiet"]) == 0
    head = capsys.readouterr().out.splitlines()[0]
    assert head.startswith("qzs simulation  Chirp 0-20 Hz over 2000 s: first 30 s run "
                           "(0-0.3 Hz), ode3 dt = "), head


@pytest.mark.parametrize("argv, flag", [
    (["--frequency", "3"], "`--frequency`"),
    (["--record", "base.csv"], "`--record`"),
    (["--excitation", "sine", "--seed", "4"], "`--seed`"),
    (["--excitation", "sine", "--excitation-duration", "20"], "`--excitation-duration`"),
    (["--excitation", "sine", "--f0", "1"], "`--f0`"),
    (["--excitation", "random", "--method", "logarithmic"], "`--method`"),
])
def test_an_option_the_excitation_does_not_use_is_an_error(tmp_path, capsys, argv, flag):
    plot = tmp_path / "never.png"
    assert main(["simulate", *argv, "--duration", "1", "--plot", str(plot), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert flag in err and "is not used by a" in err
    assert not plot.exists()


def test_a_config_option_of_another_kind_is_named_with_its_file(tmp_path, capsys):
    config = save_config(tmp_path / "c.toml", excitation={"kind": "sine", "frequency": 2.0})
    assert main(["simulate", "--config", str(config), "--excitation", "chirp", "--duration", "1",
                 "--plot", "none", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "`frequency` in the [excitation] table of" in err and "c.toml" in err


def test_json_summary_is_strict_json_with_the_statistics(capsys):
    assert main(["simulate", "--excitation", "sine", "--frequency", "300", "--amplitude", "1e-4",
                 "--duration", "3", "--plot", "none", "--json", "--dt", "1e-4"]) == 0
    record = json.loads(capsys.readouterr().out)
    assert record["excitation"] == "Sine"
    assert record["run"]["steps"] == 30000 and record["run"]["completed"] is True
    assert record["statistics"]["samples"] == 3001
    assert [w["code"] for w in record["warnings"]] == ["output_rate_low"]


# ------------------------------------------------------------------ the summary's warnings
def _codes(result):
    return [code for code, _ in run_warnings(result)]


SINE = Sine(amplitude=0.002, frequency=3.0)


def test_a_plain_run_has_no_warning():
    result = simulate(SINE, duration=3.0, sample_rate=200.0)
    assert _codes(result) == []
    assert "WARNING" not in result.summary()


def test_saturation_is_warned_with_its_share():
    """A 1 N motor cannot carry the 1.94 N the spring leaves: it saturates all the time."""
    result = simulate(SINE, IsolatorParameters(motor_force_max=1.0), duration=3.0,
                      sample_rate=200.0)
    assert _codes(result) == ["motor_saturated"]
    assert result.statistics["saturated_fraction"] == 1.0
    assert "the motor saturates 100.00 % of the time" in result.summary()


def test_setpoint_outside_the_constant_force_region_is_warned():
    edge = IsolatorParameters().constant_force_edge
    assert -0.034 < edge < -0.033  # atanh(0.99)/78.1 m
    inside = simulate(SINE, controller=ControllerParameters(position_setpoint=edge - 1e-4),
                      duration=2.0, sample_rate=200.0)
    outside = simulate(SINE, controller=ControllerParameters(position_setpoint=edge + 1e-3),
                       duration=2.0, sample_rate=200.0)
    assert "setpoint_outside_constant_force" not in _codes(inside)
    assert "setpoint_outside_constant_force" in _codes(outside)


def test_fast_excitation_for_the_output_rate_and_the_step_is_warned():
    fast = Sine(amplitude=1e-5, frequency=210.0)
    at_200 = simulate(fast, duration=1.0, sample_rate=1000.0)  # 4.8 samples per period
    assert _codes(at_200) == ["output_rate_low"]
    at_ok = simulate(Sine(amplitude=1e-5, frequency=190.0), duration=1.0, sample_rate=1000.0)
    assert _codes(at_ok) == []
    coarse = simulate(Sine(amplitude=1e-4, frequency=55.0), duration=1.0, dt=1e-3,
                      sample_rate=1000.0, solver="rk4")  # 18 steps per period
    assert "few_steps_per_period" in _codes(coarse)


def test_a_large_energy_residual_is_warned():
    """Euler at 1 ms on a 5 Hz, 5 mm sine: the ledger drifts far beyond 1e-4 of the base work."""
    loose = simulate(Sine(amplitude=0.005, frequency=5.0), duration=3.0, dt=1e-3,
                     sample_rate=1000.0, solver="euler")
    tight = simulate(Sine(amplitude=0.005, frequency=5.0), duration=3.0, dt=1e-4,
                     sample_rate=1000.0)
    assert "energy_residual" in _codes(loose)
    assert "energy_residual" not in _codes(tight)


# ------------------------------------------------------------------ outputs: checked, never half-written
_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0


@pytest.mark.parametrize("option, name", [
    ("--out", "run.xyz"), ("--plot", "figure.xyz"), ("--out", "ro"), ("--out", "file/run.nc"),
    ("--plot", "file/deeper/figure.png"),
    ("--out", "/sys/run.nc"), ("--plot", "/sys/qzs/figure.png"),  # read-only even for root
    pytest.param("--out", "ro/run.nc", marks=pytest.mark.skipif(_ROOT, reason="root writes anyway")),
    pytest.param("--plot", "ro/figure.png",
                 marks=pytest.mark.skipif(_ROOT, reason="root writes anyway")),
])
def test_a_bad_output_path_fails_at_once_and_leaves_nothing(tmp_path, capsys, option, name):
    import time

    (tmp_path / "file").write_text("a file where a folder must go")
    read_only = tmp_path / "ro"
    read_only.mkdir()
    read_only.chmod(0o555)
    before = sorted(p.name for p in tmp_path.rglob("*"))
    start = time.perf_counter()
    try:  # the default 2000 s chirp: a check after the run would take minutes
        plot = [] if option == "--plot" else ["--plot", str(tmp_path / "plot.png")]
        code = main(["simulate", option, str(tmp_path / name), *plot, "--quiet"])
    finally:
        read_only.chmod(0o755)
    assert code == 2
    assert time.perf_counter() - start < 5.0
    assert f"{option} " in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.rglob("*")) == before
    assert not any(p.name.startswith(".") for p in tmp_path.iterdir())


def test_ctrl_c_writes_what_was_simulated(tmp_path, monkeypatch):
    """An interrupted streamed run keeps its samples, says so (run.completed = 0), exit 130."""
    import os
    import signal
    from qzs.engine import driver as driver_module, lanes

    monkeypatch.setattr(driver_module, "CHUNK_SAMPLES", 100)  # cut to 128: lcm(10, 256) steps
    real, calls = lanes.run_single, []

    def interrupted(*args):
        calls.append(args[1])
        result = real(*args)
        if len(calls) == 4:  # the warm-up call, then three chunks of 128 samples: Ctrl-C
            os.kill(os.getpid(), signal.SIGINT)  # (Python delivers it to the main thread)
        return result

    monkeypatch.setattr(lanes, "run_single", interrupted)
    out = tmp_path / "run.nc"
    assert main(["simulate", "--excitation", "sine", "--duration", "10", "--out", str(out),
                 "--plot", "none", "--quiet", "--dt", "1e-4"]) == 130
    data = read_result(out)
    assert data.attrs["run.completed"] == 0
    assert data.sizes["time"] == 1 + 3 * 128  # t = 0 and three chunks
    np.testing.assert_allclose(data.time.values[-1], 0.384)


def test_sigterm_leaves_no_file_behind(tmp_path):
    """SIGTERM during a streamed run: exit 143, no result and no hidden temporary file."""
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "run.nc"
    process = subprocess.Popen(
        [sys.executable, "-m", "qzs", "simulate", "--out", str(out), "--plot", "none",
         "--quiet"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not any(tmp_path.iterdir()) and time.monotonic() < deadline:  # the writer started
        time.sleep(0.05)
    time.sleep(0.5)
    process.send_signal(signal.SIGTERM)
    _, err = process.communicate(timeout=120)
    assert process.returncode == 143, err
    assert list(tmp_path.iterdir()) == []


def test_an_unknown_excitation_kind_in_a_config_is_named(tmp_path, capsys):
    """Was answered with "--excitation file needs --record"."""
    config = tmp_path / "c.toml"
    config.write_text('[excitation]\nkind = "square"\n')
    assert main(["simulate", "--config", str(config), "--plot", "none", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "excitation `kind` must be one of ('chirp', 'sine', 'random', 'file'), got 'square'" in err


def test_tolerance_chooses_the_step_the_run_uses(capsys):
    """`--tolerance DB` runs with the step qzs.engine.accuracy.choose_step finds for the chirp
    the run covers (its first 20 s)."""
    from qzs.engine.accuracy import choose_step, excitation_over

    assert main(["simulate", "--excitation-duration", "100", "--duration", "20",
                 "--tolerance", "0.05", "--sample-rate", "500", "--plot", "none", "--json"]) == 0
    record = json.loads(capsys.readouterr().out)
    expected = choose_step(excitation_over(Chirp(duration=100.0), 20.0), tolerance=0.05,
                           sample_rate=500.0)
    assert record["step"]["dt"] == record["run"]["dt"] == expected.dt
    assert record["step"]["chosen"] and record["step"]["unit"] == "dB"
    assert record["step"]["error"] <= 0.05 and record["run"]["step_error_db"] <= 0.05
    assert record["run"]["step_tolerance_db"] == 0.05
    assert main(["simulate", "--tolerance", "0.1", "--dt", "1e-3"]) == 2


def test_without_a_step_the_default_tolerance_chooses_it_and_dt_stays_literal(capsys):
    """No --dt: the step meeting defaults.ACCURACY (dB for a chirp, metres for a sine), stated
    in the summary and the JSON; --dt is taken as it is."""
    from qzs.defaults import ACCURACY
    from qzs.engine.accuracy import choose_step, excitation_over

    common = ["--excitation-duration", "100", "--duration", "40", "--sample-rate", "500",
              "--plot", "none"]
    assert main(["simulate", *common, "--json"]) == 0
    record = json.loads(capsys.readouterr().out)
    expected = choose_step(excitation_over(Chirp(duration=100.0), 40.0),
                           tolerance=ACCURACY["tolerance_db"], sample_rate=500.0)
    assert record["run"]["dt"] == expected.dt > 1e-4
    assert record["step"]["tolerance"] == ACCURACY["tolerance_db"]
    assert main(["simulate", *common, "--quiet"]) == 0
    text = capsys.readouterr().out
    assert "accuracy-driven: estimated error" in text
    assert f"(tolerance {ACCURACY['tolerance_db']:g} dB" in text
    assert main(["simulate", *common, "--dt", "2e-4", "--json"]) == 0
    record = json.loads(capsys.readouterr().out)
    assert record["run"]["dt"] == 2e-4 and record["step"] == {"dt": 2e-4, "chosen": False}
    assert "step_tolerance_db" not in record["run"]
    # a sine has no band: its relative position within the state tolerance
    assert main(["simulate", "--excitation", "sine", "--frequency", "2", "--duration", "3",
                 "--sample-rate", "500", "--plot", "none", "--json"]) == 0
    record = json.loads(capsys.readouterr().out)
    assert record["step"]["unit"] == "m" and record["step"]["error"] <= ACCURACY["tolerance_state"]
    assert main(["simulate", "--excitation", "sine", "--frequency", "2", "--tolerance", "0.01",
                 "--plot", "none"]) == 2
    assert "--tolerance-state" in capsys.readouterr().err


def test_the_chosen_step_is_kept_in_the_file(tmp_path, capsys):
    """The streamed file's run attributes carry the chosen step's tolerance and estimate."""
    import xarray as xr

    out = tmp_path / "run.nc"
    assert main(["simulate", "--excitation-duration", "30", "--f1", "5",
                 "--sample-rate", "500", "--plot", "none", "--quiet", "--out", str(out)]) == 0
    with xr.open_dataset(out) as raw:
        data = from_file_layout(raw)  # the containers as dotted attributes
        assert data.attrs["run.step_tolerance_db"] == 0.01 and data.attrs["run.step"] == "accuracy-driven"
        assert 0 <= data.attrs["run.step_error_db"] <= 0.01
        assert data.attrs["run.dt"] > 1e-4


def test_out_mat_writes_what_matlab_and_scipy_load(tmp_path):
    """`--out run.mat`: a MAT 5 file whose variables are the NetCDF file's, same values,
    with the units and the parameters in structs."""
    import scipy.io
    import xarray as xr

    mat, nc = tmp_path / "run.mat", tmp_path / "run.nc"
    for out in (mat, nc):
        assert main(["simulate", "--duration", "2", "--out", str(out), "--plot", "none",
                     "--quiet"]) == 0
    read = scipy.io.loadmat(mat)
    with xr.open_dataset(nc) as raw:
        netcdf = from_file_layout(raw)  # the containers as dotted attributes
        np.testing.assert_array_equal(read["relative_position"][:, 0],
                                      netcdf["relative_position"].values)
        np.testing.assert_array_equal(read["time"][:, 0], netcdf["time"].values)
        np.testing.assert_array_equal(read["locked"][:, 0], netcdf["locked"].values)
        names = set(netcdf.variables)
        assert names <= set(read)
        assert read["units"][0, 0]["relative_position"][0] == \
            netcdf["relative_position"].attrs["units"]
        mass = read["parameters"][0, 0]["isolator"][0, 0]["mass"][0, 0]
        assert mass == netcdf.attrs["isolator.mass"]
        assert read["parameter_units"][0, 0]["isolator"][0, 0]["mass"][0] == "kg"
        assert read["parameters"][0, 0]["run"][0, 0]["samples"][0, 0] == netcdf.sizes["time"]
    assert sorted(os.listdir(tmp_path)) == ["run.mat", "run.nc"]


@pytest.mark.parametrize("argv, flag, top", [
    (["--excitation", "sine", "--frequency", "4000", "--duration", "1"], "--frequency", 4000.0),
    (["--excitation", "sine", "--frequency", "500", "--duration", "1"], "--frequency", 500.0),
    (["--excitation", "chirp", "--f1", "900", "--excitation-duration", "20"], "--f1", 900.0),
    (["--excitation", "sine", "--frequency", "30", "--sample-rate", "50", "--duration", "1"],
     "--frequency", 30.0),
])
def test_an_excitation_the_output_rate_cannot_represent_is_refused(argv, flag, top, tmp_path,
                                                                    monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", *argv, "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and flag in err and "--sample-rate" in err
    assert f"{top:g} Hz" in err and f"{2 * top:g} Hz" in err  # the rate that would show it
    assert list(tmp_path.iterdir()) == []


def test_an_excitation_below_half_the_output_rate_still_runs(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", "--excitation", "sine", "--frequency", "24", "--sample-rate", "50",
                 "--duration", "0.5", "--plot", "none", "--quiet"]) == 0


def test_an_absurd_excitation_duration_is_named_as_the_flag_given(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", "--excitation-duration", "1e12", "--quiet"]) == 2
    err = capsys.readouterr().err.strip().replace("`", "")
    assert err.count("\n") == 0 and "--excitation-duration 1e+12 s" in err
    assert "--duration" not in err.replace("--excitation-duration", "")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("argv, named", [
    (["--excitation", "sine", "--duration", "1e308"], "--duration 1e+308 s"),
    (["--excitation", "sine", "--duration", "10", "--dt", "1e-300"], "--dt"),
])
def test_a_run_of_more_steps_than_a_number_holds_is_one_clear_line(argv, named, tmp_path,
                                                                   monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", *argv, "--quiet"]) == 2
    err = capsys.readouterr().err.strip().replace("`", "")
    assert err.count("\n") == 0 and named in err and list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("argv", [["--amplitude", "1e308"],
                                  ["--excitation", "sine", "--amplitude", "1e308"]])
def test_an_amplitude_beyond_float64_is_bad_input_not_a_failed_run(argv, tmp_path, monkeypatch,
                                                                    capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", *argv, "--duration", "1", "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "--amplitude" in err and list(tmp_path.iterdir()) == []


def test_an_absurd_sample_rate_is_named_as_what_bounds_the_step(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", "--sample-rate", "1e308", "--duration", "1", "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "--sample-rate" in err and list(tmp_path.iterdir()) == []


def test_the_sines_default_duration_is_named_as_the_flag_it_stands_for(tmp_path, monkeypatch,
                                                                        capsys):
    """No config file: the 10 s a sine takes by default is --duration's, never a config key
    of a file that was not given ("[simulation] duration of None")."""
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", "--excitation", "sine", "--sample-rate", "1e14", "--quiet",
                 "--plot", "none"]) == 2
    err = capsys.readouterr().err.replace("`", "")
    assert "None" not in err and "--duration 10 s" in err and "--sample-rate" in err


def test_a_config_without_a_duration_does_not_take_the_sines_default(tmp_path, monkeypatch,
                                                                     capsys):
    """A config file that sets no duration: the sine's 10 s default is still --duration's."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "run.toml").write_text("[simulation]\nsolver = \"ode3\"\n")
    assert main(["simulate", "--config", "run.toml", "--excitation", "sine", "--sample-rate",
                 "1e14", "--quiet", "--plot", "none"]) == 2
    err = capsys.readouterr().err.replace("`", "")
    assert "duration of" not in err and "--duration 10 s" in err


def test_a_validators_error_names_the_flag_or_key_the_value_came_from(tmp_path, monkeypatch,
                                                                     capsys):
    """The shared validators' errors carry the argument they name: the command line says
    --dt for a flag and the config's key for a file's value, not the Python name."""
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", "--dt", "-1", "--quiet", "--plot", "none"]) == 2
    assert "`--dt` must be positive" in capsys.readouterr().err
    (tmp_path / "run.toml").write_text("[simulation]\nduration = 1e12\n")
    assert main(["simulate", "--config", "run.toml", "--quiet", "--plot", "none"]) == 2
    assert "`[simulation] duration of run.toml` (1000000000000.0 s) exceeds" in \
        capsys.readouterr().err


def test_running_twice_replaces_the_default_figure_and_refuses_a_named_one(tmp_path,
                                                                            monkeypatch, capsys):
    """getting-started's `qzs simulate` after the README's failed on the figure it never
    named (`--plot 'qzs-simulation.png' exists`); a figure the user named is still kept."""
    monkeypatch.chdir(tmp_path)
    run = ["simulate", "--excitation-duration", "4", "--dt", "1e-3", "--quiet"]
    assert main(run) == 0, capsys.readouterr().err
    first = (tmp_path / "qzs-simulation.png").stat().st_mtime_ns
    (tmp_path / "qzs-simulation.png").write_bytes(b"an older figure")
    assert main(run) == 0, capsys.readouterr().err
    assert (tmp_path / "qzs-simulation.png").read_bytes()[:4] == b"\x89PNG"
    assert (tmp_path / "qzs-simulation.png").stat().st_mtime_ns >= first
    capsys.readouterr()
    assert main([*run, "--plot", "qzs-simulation.png"]) == 2
    assert "--plot 'qzs-simulation.png' exists; pass --overwrite" in capsys.readouterr().err
    assert main([*run, "--plot", "qzs-simulation.png", "--overwrite"]) == 0


def test_a_controller_file_runs_as_its_controller_does_in_the_api(tmp_path):
    """`qzs simulate --controller FILE.toml` is `qzs.simulate(controller=...)` of that file's
    controller, sample for sample (a compensation, a discrete lead on the velocity)."""
    import qzs

    path = tmp_path / "c.toml"
    path.write_text("[controller]\npi_kp = 70\n[controller.compensation]\nfraction = 0.7\n"
                    "[controller.linear]\nnum = [20.0, -18.0]\nden = [1.0, -0.5]\n"
                    "sample_time = 0.001\n")
    out = tmp_path / "run.nc"
    assert main(["simulate", "--controller", str(path), "--excitation", "sine", "--frequency",
                 "3", "--duration", "2", "--dt", "1e-4", "--sample-rate", "100", "--out",
                 str(out), "--plot", "none", "--quiet"]) == 0
    controller = (qzs.PIDamping(pi_kp=70.0) + qzs.FrictionCompensation(fraction=0.7)
                  + qzs.LinearController.from_transfer_function(
                      [20.0, -18.0], [1.0, -0.5], sample_time=1e-3))
    api = simulate(Sine(frequency=3.0), controller=controller, duration=2.0,
                   sample_rate=100.0, dt=1e-4)
    data = read_result(out)
    for name in ("relative_position", "motor_force", "compensation_force", "linear_force"):
        np.testing.assert_array_equal(data[name].values, api[name])
    assert np.ptp(api["linear_force"]) > 0 and np.ptp(api["compensation_force"]) > 0


@pytest.mark.parametrize("body, named", [
    ("[controller.linear]\nnum = [1.0, 0.0]\nden = [1.0]\n", "[controller.linear] num"),
    ("[controller.compensation]\nfraction = -0.1\n", "[controller.compensation] fraction"),
    ("[controller.linear]\nnum = [1.0]\nden = [1.0, 0.5]\nsample_time = 0.00025\n",
     "[controller.linear] sample_time"),
])
def test_a_bad_controller_file_exits_2_before_any_work(tmp_path, capsys, body, named):
    path = tmp_path / "c.toml"
    path.write_text("[controller]\n" + body)
    out, plot = tmp_path / "run.nc", tmp_path / "run.png"
    assert main(["simulate", "--controller", str(path), "--excitation", "sine", "--frequency",
                 "3", "--duration", "1", "--dt", "1e-4", "--out", str(out), "--plot",
                 str(plot), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert named in err and str(path) in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.toml"]
