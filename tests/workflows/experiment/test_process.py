"""Experiment pipeline: example data, synthetic logs against the simulation, CLI, README."""
import argparse
import re
import shlex
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import qzs
from qzs.errors import DataError, ParameterError
from qzs.cli.experiment import add_parser, run
from qzs.workflows.experiment.process import infer_chirp, process_experiment
from qzs.analysis.spectral import highpass
from qzs.errors import DataWarning
from qzs.iotools.rig import Recording, read_recording
from qzs.analysis.spectral import transmissibility

ROOT = Path(__file__).resolve().parents[3]
DATA = ROOT / "examples" / "data"


@pytest.fixture(scope="module")
def example():
    recording = read_recording(DATA / "experiment.csv", DATA / "experiment_map.toml")
    return process_experiment(recording, highpass_corner=1.0, fft_length=8192, n_averages=29)


def test_example_report_figure_and_flagged_band(example, tmp_path):
    paths = example.write_report(tmp_path / "out")
    assert paths["figure"].stat().st_size > 10_000 and paths["figure"].with_suffix(".svg").exists()
    report = paths["report"].read_text()
    assert "Flagged band: below 1.5 Hz" in report
    assert "![transmissibility](transmissibility.png)" in report
    assert "| resonance_frequency | Hz |" in report
    import pandas as pd

    table = pd.read_csv(paths["table"], comment="#", header=[0, 1])
    assert list(table.columns) == [("frequency", "Hz"), ("experiment", "1"), ("coherence", "1"),
                                   ("trusted", "1"), ("simulation", "1")]
    np.testing.assert_array_equal(table[("trusted", "1")], table[("frequency", "Hz")] >= 1.5)
    assert example.untrusted_below == 1.5 and example.metrics.untrusted_below == 1.5
    assert example.measured.n_averages == 29 and example.signal == "velocity"


def test_example_matches_the_simulation_it_came_from(example):
    assert example.excitation_inferred
    assert example.excitation.amplitude == pytest.approx(0.010, rel=1e-3)
    assert example.excitation.f0 == pytest.approx(0.0, abs=0.01)
    assert example.excitation.f1 == pytest.approx(20.0, abs=0.01)
    # The log is this simulation plus noise (0.00 dB when made); the margin leaves room for
    # kernel changes after examples/make_data.py last ran.
    assert example.discrepancy_db() < 0.3
    measured, simulated = example.metrics, example.simulated_metrics
    assert measured.resonance_frequency == pytest.approx(simulated.resonance_frequency)
    assert measured.at[12.0] == pytest.approx(simulated.at[12.0], rel=0.01)
    assert 19.0 <= example.band[1] < 20.0  # the sweep's top, as far as the averages reach


def test_dspace_export_gives_the_same_curve(example):
    recording = read_recording(DATA / "experiment_dspace.mat", DATA / "experiment_dspace_map.toml")
    result = process_experiment(recording, fft_length=8192, simulate_match=False,
                                excitation=example.excitation)
    assert result.simulated is None and np.isnan(result.discrepancy_db())
    f = example.measured.frequency
    trusted = (f >= 1.5) & (f <= example.band[1])  # MAT holds float32, the CSV 5 digits
    np.testing.assert_allclose(result.measured.magnitude[trusted],
                               example.measured.magnitude[trusted], rtol=2e-3)


def synthetic_log(kind="velocity", duration=60.0, rate=200.0, noise=1e-4, seed=0):
    """A short chirp through the model, measured through a 1 Hz high-pass with noise."""
    chirp = qzs.Chirp(amplitude=0.010, f0=0.0, f1=15.0, duration=duration)
    sim = qzs.simulate(chirp, dt=1e-4, sample_rate=rate)
    rng = np.random.default_rng(seed)
    channels = {f"{part}_{kind}": highpass(sim[f"{part}_{kind}"], 1.0, rate)
                + rng.normal(0, noise, len(sim)) for part in ("base", "payload")}
    unit = "m/s" if kind == "velocity" else "m/s^2"
    recording = Recording(time=sim.time, channels=channels, units=dict.fromkeys(channels, unit),
                          sample_rate=rate, source="synthetic")
    return recording, sim, chirp


