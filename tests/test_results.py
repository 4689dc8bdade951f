"""Every public result class has one protocol (issue 42), checked on a real instance of each.

Which classes. A *public result class* is a class named in the ``__all__`` of a qzs module
(every module and package that ``pkgutil.walk_packages`` finds; the command line
``qzs.cli`` and the page ``qzs.app`` left out, they return none) whose name ends in one of
:data:`RESULT_ENDINGS`: the names qzs gives what its public functions return
(``SimulationResult``, ``SpringFit``, ``SteadyStateResponse``, ``HexapodTransmissibility``,
``TransmissibilityEstimate``, ``FrequencyResponseCurve``, ``StepChoice``,
``HarmonicBalanceSolution``, ...). They are found by introspection, not listed: a new result
class is walked as soon as it is exported, and fails :func:`test_every_result_class_has_a_factory`
until :data:`FACTORIES` builds it.

The protocol, on a small real instance built through the public function that returns it
(cheap settings):

* ``summary()`` is a non-empty ``str`` naming a value of the result (:data:`FACTORIES` says
  which number, read from the result; the text must show it to 3 significant digits);
* ``plot()`` returns a matplotlib ``Figure`` whose every drawn axes carries a unit in
  brackets or parentheses on its own label or on the shared x axis's label, and
  ``plot(path)`` writes the file;
* ``save(path)`` for each extension of the class's ``save_suffixes`` writes a file whose
  numbers read back (``.nc`` with xarray, ``.csv`` with the csv module, ``.mat`` with
  scipy.io, ``.json`` with json, ``.toml`` with tomllib) equal the result's; an extension
  it does not accept raises :class:`~qzs.errors.OutputPathError` naming the path, the
  extension and the accepted ones, before anything is written;
* ``to_xarray()``, where the result has arrays, gives a units attribute to every numeric
  variable.

:data:`LEFT` names the classes that do not have the protocol yet, each with the reason; their
tests are strict xfails, so a class that gets the protocol must leave the list.
"""
import csv
import importlib
import inspect
import json
import math
import pkgutil
import re
import tomllib
import warnings
from functools import cache
from pathlib import Path

import numpy as np
import pytest

import qzs
from qzs.errors import OutputPathError

from helpers import (LINEAR_PROBLEM, SENSITIVITY_PROBLEM, SMALL_STUDY, instron_test,
                     tiny_hexapod_study)

ROOT = Path(__file__).resolve().parents[1]
#: How a result class's name ends (the rule of the module docstring).
RESULT_ENDINGS = ("Result", "Fit", "Response", "Transmissibility", "Estimate", "Curve",
                  "Choice", "Solution")
#: A unit in a label: ``[N]``, ``[m/s^2]``, ``(Hz)``, ``[-]``.
UNIT = re.compile(r"\[[^\]]+\]|\([^)]*[A-Za-z1-]\)")
#: Classes without the protocol yet -> why (strict xfail: a class that gets it must leave).
LEFT = {
}


def result_classes():
    """Every public result class (module docstring), by name."""
    found = {}
    modules = ["qzs", *(m.name for m in pkgutil.walk_packages(qzs.__path__, "qzs."))]
    for name in modules:
        if name.startswith(("qzs.cli", "qzs.app")):
            continue
        module = importlib.import_module(name)
        for exported in getattr(module, "__all__", ()):
            obj = getattr(module, exported, None)
            if inspect.isclass(obj) and obj.__module__.startswith("qzs.") and \
                    obj.__name__.endswith(RESULT_ENDINGS):
                found[obj.__name__] = obj
    return dict(sorted(found.items()))


CLASSES = result_classes()


# ---------------------------------------------------------------- one small instance of each
def _simulation():
    return qzs.simulate(qzs.Sine(amplitude=0.002, frequency=3.0), duration=0.2, dt=1e-4,
                        sample_rate=200.0)


def _batch():
    cases = [(qzs.IsolatorParameters(stiction_force=f), qzs.ControllerParameters())
             for f in (5.0, 10.0)]
    return qzs.simulate_batch(cases, qzs.Sine(amplitude=0.002, frequency=3.0), duration=0.2,
                              sample_rate=200.0, channels=("relative_position", "motor_force",
                                                           "locked"), workers=1)


def _hexapod():
    from qzs.workflows.hexapod.setups import load_hexapod, simulate_setup

    return simulate_setup(load_hexapod("paper_legs_cubic"), duration=0.1, dt=1e-3)


