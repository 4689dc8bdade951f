"""``qzs export``: the command line parses and delegates to qzs.export."""
import pytest

from qzs.cli import main
from qzs.errors import CompilerError
from qzs.export.controller import PARAMETERS_NAME


def test_export_controller_writes_the_configurations_controller(tmp_path, capsys):
    out = tmp_path / "controller.c"
    code = main(["export", "controller", "--set", "pi_kp=123.5", "--set",
                 "controller_rate=500", "--dt", "1e-4", "--out", str(out)])
    assert code == 0, capsys.readouterr().err
    text = out.read_text()
    assert f"QzsControllerParameters {PARAMETERS_NAME}" in text
    assert "    123.5,  /* pi_kp */" in text and "    20.0,  /* period_steps */" in text


def test_a_continuous_controller_is_exported_at_one_kilohertz_with_a_note(tmp_path, capsys):
    out = tmp_path / "controller.c"
    assert main(["export", "controller", "--out", str(out)]) == 0
    assert "1000 Hz" in capsys.readouterr().err
    assert "    10.0,  /* period_steps */" in out.read_text()


def test_a_bad_rate_is_refused_before_writing(tmp_path, capsys):
    out = tmp_path / "controller.c"
    code = main(["export", "controller", "--set", "controller_rate=333", "--out", str(out)])
    assert code == 2 and "controller_rate" in capsys.readouterr().err
    assert not out.exists()


def test_a_missing_compiler_is_one_line_and_exit_1(monkeypatch, capsys):
    from qzs.cli.common import run_handler

    def handler(args):
        raise CompilerError("no-cc", "was not found on PATH")
    assert run_handler(handler, None) == 1
    err = capsys.readouterr().err
    assert err.startswith("qzs: error: the C compiler 'no-cc'") and err.count("\n") == 1


