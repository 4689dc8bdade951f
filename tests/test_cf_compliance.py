"""Every kind of NetCDF file qzs writes, small, through the IOOS compliance checker.

``compliance-checker --test=cf:1.10`` (the community's own checker of the CF conventions,
a test dependency) must find no error (its high-priority failures) and no warning (its
medium-priority ones) in: a single run (``qzs simulate --out``), a batch's and a sweep's
dataset, a six-axis run (``qzs hexapod simulate --out``), a steady-state response
(``qzs response --out``), an experiment's transmissibility, a study's curves, an
optimisation's and a sensitivity analysis's results, a six-axis transmissibility
matrix, and a fit's data (a friction fit's ``save``). How qzs encodes what CF has no home for: docs/model.md, decision 34.

Run as a script (``python tests/test_cf_compliance.py FOLDER``) it writes each kind into
FOLDER and prints the checker's counts per file.
"""
import sys
from pathlib import Path

import numpy as np
import pytest

checker = pytest.importorskip("compliance_checker.runner",
                              reason="compliance-checker is in the test extra: "
                                     "pip install -e '.[test]'")

from helpers import LINEAR_PROBLEM, SENSITIVITY_PROBLEM, instron_test

ROOT = Path(__file__).resolve().parents[1]


def findings(path):
    """The cf:1.10 checker's messages for ``path``: ``(errors, warnings)``.

    Errors are the failed high-priority checks, warnings the failed medium-priority ones:
    what ``compliance-checker --test=cf:1.10`` lists under "Errors" and "Warnings"; a check
    that cannot run on the file (the checker raised) counts as an error.
    """
    suite = checker.CheckSuite()
    suite.load_all_available_checkers()
    dataset = suite.load_dataset(str(path))
    try:
        results, failures = suite.run_all(dataset, ["cf:1.10"], [], [])["cf:1.10"]
    finally:
        dataset.close()
    found = {3: [f"the checker's {name} failed: {error!r}" for name, (error, _) in
                 failures.items()], 2: []}
    for result in results:
        scored, possible = result.value if isinstance(result.value, tuple) else (
            int(result.value), 1)
        if result.weight in found and possible and scored < possible:
            found[result.weight].extend(result.msgs or [result.name])
    return found[3], found[2]


# ---------------------------------------------------------------- one file of each kind
def single_run(folder):
    import qzs

    return qzs.simulate(qzs.Sine(amplitude=0.002, frequency=3.0), duration=0.2, dt=1e-4,
                        sample_rate=200.0).save(folder / "run.nc")


def streamed_run(folder):
    import qzs
    from qzs.workflows.run import simulate_to_file

    path = folder / "streamed.nc"
    simulate_to_file(path, qzs.Sine(amplitude=0.002, frequency=3.0), duration=0.2,
                     sample_rate=200.0)
    return path


def batch(folder):
    import qzs

    cases = [(qzs.IsolatorParameters(stiction_force=f), qzs.ControllerParameters())
             for f in (5.0, 10.0)]
    result = qzs.simulate_batch(cases, qzs.Sine(amplitude=0.002, frequency=3.0), duration=0.2,
                                sample_rate=200.0, channels=("relative_position", "locked"),
                                workers=1)
    return result.save(folder / "batch.nc")  # BatchResult.save: write_dataset of to_xarray


def sweep(folder):
    from qzs.iotools.writer import write_dataset
    from qzs.workflows.sweeps import open_sweep, run_sweep

    document = {"sweep": {"name": "small", "batch_size": 2},
                "grid": {"pi_kp": [5.0, 200.0]}, "excitation": {"f1": 10.0},
                "analysis": {"duration": 20.0, "fft_length": 2048,
                             "band": [0.0, 10.0], "at_frequencies": [2.0]},
                "outputs": {"bands": {"low": [1.0, 3.0]}}}
    store = folder / "small.zarr"
    run_sweep(document, store, threads=1, progress=False)
    return write_dataset(open_sweep(store), folder / "sweep.nc")


def hexapod_run(folder):
    from qzs.workflows.hexapod.setups import load_hexapod, simulate_setup

    path = folder / "platform.nc"
    simulate_setup(load_hexapod("paper_legs_cubic"), duration=0.1, dt=1e-3, out=path)
    return path


def response(folder):
    from qzs.workflows.response import steady_state_response

    return steady_state_response([2.0], 0.010, dt=1e-3, workers=1).save(
        folder / "response.nc")


def experiment(folder):
    import qzs
    from qzs.workflows.experiment.process import process_experiment

    recording = qzs.read_recording(ROOT / "examples" / "data" / "experiment.csv",
                                   ROOT / "examples" / "data" / "experiment_map.toml")
    result = process_experiment(recording, fft_length=1024, n_averages=None,
                                simulate_match=False)
    return result.save(folder / "experiment.nc")


def curves(folder):
    from qzs.workflows.paper.curves import curves_dataset, write_curves

    frequency = np.linspace(0.0, 20.0, 41)
    magnitude = 1.0 / np.abs(1.0 - (frequency / 3.0) ** 2 + 0.2j * frequency / 3.0)
    cases = [{"label": f"Kd = {gain:g} N s/m", "frequency": frequency,
              "magnitude": magnitude / (1 + gain / 100), "phase": -np.arctan(frequency),
              "coherence": np.ones_like(frequency), "parameters": {"damping_gain": gain}}
             for gain in (0.0, 50.0)]
    dataset = curves_dataset(cases, {"title": "damping gains", "study": "damping",
                                     "duration": 20.0, "duration_units": "s"})
    return write_curves(dataset, folder, "damping")[0]