def _design():
    from qzs.workflows.design import design_controller

    return design_controller(excitation=qzs.Chirp(duration=60.0), stiction_range=(8.0, 12.0),
                             mass_range=(6.4, 6.4), force_steps=(2.0,), band=(1.0, 20.0),
                             quick=True, dt=1e-3, damping_gain_max=300.0)


def _optimisation(folder):
    pytest.importorskip("pymoo")
    return qzs.optimize(LINEAR_PROBLEM, folder / "linear.zarr", progress=False)


def _sensitivity():
    pytest.importorskip("SALib")
    return qzs.sensitivity(SENSITIVITY_PROBLEM, progress=False)


def _response():
    return qzs.steady_state_response([2.0], 0.010, dt=1e-3, workers=1)


def _hexapod_matrix():
    from qzs.workflows.hexapod.setups import load_hexapod

    return qzs.hexapod_transmissibility(load_hexapod("paper_legs_cubic"), axes=("z",),
                                        duration=4.0, dt=1e-3, fft_length=512, workers=1)


def _experiment():
    from qzs.workflows.experiment.process import process_experiment

    recording = qzs.read_recording(ROOT / "examples" / "data" / "experiment.csv",
                                   ROOT / "examples" / "data" / "experiment_map.toml")
    return process_experiment(recording, fft_length=1024, n_averages=None,
                              simulate_match=False)


def _spring_fit():
    z = np.linspace(-0.1, 0.1, 41)
    noise = np.random.default_rng(0).normal(0.0, 0.5, z.size)
    return qzs.fit_spring(z, qzs.spring_force(z, qzs.IsolatorParameters()) + noise)


def _law_fit():
    from qzs.identify.spring_laws import fit_polynomial

    z = np.linspace(-0.1, 0.1, 41)
    noise = np.random.default_rng(1).normal(0.0, 0.5, z.size)
    return fit_polynomial(z, qzs.spring_force(z, qzs.IsolatorParameters()) + noise, 3, None,
                          0.95)


def _case_curve():
    from qzs.workflows.questions.common import ChirpPlan, run_chirp_cases

    (curve,) = run_chirp_cases(["viscous 60 N*s/m"],
                               [(qzs.IsolatorParameters(viscous_damping=60.0),
                                 qzs.ControllerParameters())],
                               ChirpPlan(CHIRP, 100.0, 512, 5e-4), workers=1)
    return curve


@cache
def _study(folder):
    from qzs.workflows.paper.studies import run_study

    (folder / "small.toml").write_text(SMALL_STUDY, encoding="utf-8")
    return run_study(folder / "small.toml", workers=1, progress=False)


def _friction_fit():
    truth = qzs.IsolatorParameters()
    return qzs.fit_friction(*instron_test(), spring=truth, mass=truth.mass)


#: The chirp of the small transmissibility estimate and fit.
CHIRP = qzs.Chirp(amplitude=0.010, f0=0.0, f1=20.0, duration=20.0)


@cache
def _estimate():
    run = qzs.simulate(CHIRP, qzs.IsolatorParameters(viscous_damping=60.0), dt=5e-4,
                       sample_rate=100.0)
    return qzs.transmissibility(run.base_acceleration, run.payload_acceleration, 100.0,
                                fft_length=512)


def _transmissibility_fit():
    estimate = _estimate()
    return qzs.fit_transmissibility(estimate.frequency, estimate.magnitude,
                                    ("viscous_damping",), excitation=CHIRP)


def _periodic():
    from qzs.analysis.harmonic_balance import SmoothModel, periodic_response

    model = SmoothModel.from_parameters(qzs.IsolatorParameters(), qzs.ControllerParameters(),
                                        amplitude=0.002)
    return periodic_response(2.0, model, harmonics=3)


@cache
def _balance():
    from qzs.analysis.harmonic_balance import SmoothModel, frequency_response_curve

    model = SmoothModel.from_parameters(qzs.IsolatorParameters(), qzs.ControllerParameters(),
                                        amplitude=0.002)
    return frequency_response_curve(model, (1.0, 6.0), harmonics=3, max_points=60)


def _step_choice():
    from qzs.engine.accuracy import choose_step

    return choose_step(qzs.Chirp(duration=20.0, f1=20.0), tolerance=1e-4)