@pytest.mark.parametrize("argv", [["export"], ["export", "controller", "--out", "x.txt"]])
def test_usage_and_suffix_errors_exit_2(argv, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    assert list(tmp_path.iterdir()) == []


def test_export_fmu_writes_a_valid_fmu_of_the_options(tmp_path, capsys):
    fmpy = pytest.importorskip("fmpy")
    from fmpy.validation import validate_fmu

    out = tmp_path / "iso.fmu"
    code = main(["export", "fmu", "--out", str(out), "--fmi", "2", "--mode", "plant",
                 "--excitation", "sine", "--frequency", "3", "--set", "mass=7",
                 "--duration", "5"])
    assert code == 0, capsys.readouterr().err
    assert validate_fmu(str(out)) == []
    description = fmpy.read_model_description(str(out))
    starts = {v.name: v.start for v in description.modelVariables}
    assert float(starts["isolator.mass"]) == 7.0 and float(starts["excitation.f0"]) == 3.0
    assert description.fmiVersion == "2.0" and float(description.defaultExperiment.stopTime) == 5


def test_export_fmu_refuses_excitation_options_with_inputs(tmp_path, capsys):
    out = tmp_path / "iso.fmu"
    code = main(["export", "fmu", "--out", str(out), "--base-motion", "input", "--f0", "1"])
    assert code == 2 and "--base-motion input" in capsys.readouterr().err
    assert not out.exists()


def test_export_fmu_steps_as_qzs_simulate_chooses(tmp_path, capsys):
    """Without --dt the FMU's internal step is the one `qzs simulate` chooses for the same
    inputs (one resolved run, docs/model.md decision 33), and the description says how."""
    fmpy = pytest.importorskip("fmpy")
    import json

    import qzs

    options = ["--excitation-duration", "30", "--f1", "5", "--set", "stiction_force=6"]
    out = tmp_path / "iso.fmu"
    assert main(["export", "fmu", "--out", str(out), *options]) == 0
    description = fmpy.read_model_description(str(out))
    starts = {v.name: v.start for v in description.modelVariables}
    capsys.readouterr()
    assert main(["simulate", *options, "--plot", "none", "--json"]) == 0
    simulated = json.loads(capsys.readouterr().out)["step"]
    assert simulated["chosen"] and float(starts["step_size"]) == simulated["dt"]
    resolved = qzs.resolve(qzs.Chirp(duration=30.0, f1=5.0),
                           qzs.IsolatorParameters(stiction_force=6.0), step="chosen")
    assert resolved.dt == simulated["dt"]
    assert "accuracy-driven" in description.description
    # a literal --dt stays literal
    assert main(["export", "fmu", "--out", str(out), *options, "--dt", "2e-4", "--overwrite"]) == 0
    starts = {v.name: v.start for v in fmpy.read_model_description(str(out)).modelVariables}
    assert float(starts["step_size"]) == 2e-4


def test_the_default_file_is_replaced_and_a_named_one_refused(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "controller.c").write_text("an older export")
    assert main(["export", "controller"]) == 0, capsys.readouterr().err
    assert PARAMETERS_NAME in (tmp_path / "controller.c").read_text()
    capsys.readouterr()
    assert main(["export", "controller", "--out", "controller.c"]) == 2
    assert "--out 'controller.c' exists; pass --overwrite" in capsys.readouterr().err


def test_the_issues_sine_fmu_starts_and_is_qzs_simulate(tmp_path, capsys):
    """`qzs export fmu --excitation sine --frequency 3 --amplitude 0.008 --duration 4`
    (issue 39: it failed to initialise) runs through FMPy to its stop time as `qzs simulate`
    runs the same options, at the step both chose."""
    pytest.importorskip("fmpy")
    import json

    import numpy as np
    from fmpy import read_model_description, simulate_fmu

    options = ["--excitation", "sine", "--frequency", "3", "--amplitude", "0.008",
               "--duration", "4"]
    out = tmp_path / "sine.fmu"
    assert main(["export", "fmu", "--out", str(out), *options]) == 0, capsys.readouterr().err
    description = read_model_description(str(out))
    step = float(description.defaultExperiment.stepSize)
    result = simulate_fmu(str(out), output_interval=step)
    capsys.readouterr()
    assert main(["simulate", *options, "--plot", "none", "--json"]) == 0
    dt = json.loads(capsys.readouterr().out)["step"]["dt"]
    starts = {v.name: v.start for v in description.modelVariables}
    assert float(starts["step_size"]) == dt
    import qzs

    reference = qzs.simulate(qzs.Sine(amplitude=0.008, frequency=3.0), duration=4.0, dt=dt,
                             sample_rate=1.0 / step)
    assert result["time"][-1] == 4.0
    for name in ("relative_position", "friction_force", "motor_force"):
        np.testing.assert_array_equal(result[name], np.asarray(reference[name]), name)


@pytest.mark.parametrize("argv, flag, value", [
    (["--step", "0"], "--step", "0.0"),
    (["--step", "-1e-3"], "--step", "-0.001"),
    (["--excitation", "sine", "--frequency", "0"], "--frequency", "0.0 Hz"),
    (["--dt", "0"], "--dt", "0.0"),
    (["--duration", "-2"], "--duration", "-2.0"),
    (["--tolerance", "0"], "--tolerance", "0.0"),
    (["--excitation-duration", "4", "--step", "5"], "--step", "5.0"),
    (["--excitation-duration", "4", "--duration", "2", "--step", "3"], "--duration", "2.0 s"),
    (["--excitation", "sine", "--frequency", "3", "--dt", "0.05"], "--dt", "0.05"),
    (["--excitation", "sine", "--frequency", "40", "--dt", "5e-3"], "--frequency", "40 Hz"),
])
def test_export_fmu_bad_input_names_the_flag_before_any_work(argv, flag, value, tmp_path,
                                                             monkeypatch, capsys):
    """Exit 2, one line naming the flag and the value, nothing compiled or written."""
    from qzs.export import fmu

    def compile_shared(*args, **kwargs):  # pragma: no cover - the failure it guards
        raise AssertionError("compiled before the inputs were checked")
    monkeypatch.setattr(fmu, "compile_shared", compile_shared)
    out = tmp_path / "iso.fmu"
    assert main(["export", "fmu", "--out", str(out), *argv]) == 2
    err = capsys.readouterr().err
    line = next(text for text in err.splitlines() if text.startswith("qzs: error:"))
    assert f"`{flag}`" in line and value in line, line
    assert "sample_rate" not in line and "communication_step" not in line
    assert list(tmp_path.iterdir()) == []


def test_a_bad_value_from_the_configuration_file_is_named_as_its_key_there(tmp_path, capsys):
    """`[simulation] dt = 0.05` in the --config file (unstable): exit 2, the message names
    the file's key, not a --dt the user never typed; nothing is written."""
    config = tmp_path / "run.toml"
    config.write_text("[simulation]\ndt = 0.05\n")
    out = tmp_path / "iso.fmu"
    assert main(["export", "fmu", "--config", str(config), "--excitation", "sine",
                 "--frequency", "3", "--out", str(out)]) == 2
    line = next(text for text in capsys.readouterr().err.splitlines()
                if text.startswith("qzs: error:"))
    assert f"`[simulation] dt of {config}` (0.05 s)" in line and "`--dt`" not in line, line
    assert not out.exists()


def test_a_communication_step_that_is_no_multiple_of_the_internal_step_is_taken(tmp_path,
                                                                                capsys):
    """`--dt 1e-4 --step 1.5e-4` (issue 39: a message about `sample_rate`): the FMU takes any
    communication step, so the default experiment is written as asked and runs."""
    pytest.importorskip("fmpy")
    from fmpy import read_model_description, simulate_fmu

    out = tmp_path / "iso.fmu"
    code = main(["export", "fmu", "--out", str(out), "--dt", "1e-4", "--step", "1.5e-4",
                 "--excitation-duration", "0.3"])
    assert code == 0, capsys.readouterr().err
    experiment = read_model_description(str(out)).defaultExperiment
    assert float(experiment.stepSize) == 1.5e-4 and float(experiment.stopTime) == 0.3
    result = simulate_fmu(str(out), output_interval=1.5e-4)
    assert result["time"][-1] == pytest.approx(0.3) and len(result) == 2001


def test_export_fmu_takes_a_spring_file_as_simulate_does(tmp_path, capsys):
    """``--spring FILE.toml``: the law of the file is the FMU's, its numbers its parameters
    (an FMI 3 array for the coefficients), and the FMU is valid."""
    fmpy = pytest.importorskip("fmpy")
    from fmpy.validation import validate_fmu

    spring = tmp_path / "spring.toml"
    spring.write_text('[spring]\nlaw = "polynomial"\ncoefficients = [62.78, -300.0, 0.0, -4e4]\n'
                      'center = -0.06\n')
    out = tmp_path / "poly.fmu"
    code = main(["export", "fmu", "--spring", str(spring), "--out", str(out), "--excitation",
                 "sine", "--duration", "1", "--dt", "1e-4"])
    assert code == 0, capsys.readouterr().err
    assert validate_fmu(str(out)) == []
    starts = {v.name: v.start for v in fmpy.read_model_description(str(out)).modelVariables}
    assert [float(v) for v in starts["spring.coefficients"].split()] == [62.78, -300.0, 0.0, -4e4]
    assert float(starts["spring.center"]) == -0.06