@pytest.mark.parametrize("kind", ["velocity", "acceleration"])
def test_high_passed_signals_give_the_models_transmissibility(kind):
    """The high-pass cancels in the ratio: the log's curve is the model's acceleration ratio."""
    recording, sim, chirp = synthetic_log(kind)
    result = process_experiment(recording, fft_length=1024, n_averages=None, excitation=chirp)
    assert result.signal == kind and result.discrepancy_db() < 0.1
    direct = transmissibility(sim.base_acceleration, sim.payload_acceleration, 200.0,
                              fft_length=1024)
    f = result.measured.frequency
    trusted = (f >= 1.5) & (f <= result.band[1])
    difference = 20 * np.log10(result.measured.magnitude[trusted] / direct.magnitude[trusted])
    assert np.median(np.abs(difference)) < 0.1 and np.max(np.abs(difference)) < 1.0


def test_inferred_chirp_of_a_short_log():
    recording, _, chirp = synthetic_log()
    inferred = infer_chirp(recording)
    assert inferred.amplitude == pytest.approx(chirp.amplitude, rel=0.01)
    assert inferred.f1 == pytest.approx(chirp.f1, abs=0.05)
    assert inferred.duration == pytest.approx(chirp.duration, rel=1e-3)


def test_bad_input():
    recording, _, chirp = synthetic_log(duration=20.0)
    lonely = Recording(time=recording.time, channels={"base_velocity": recording["base_velocity"]},
                       units={"base_velocity": "m/s"}, sample_rate=200.0, source="lonely")
    with pytest.raises(DataError, match=r"needs base_velocity and payload_velocity.*"
                                        r"\['base_velocity'\]"):
        process_experiment(lonely)
    with pytest.raises(DataError, match="`fft_length` \\(32768\\) is longer than the log"):
        process_experiment(recording)
    with pytest.warns(DataWarning, match="only 6 Welch averages .* not the 29 requested"):
        result = process_experiment(recording, fft_length=1024, excitation=chirp,
                                    simulate_match=False)
    assert result.measured.n_averages == 6 and "only 6 Welch averages" in result.notes[0]
    rng = np.random.default_rng(1)
    noise = Recording(time=recording.time, channels={
        "base_velocity": rng.normal(size=recording.time.size),
        "payload_velocity": rng.normal(size=recording.time.size)},
        units={"base_velocity": "m/s", "payload_velocity": "m/s"}, sample_rate=200.0,
        source="noise")
    with pytest.raises(DataError, match="not a rising linear chirp"):
        process_experiment(noise, fft_length=1024, n_averages=None)
    with pytest.raises(ParameterError, match="must be a qzs.iotools.rig.Recording"):
        process_experiment({"time": [0, 1]})
    with pytest.raises(ParameterError, match=r"`highpass_corner` must be non-negative, got "
                                             r"-1.0; in Hz"):
        process_experiment(recording, highpass_corner=-1.0)
    with pytest.raises(ParameterError, match="`highpass_corner` must be a number, got '1'"):
        process_experiment(recording, highpass_corner="1")  # float() took it before


def parse(argv):
    parser = argparse.ArgumentParser(prog="qzs")
    add_parser(parser.add_subparsers(dest="command", required=True))
    return parser.parse_args(["experiment", *argv])


def test_run_writes_the_report(tmp_path, capsys):
    args = parse([str(DATA / "experiment.csv"), "--map", str(DATA / "experiment_map.toml"),
                  "--out", str(tmp_path), "--no-simulation", "--fft-length", "8192",
                  "--averages", "29"])
    assert run(args) == 0
    out = capsys.readouterr().out
    assert "flagged band   below 1.5 Hz" in out and "29 averages" in out
    import pandas as pd

    table = pd.read_csv(tmp_path / "transmissibility.csv", comment="#", header=[0, 1])
    assert list(table.columns) == [("frequency", "Hz"), ("experiment", "1"), ("coherence", "1"),
                                   ("trusted", "1")]  # no simulation column, a units row


def test_run_lets_data_errors_through(tmp_path):
    (tmp_path / "map.toml").write_text('[channels.base_velocity]\nsource = "base"\nunit = "mm/s"\n')
    with pytest.raises(DataError, match="no signal 'base'; signals found: \\['time', "
                                        "'shaker_vel', 'payload_vel'\\]"):
        run(parse([str(DATA / "experiment.csv"), "--map", str(tmp_path / "map.toml")]))


def _readme_commands():
    text = (ROOT / "examples" / "README.md").read_text()
    block = re.findall(r"```sh\n(.*?)```", text, re.S)[0]
    return [line.split("#")[0].strip() for line in block.splitlines() if line.split("#")[0].strip()]