#: Class name -> (how to build a small instance from a folder, a number its summary shows).
FACTORIES = {
    "StepChoice": (lambda folder: _step_choice(), lambda r: r.error),
    "SimulationResult": (lambda folder: _simulation(), lambda r: r["time"][-1]),
    "BatchResult": (lambda folder: _batch(), lambda r: r.stats["motor_force_rms"][0]),
    "HexapodResult": (lambda folder: _hexapod(), lambda r: r.time[-1]),
    "DesignResult": (lambda folder: _design(), lambda r: r.gains["pi_kp"]),
    "OptimizationResult": (_optimisation, lambda r: len(r.designs)),
    "SensitivityResult": (lambda folder: _sensitivity(), lambda r: r.evaluations),
    "SteadyStateResponse": (lambda folder: _response(), lambda r: r.dt),
    "HexapodTransmissibility": (lambda folder: _hexapod_matrix(),
                                lambda r: r.setup.platform.mass),
    "HexapodStudyResult": (lambda folder: tiny_hexapod_study(folder / "hexapod_study"),
                           lambda r: r.rows[0]["T_at_16_hz"]),
    "ExperimentResult": (lambda folder: _experiment(), lambda r: r.band[1]),
    "SpringFit": (lambda folder: _spring_fit(), lambda r: r.parameters["plateau"]),
    "LawFit": (lambda folder: _law_fit(), lambda r: r.parameters["c1"]),
    "StudyResult": (_study, lambda r: r.cases[1].metrics["isolation_onset"]),
    "CaseResult": (lambda folder: _study(folder).cases[0],
                   lambda r: r.metrics["resonance_frequency"]),
    "CaseCurve": (lambda folder: _case_curve(), lambda r: r.metrics["isolation_onset"]),
    "FrictionFit": (lambda folder: _friction_fit(), lambda r: r.stiction_force),
    "FrequencyResponseCurve": (lambda folder: _balance(),
                               lambda r: float(np.max(r.transmissibility[r.stable & r.valid]))),
    "HarmonicBalanceSolution": (lambda folder: _periodic(),
                                lambda r: r.transmissibility),
    "TransmissibilityEstimate": (lambda folder: _estimate(),
                                 lambda r: float(np.max(r.magnitude[r.trusted]))),
    "TransmissibilityFit": (lambda folder: _transmissibility_fit(),
                            lambda r: r.parameters["viscous_damping"]),
}


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    return tmp_path_factory.mktemp("results")


@pytest.fixture(scope="module")
def built(folder):
    """The instances, built once for the module, by class name."""
    made = {}

    def get(name):
        if name not in made:
            made[name] = FACTORIES[name][0](folder)
        return made[name]

    return get


def _walked(name):
    marks = [pytest.mark.xfail(reason=LEFT[name], strict=True)] if name in LEFT else []
    return pytest.param(name, marks=marks, id=name)


WALKED = [_walked(name) for name in CLASSES]


# ---------------------------------------------------------------- the walk
def test_the_walk_finds_the_result_classes():
    """The rule finds the classes the issue names, and LEFT names only classes it finds."""
    assert {"SimulationResult", "BatchResult", "HexapodResult", "SpringFit", "FrictionFit",
            "TransmissibilityFit", "SensitivityResult", "ExperimentResult", "StudyResult",
            "HexapodStudyResult", "SteadyStateResponse"} <= set(CLASSES)
    assert set(LEFT) <= set(CLASSES), set(LEFT) - set(CLASSES)
    assert not set(LEFT) & set(FACTORIES), "a class with a factory is not left"


@pytest.mark.parametrize("name", WALKED)
def test_every_result_class_has_a_factory(name):
    assert name in FACTORIES, (f"{name} is a public result class: add a factory to FACTORIES "
                               "(and give it summary, plot, save, to_xarray)")
    for method in ("summary", "plot", "save"):
        assert callable(getattr(CLASSES[name], method, None)), f"{name}.{method}"
    assert CLASSES[name].save_suffixes


def _shows(text, value):
    """Does ``text`` show the number ``value`` to 3 significant digits?"""
    for token in re.findall(r"[-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?", text):
        if math.isclose(float(token), float(value), rel_tol=5e-3, abs_tol=1e-12):
            return True
    return False


@pytest.mark.parametrize("name", WALKED)
def test_summary_names_a_value_of_the_result(name, built):
    result = built(name)
    assert isinstance(result, CLASSES[name])
    text = result.summary()
    assert isinstance(text, str) and text.strip()
    value = FACTORIES[name][1](result)
    assert _shows(text, value), (value, text)


def _unit_label(ax):
    """The axes' labels, the shared x axis's counted, that carry a unit."""
    labels = [ax.get_xlabel(), ax.get_ylabel()]
    labels += [other.get_xlabel() for other in ax.get_shared_x_axes().get_siblings(ax)]
    return [label for label in labels if UNIT.search(label)]