def optimisation(folder):
    pytest.importorskip("pymoo")
    from qzs.workflows.design_space.optimizer import optimize

    result = optimize(LINEAR_PROBLEM, folder / "linear.zarr", progress=False)
    return result.save(folder / "optimisation.nc")


def sensitivity(folder):
    pytest.importorskip("SALib")
    from qzs.workflows.design_space.sensitivity import sensitivity as analyse

    return analyse(SENSITIVITY_PROBLEM, progress=False).save(folder / "sensitivity.nc")


def friction_fit(folder):
    """A fit's dataset (qzs.identify's FitProtocol.save): the test on ``time``, the
    estimates and their intervals as global attributes."""
    import qzs

    truth = qzs.IsolatorParameters()
    fit = qzs.fit_friction(*instron_test(), spring=truth, mass=truth.mass)
    return fit.save(folder / "friction_fit.nc")


def hexapod_transmissibility(folder):
    from qzs.workflows.hexapod.setups import load_hexapod
    from qzs.workflows.hexapod.transmissibility import hexapod_transmissibility as matrix

    result = matrix(load_hexapod("paper_legs_cubic"), axes=("z",), duration=4.0, dt=1e-3,
                    fft_length=512, workers=1)
    return result.save(folder / "hexapod_transmissibility.nc")


def _blocks_controller():
    import qzs

    return (qzs.PIDamping() + qzs.FrictionCompensation(fraction=0.8, viscous_damping=None)
            + qzs.Dither(amplitude=0.5) + qzs.LinearController.from_transfer_function(
                [20.0, -18.0], [1.0, -0.5], ("measured_payload_velocity",), sample_time=1e-3,
                name="lead lag"))


def run_with_blocks(folder):
    """A run of a controller with every block: its parameters (a linear controller's
    matrices, sensors, None levels) and the blocks' channels."""
    import qzs

    return qzs.simulate(qzs.Sine(amplitude=0.002, frequency=3.0), controller=_blocks_controller(),
                        duration=0.2, dt=1e-4, sample_rate=200.0).save(folder / "blocks.nc")


def batch_with_blocks(folder):
    """A batch over ``compensation.fraction``: a dotted coordinate."""
    import qzs
    from qzs.iotools.writer import write_dataset

    cases = [(qzs.IsolatorParameters(), qzs.PIDamping() + qzs.FrictionCompensation(fraction=f))
             for f in (0.0, 1.2)]
    result = qzs.simulate_batch(cases, qzs.Sine(amplitude=0.002, frequency=3.0), duration=0.2,
                                sample_rate=200.0,
                                channels=("relative_position", "motor_force", "locked"),
                                workers=1)
    return write_dataset(result.to_xarray(), folder / "batch_blocks.nc")


def step_choice(folder):
    """A step choice's candidates (StepChoice.save)."""
    import qzs
    from qzs.engine.accuracy import choose_step

    return choose_step(qzs.Chirp(duration=20.0, f1=20.0), tolerance=1e-4).save(
        folder / "step_choice.nc")


#: Every kind of NetCDF file qzs writes: name -> writer of one small file into a folder.
KINDS = {"single_run": single_run, "run_with_blocks": run_with_blocks,
         "batch_with_blocks": batch_with_blocks,
         "streamed_run": streamed_run, "batch": batch,
         "sweep": sweep, "hexapod_run": hexapod_run, "response": response,
         "experiment": experiment, "curves": curves, "optimisation": optimisation,
         "sensitivity": sensitivity, "hexapod_transmissibility": hexapod_transmissibility,
         "friction_fit": friction_fit, "step_choice": step_choice}


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return tmp_path_factory.mktemp("cf")


@pytest.mark.parametrize("kind", list(KINDS))
def test_the_checker_finds_no_error_and_no_warning(kind, folder):
    path = KINDS[kind](folder)
    errors, warnings = findings(path)
    assert (errors, warnings) == ([], []), (
        f"{kind} ({path.name}): {len(errors)} errors, {len(warnings)} warnings:\n"
        + "\n".join(f"error: {m}" for m in errors)
        + "\n" + "\n".join(f"warning: {m}" for m in warnings[:20]))


def test_the_checker_sees_what_it_is_asked_to_see(tmp_path):
    """The check can fail: a file with the problems qzs's files had gets them counted."""
    import xarray as xr

    dataset = xr.Dataset({"x": ("time", np.zeros(3), {"units": "m, rad"})},
                         coords={"time": ("time", np.arange(3.0),
                                          {"units": "s", "standard_name": "time"})},
                         attrs={"Conventions": "CF-1.10", "isolator.mass": 6.4})
    path = tmp_path / "bad.nc"
    dataset.to_netcdf(path, engine="h5netcdf")
    errors, warnings = findings(path)
    assert any("time" in m and "since" in m for m in errors), errors
    assert any("isolator.mass" in m for m in warnings), warnings
    assert any("m, rad" in m for m in errors + warnings), (errors, warnings)
    assert any("long_name" in m or "standard_name" in m for m in errors + warnings)


if __name__ == "__main__":  # python tests/test_cf_compliance.py FOLDER [KIND ...]
    out = Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    for name in sys.argv[2:] or KINDS:
        try:
            written = KINDS[name](out)
        except BaseException as error:  # a kind that cannot be written here is reported
            print(f"{name:26s} not written: {type(error).__name__}: {error}"[:300])
            continue
        errors, warnings = findings(written)
        print(f"{name:26s} {written.name:30s} {len(errors):3d} errors {len(warnings):4d} "
              f"warnings", flush=True)
        for message in [*errors, *warnings]:
            print(f"    {message}"[:200])