def _run_in_process(words, capsys):
    """Run a README command line in this process (the imports are paid once)."""
    import runpy

    from qzs.cli import main

    if words[:2] == ["qzs", "experiment"]:
        return main(words[1:])
    if words[:3] == ["python", "-m", "qzs"]:
        return main(words[3:])
    assert words[0] == "python" and words[1].endswith(".py"), words
    saved = sys.argv
    sys.argv = words[1:]
    try:
        runpy.run_path(str(ROOT / words[1]), run_name="__main__")
    finally:
        sys.argv = saved
    return 0


def test_every_readme_command_works(tmp_path, capsys, monkeypatch):
    """Each command of examples/README.md, outputs redirected into a temporary folder."""
    import matplotlib.pyplot as plt

    monkeypatch.chdir(ROOT)
    commands = _readme_commands()
    assert len(commands) >= 5
    for command in commands:
        words = shlex.split(command)
        if "make_data.py" in command:
            words += ["--out", str(tmp_path / "data")]
        elif "--out" in words:
            words[words.index("--out") + 1] = str(tmp_path / words[words.index("--out") + 1])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DataWarning)  # the default FFT's 6 averages
            assert _run_in_process(words, capsys) == 0, command
        plt.close("all")
    assert (tmp_path / "data" / "experiment.csv").exists()
    for name in ("experiment", "experiment-mat", "experiment-only", "experiment-default"):
        assert (tmp_path / "results" / name / "report.md").exists(), name
    assert (tmp_path / "results" / "identify" / "friction_fit.png").exists()
    regenerated = (tmp_path / "data" / "spring_static.csv").read_bytes()
    assert regenerated == (DATA / "spring_static.csv").read_bytes()  # seeded: same files


def test_module_entry_point_runs():
    """``python -m qzs experiment`` starts, parses and reports a bad map as an error."""
    done = subprocess.run([sys.executable, "-m", "qzs", "experiment", str(DATA / "experiment.csv"),
                           "--map", str(DATA / "missing.toml")], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 2 and "channel map not found" in done.stderr


def test_readme_python_example_runs(tmp_path, monkeypatch, capsys):
    """The Python block of examples/README.md, run as written (from the repository root)."""
    import matplotlib.pyplot as plt

    code = re.findall(r"```python\n(.*?)```", (ROOT / "examples" / "README.md").read_text(), re.S)
    assert len(code) == 1
    monkeypatch.chdir(ROOT)
    namespace = {}
    exec(code[0].replace('"results/', f'"{tmp_path}/results/'), namespace)
    plt.close("all")
    fit = namespace["fit"]  # the example log's Table 1 value is recovered
    assert fit.parameters["viscous_damping"] == pytest.approx(100.0, rel=0.03)
    assert (tmp_path / "results" / "experiment-python" / "report.md").exists()


def test_experiment_metrics_come_from_trusted_bins_only(example):
    """The metrics read the estimate's trusted bins only: an estimate that distrusts a mid
    band full of garbage (a 1e6 spike) gives the metrics of the clean curve without it, and
    every metric of the example passes the trusted-bin check (docs/model.md §10)."""
    import dataclasses

    from test_trust import assert_metrics_from_trusted

    from qzs.analysis.spectral import band_mask, transmissibility_metrics
    from qzs.workflows.experiment.process import experiment_metrics

    measured = example.measured
    keep = band_mask(measured.frequency, 0.0, example.band[1])
    f = measured.frequency[keep]
    assert measured.trusted[keep][(f >= 1.5)].all()  # the example trusts all above 1.5 Hz
    hole = (measured.frequency > 4.0) & (measured.frequency < 6.0)
    spiked = dataclasses.replace(measured, trusted=measured.trusted & ~hole,
                                 magnitude=np.where(hole, 1e6, measured.magnitude))
    clean = dataclasses.replace(measured, trusted=measured.trusted & ~hole)
    with_hole = experiment_metrics(spiked, example.band, 1.0).to_dict()
    assert with_hole == pytest.approx(experiment_metrics(clean, example.band, 1.0).to_dict(),
                                      nan_ok=True)
    assert not with_hole["resonance_peak"] > 2.0
    trusted = spiked.trusted[keep] & (f >= example.untrusted_below)

    def recompute(values):
        return transmissibility_metrics(f, values, trusted=spiked.trusted[keep],
                                        highpass_corner=1.0).to_dict()

    metrics = experiment_metrics(spiked, example.band, 1.0)
    assert_metrics_from_trusted(f, spiked.magnitude[keep], trusted, metrics.to_dict(),
                                metrics.reasons, recompute=recompute)