@pytest.mark.parametrize("name", WALKED)
def test_plot_returns_a_figure_with_units_on_its_axes(name, built, tmp_path):
    import matplotlib.pyplot as plt
    from matplotlib.figure import Figure

    result = built(name)
    figure = result.plot(tmp_path / "figure.png", title="a title")
    try:
        assert isinstance(figure, Figure)
        assert (tmp_path / "figure.png").stat().st_size > 0
        drawn = [ax for ax in figure.axes if ax.axison and ax.get_label() != "<colorbar>"
                 and (ax.lines or ax.collections or ax.patches or ax.images)]
        assert drawn, "no axes with data"
        bare = [(ax.get_xlabel(), ax.get_ylabel()) for ax in drawn if not _unit_label(ax)]
        assert not bare, f"axes without a unit: {bare}"
    finally:
        plt.close(figure)


def _same(read, expected, what):
    """Numbers read back equal the result's: the same values (a long table repeats them),
    each within the CSV's 10 significant digits of one of the other's."""
    read, expected = (np.unique(np.asarray(a, dtype=float)) for a in (read, expected))
    assert np.isnan(read).any() == np.isnan(expected).any(), what  # NaN read back as NaN
    read, expected = read[np.isfinite(read)], expected[np.isfinite(expected)]
    assert (read.size == 0) == (expected.size == 0), what
    for one, other in ((read, expected), (expected, read)):
        nearest = other[np.clip(np.searchsorted(other, one), 0, other.size - 1)]
        below = other[np.clip(np.searchsorted(other, one) - 1, 0, other.size - 1)]
        close = (np.isclose(one, nearest, rtol=1e-9, atol=0.0)
                 | np.isclose(one, below, rtol=1e-9, atol=0.0))
        assert close.all(), (what, one[~close][:5], other[:5])
    return read.size


def _numeric(dataset):
    """The numeric data variables of a dataset, by name."""
    return {name: variable for name, variable in dataset.data_vars.items()
            if variable.dtype.kind in "fiub" and variable.size}


def _check_nc(path, expected):
    from qzs.iotools.files import read_result

    read = read_result(path)
    try:
        common = set(_numeric(expected)) & set(read.data_vars)
        assert common, (sorted(_numeric(expected)), sorted(read.data_vars))
        assert sum(_same(read[name].values, expected[name].values, f"{path.name}: {name}")
                   for name in common), f"{path.name}: no finite number compared"
    finally:
        read.close()


def _csv_columns(path):
    """The numeric columns of a CSV file of qzs (``#`` head lines, names, a units row)."""
    lines = [line for line in path.read_text(encoding="utf-8").splitlines()
             if not line.startswith("#")]
    rows = [row for row in csv.reader(lines) if row]
    names, units, body = rows[0], rows[1], rows[2:]  # CSV_LAYOUT: a units row, always
    assert len(units) == len(names) and body, path
    columns = {}
    for i, name in enumerate(names):
        try:
            columns[name] = [float(row[i]) if row[i] != "" else math.nan for row in body]
        except ValueError:
            continue  # a text column
    return columns


def _check_csv(path, expected):
    columns = _csv_columns(path)
    common = set(_numeric(expected)) & set(columns)
    assert common, (sorted(_numeric(expected)), sorted(columns))
    assert sum(_same(columns[name], expected[name].values, f"{path.name}: {name}")
               for name in common), f"{path.name}: no finite number compared"


def _check_mat(path, expected):
    from scipy.io import loadmat

    from qzs.iotools.matfile import matlab_name

    read = loadmat(path)
    common = {name for name in _numeric(expected) if matlab_name(name) in read}
    assert common, (sorted(_numeric(expected)), sorted(read))
    assert sum(_same(read[matlab_name(name)], expected[name].values, f"{path.name}: {name}")
               for name in common), f"{path.name}: no finite number compared"


def _record(result):
    from qzs._format import json_text

    method = getattr(result, "to_record", None) or result.to_dict
    return json.loads(json_text(method()))


def _check_json(path, result):
    read = json.loads(path.read_text(encoding="utf-8"))
    assert read == _record(result)
    for name, (low, high) in getattr(result, "intervals", {}).items():
        if np.ndim(low) == 0:  # a fit's: read back as the same numbers
            assert read["intervals"][name] == pytest.approx([low, high], nan_ok=True)


def _check_toml(path, result):
    table = tomllib.loads(path.read_text(encoding="utf-8"))["spring"]
    shown = {key: value for key, value in table.items() if key in result.parameters}
    assert shown and all(value == result.parameters[key] for key, value in shown.items())


#: What ``save`` writes where it is not ``to_xarray()``: class name -> the dataset.
SAVED = {"OptimizationResult": lambda r: r.to_xarray(pareto_only=True)}  # save's default


@pytest.mark.parametrize("name", WALKED)
def test_save_round_trips_every_extension_and_refuses_others(name, built, tmp_path):
    result = built(name)
    expected = (SAVED[name](result) if name in SAVED
                else result.to_xarray() if hasattr(result, "to_xarray") else None)
    for suffix in result.save_suffixes:
        path = tmp_path / f"result{suffix}"
        assert result.save(path) == path and path.stat().st_size > 0
        if suffix == ".json":
            _check_json(path, result)
        elif suffix == ".toml":
            _check_toml(path, result)
        else:
            {".nc": _check_nc, ".csv": _check_csv, ".mat": _check_mat}[suffix](path, expected)
    wrong = tmp_path / "result.xyz"
    with pytest.raises(OutputPathError) as error:
        result.save(wrong)
    message = str(error.value)
    assert str(wrong) in message and "'.xyz'" in message
    assert all(suffix in message for suffix in result.save_suffixes)
    assert not wrong.exists() and sorted(p.suffix for p in tmp_path.iterdir()) == sorted(
        p.suffix for p in tmp_path.iterdir() if p.suffix in result.save_suffixes)


@pytest.mark.parametrize("name", WALKED)
def test_to_xarray_gives_every_numeric_variable_a_unit(name, built):
    result = built(name)
    if not hasattr(result, "to_xarray"):
        pytest.skip(f"{name} has no arrays")
    dataset = result.to_xarray()
    numeric = {**_numeric(dataset), **{n: c for n, c in dataset.coords.items()
                                        if c.dtype.kind == "f"}}  # an integer index: none
    assert numeric
    bare = [n for n, variable in numeric.items() if "units" not in variable.attrs]
    assert not bare, f"{name}.to_xarray(): no units on {bare}"


# ---------------------------------------------------------------- intervals, spelled once
FITS = [name for name in FACTORIES if name.endswith("Fit")] + ["SensitivityResult"]


@pytest.mark.parametrize("name", FITS)
def test_intervals_map_each_estimate_to_low_and_high_at_a_confidence(name, built):
    """``intervals``: estimated name -> (low, high) with low <= estimate <= high, and the
    level in ``confidence``."""
    result = built(name)
    assert 0.0 < result.confidence < 1.0
    assert result.intervals
    for key, (low, high) in result.intervals.items():
        estimate = (result.estimates()[key] if hasattr(result, "estimates")
                    else getattr(result, key))
        ok = np.isfinite(low) & np.isfinite(high)
        assert np.all(ok) or name == "SensitivityResult", (key, low, high)
        assert np.all(np.asarray(low)[ok] <= np.asarray(estimate)[ok]), (key, low, estimate)
        assert np.all(np.asarray(estimate)[ok] <= np.asarray(high)[ok]), (key, estimate, high)
    if hasattr(result, "estimates"):
        assert set(result.intervals) <= set(result.estimates())


def test_friction_and_transmissibility_intervals_name_every_estimate(built):
    friction, fit = built("FrictionFit"), built("TransmissibilityFit")
    assert set(friction.intervals) == set(friction.estimates()) == {
        "stiction_force", "coulomb_force", "stribeck_decay", "viscous_damping", "offset"}
    assert set(fit.intervals) == set(fit.parameters) == {"viscous_damping"}


def test_the_spring_fits_old_interval_names_warn_and_give_the_same_numbers(built):
    fit = built("SpringFit")
    assert fit.kind == "tanh" and set(fit.intervals) == {"plateau", "shape"}
    for old, new in (("spring_force_interval", "plateau"), ("spring_shape_interval", "shape")):
        with pytest.warns(DeprecationWarning, match=rf"use `intervals\['{new}'\]`"):
            value = getattr(fit, old)
        assert value == fit.intervals[new]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fit.intervals["plateau"]  # the new name does not warn


def test_a_fits_save_refuses_an_unknown_extension_before_writing(built, tmp_path):
    fit = built("FrictionFit")
    with pytest.raises(OutputPathError) as error:
        fit.save(tmp_path / "fit.txt")
    assert error.value.argument == "path" and error.value.value == str(tmp_path / "fit.txt")
    assert list(tmp_path.iterdir()) == []
