"""Metrics of a population (qzs.workflows.design_space.metrics): each design's numbers are
those of its own single run, the linear ones those of the closed forms, and every design
sees the same draws."""
import copy
import warnings

import numpy as np
import pytest

import qzs
from qzs.analysis.spectral import band_mask, transmissibility, transmissibility_metrics
from qzs.workflows.design_space.evaluation import case_settings, evaluate
from qzs.workflows.design_space.metrics import METRICS
from qzs.workflows.design_space.problem import load_problem

SHORT = {
    "problem": {"name": "short"},
    "variables": {"damping_gain": {"low": 0.0, "high": 4000.0},
                  "pi_kp": {"low": 1.0, "high": 1000.0, "scale": "log"}},
    "excitation": {"duration": 20.0},
    "simulation": {"dt": 1e-3},
    "analysis": {"fft_length": 4096, "duration": 20.0},
    "objectives": [{"metric": "transmissibility_at", "frequency": 12.0},
                   {"metric": "rms_transmissibility", "band": [1.0, 5.0]}],
    "constraints": [{"metric": "peak_stroke", "max": 0.05},
                    {"metric": "motor_force_rms", "max": 100.0},
                    {"metric": "saturated_fraction", "max": 1.0},
                    {"metric": "locked_fraction", "max": 1.0}],
}
DESIGNS = np.array([[0.0, 20.0], [150.0, 300.0], [4000.0, 10.0]])


@pytest.fixture(scope="module")
def evaluated():
    problem = load_problem(SHORT)
    return problem, evaluate(problem, DESIGNS)


def single_run(problem, design):
    controller = qzs.ControllerParameters(damping_gain=design[0], pi_kp=design[1])
    excitation = qzs.Chirp(duration=20.0)
    return qzs.simulate(excitation, qzs.IsolatorParameters(), controller, dt=1e-3,
                        sample_rate=1000.0)


def test_each_design_has_the_statistics_of_its_own_single_run(evaluated):
    problem, evaluation = evaluated
    saturated = []
    for i, design in enumerate(DESIGNS):
        run = single_run(problem, design)
        stats = run.statistics
        for name in ("peak_stroke", "motor_force_rms", "locked_fraction", "saturated_fraction"):
            assert evaluation.values[name][i, 0] == pytest.approx(stats[name], rel=1e-12,
                                                                  abs=1e-15), name
        saturated.append(evaluation.values["saturated_fraction"][i, 0])
    # the stiff damping loop asks for more than the motor's 44 N; the others never do
    assert saturated[0] == 0.0 and saturated[2] > 0.05


def test_the_transmissibility_metrics_are_those_of_the_single_runs_estimate(evaluated):
    problem, evaluation = evaluated
    a = problem.sweep.analysis
    for i, design in enumerate(DESIGNS):
        run = single_run(problem, design)
        warnings.simplefilter("ignore")  # the saturating design has no trusted bin in 1-5 Hz
        estimate = transmissibility(run.base_acceleration, run.payload_acceleration, 1000.0,
                                    fft_length=a["fft_length"], overlap=a["overlap"])
        f, magnitude, trusted = estimate.frequency, estimate.magnitude, estimate.trusted
        inside = band_mask(f, 1.0, 5.0, trusted=trusted)
        rms = np.sqrt(np.mean(magnitude[inside] ** 2)) if inside.any() else np.nan
        assert evaluation.values["rms_transmissibility_from_1_to_5_hz"][i, 0] == \
            pytest.approx(rms, rel=1e-12, nan_ok=True)
        keep = band_mask(f, *a["band"])
        at = transmissibility_metrics(f[keep], magnitude[keep], trusted=trusted[keep],
                                      at_frequencies=[12.0]).to_dict()
        assert evaluation.values["transmissibility_at_12_hz"][i, 0] == \
            pytest.approx(at["transmissibility_at_12_hz"], rel=1e-12, nan_ok=True)
    # damping lowers the RMS transmissibility over 1-5 Hz (physics, not a pinned number)
    rms = evaluation.values["rms_transmissibility_from_1_to_5_hz"][:, 0]
    assert np.isfinite(rms[:2]).all() and rms[1] < rms[0]


def test_linear_metrics_are_the_closed_forms_and_need_no_simulation(monkeypatch):
    from qzs.analysis.control_design.hunting import predict_hunting
    from qzs.analysis.control_design.stability_margins import loop_margins
    from qzs.analysis.linear import linear_transmissibility
    from qzs.workflows.sweeps import batch

    def no_runs(*args, **kwargs):
        raise AssertionError("a linear metric ran a simulation")

    monkeypatch.setattr(batch, "run_batch", no_runs)
    document = copy.deepcopy(SHORT)
    document["simulation"] = {}  # no step needed, none chosen
    document["objectives"] = [{"metric": "linear_transmissibility_at", "frequency": 3.0},
                              {"metric": "hunting_amplitude"}]
    document["constraints"] = [{"metric": "phase_margin", "min": 30.0},
                               {"metric": "gain_margin", "min": 6.0}]
    problem = load_problem(document)
    designs = np.array([[50.0, 20.0], [300.0, 500.0]])
    evaluation = evaluate(problem, designs)
    for i, (kd, kp) in enumerate(designs):
        controller = qzs.ControllerParameters(damping_gain=kd, pi_kp=kp)
        isolator = qzs.IsolatorParameters()
        assert evaluation.values["linear_transmissibility_at_3_hz"][i, 0] == pytest.approx(
            abs(complex(linear_transmissibility(3.0, isolator, controller))), rel=1e-14)
        # the population's closed forms: python-control's scalar path within its bounds
        # (tests/analysis/control_design/test_{hunting,linear}_population.py)
        prediction = predict_hunting(isolator, controller)
        assert prediction.hunts
        assert evaluation.values["hunting_amplitude"][i, 0] == pytest.approx(
            prediction.amplitude, rel=1e-6)
        margins = loop_margins(isolator, controller)
        for name in ("gain_margin", "phase_margin"):
            assert evaluation.values[name][i, 0] == pytest.approx(getattr(margins, name),
                                                                  rel=1e-6)
    # a stiffer position loop hunts with a smaller plateau d/K
    assert evaluation.values["hunting_amplitude"][1, 0] < evaluation.values[
        "hunting_amplitude"][0, 0]


def test_every_design_sees_the_same_draws():
    document = copy.deepcopy(SHORT)
    document["uncertain"] = {"stiction_force": {"distribution": "uniform", "low": 5.0,
                                                "high": 15.0},
                             "mass": {"distribution": "normal", "mean": 6.4, "std": 0.1}}
    document["robust"] = {"samples": 5}
    problem = load_problem(document)
    settings = case_settings(problem, DESIGNS)
    assert len(settings) == 15
    per_design = [[(s["stiction_force"], s["mass"]) for s in settings[i * 5:(i + 1) * 5]]
                  for i in range(3)]
    assert per_design[0] == per_design[1] == per_design[2]
    assert [s["pi_kp"] for s in settings[5:10]] == [300.0] * 5


def test_a_failed_run_defines_no_metric():
    """A case whose parameters the kernel refuses at this step is invalid, its metrics NaN."""
    document = copy.deepcopy(SHORT)
    document["variables"]["pi_kp"] = {"low": 1.0, "high": 1e9, "scale": "log"}
    problem = load_problem(document)
    evaluation = evaluate(problem, np.array([[0.0, 20.0], [0.0, 1e9]]))
    assert evaluation.status[0, 0] == 1 and evaluation.status[1, 0] != 1
    assert evaluation.messages[1][0]
    assert all(np.isnan(v[1, 0]) for v in evaluation.values.values())
    assert all(np.isfinite(v[0, 0]) for v in evaluation.values.values())


def test_every_metric_has_a_unit_and_a_known_source():
    for metric in METRICS.values():
        assert metric.units and metric.source in ("run", "spectrum", "linear")
        assert metric.description


def test_an_unstable_loop_has_no_margin_and_a_hunting_check_skips_the_friction_law():
    from qzs.analysis.control_design.hunting import predict_hunting
    from qzs.analysis.control_design.stability_margins import loop_margins

    document = copy.deepcopy(SHORT)
    document["simulation"] = {}
    document["variables"] = {"pi_ki": {"low": 1.0, "high": 1e6, "scale": "log"}}
    document["objectives"] = [{"metric": "phase_margin", "sense": "maximize"},
                              {"metric": "gain_margin", "sense": "maximize"}]
    document["constraints"] = []
    problem = load_problem(document)
    stiff = qzs.ControllerParameters(pi_ki=1e6)
    assert not loop_margins(qzs.IsolatorParameters(), stiff).stable  # the case checked
    evaluation = evaluate(problem, np.array([[20.0], [1e6]]))
    assert not np.isnan(evaluation.values["gain_margin"][0, 0])  # stable: inf or a number
    # the margin routine gives the unstable loop 92 dB and 73 deg: angles, not margins
    assert np.isnan(evaluation.values["phase_margin"][1, 0])
    assert np.isnan(evaluation.values["gain_margin"][1, 0])
    full = predict_hunting(qzs.IsolatorParameters(), qzs.ControllerParameters())
    quick = predict_hunting(qzs.IsolatorParameters(), qzs.ControllerParameters(),
                            memoryless=False)
    assert (quick.hunts, quick.amplitude) == (full.hunts, full.amplitude)
    assert quick.friction_intersections == () and "memoryless" in quick.reasons[
        "friction_intersections"]


def _robust(document, uncertain, samples):
    document = copy.deepcopy(document)
    document["uncertain"] = uncertain
    document["robust"] = {"samples": samples}
    return load_problem(document)


def test_with_several_draws_each_row_is_its_design_under_each_draw_linear():
    """Several designs under several draws of the mass: value[i, k] is the closed form of
    design i with draw k (design-major, draws fastest), not another design's or draw's."""
    from qzs.analysis.linear import linear_transmissibility

    document = copy.deepcopy(SHORT)
    document["simulation"] = {}
    document["objectives"] = [{"metric": "linear_transmissibility_at", "frequency": 3.0}]
    document["constraints"] = []
    problem = _robust(document, {"mass": {"distribution": "uniform", "low": 5.0,
                                          "high": 8.0}}, 4)
    designs = np.array([[50.0, 20.0], [300.0, 500.0], [1000.0, 3.0]])
    evaluation = evaluate(problem, designs)
    masses = problem.draws()["mass"]
    column = evaluation.values["linear_transmissibility_at_3_hz"]
    assert column.shape == (3, 4) and np.unique(masses).size == 4
    for i, (kd, kp) in enumerate(designs):
        controller = qzs.ControllerParameters(damping_gain=kd, pi_kp=kp)
        for k, mass in enumerate(masses):
            expected = abs(complex(linear_transmissibility(
                3.0, qzs.IsolatorParameters(mass=float(mass)), controller)))
            assert column[i, k] == pytest.approx(expected, rel=1e-12), (i, k)
    assert np.unique(column).size == 12  # every design and draw gives its own number
    # the designs permuted: the rows permute with them, bit for bit
    order = [2, 0, 1]
    permuted = evaluate(problem, designs[order])
    assert np.array_equal(permuted.values["linear_transmissibility_at_3_hz"], column[order])
    assert np.array_equal(permuted.designs, designs[order])


def test_with_several_draws_each_row_is_its_design_under_each_draw_simulated():
    """Simulated metrics of 3 designs under 3 draws of the stiction force, in batches of 4
    cases (cut across designs): value[i, k] and status[i, k] are design i's single run
    with draw k."""
    document = copy.deepcopy(SHORT)
    document["excitation"] = {"duration": 4.0}
    document["analysis"] = {"fft_length": 1024, "duration": 4.0}
    document["objectives"] = [{"metric": "motor_force_rms"}]
    document["constraints"] = [{"metric": "peak_stroke", "max": 0.05}]
    problem = _robust(document, {"stiction_force": {"distribution": "uniform", "low": 2.0,
                                                    "high": 15.0}}, 3)
    designs = np.array([[0.0, 20.0], [150.0, 300.0], [4000.0, 10.0]])
    evaluation = evaluate(problem, designs, batch_size=4)
    forces = problem.draws()["stiction_force"]
    assert evaluation.status.shape == (3, 3) and (evaluation.status == 1).all()
    for i, (kd, kp) in enumerate(designs):
        for k, force in enumerate(forces):
            run = qzs.simulate(qzs.Chirp(duration=4.0), qzs.IsolatorParameters(
                stiction_force=float(force)), qzs.ControllerParameters(
                damping_gain=kd, pi_kp=kp), dt=1e-3, sample_rate=1000.0)
            for name in ("motor_force_rms", "peak_stroke"):
                assert evaluation.values[name][i, k] == pytest.approx(
                    run.statistics[name], rel=1e-12, abs=1e-15), (name, i, k)
    assert np.unique(evaluation.values["motor_force_rms"]).size == 9


def test_with_several_draws_a_failed_design_keeps_its_status_and_messages_in_its_row():
    """Designs ok, refused (a PI gain the kernel cannot step) and ok, each under 3 draws:
    status[i, k], messages[i][k] and the NaN metrics are those of design i, every draw."""
    document = copy.deepcopy(SHORT)
    document["variables"]["pi_kp"] = {"low": 1.0, "high": 1e9, "scale": "log"}
    document["excitation"] = {"duration": 4.0}
    document["analysis"] = {"fft_length": 1024, "duration": 4.0}
    document["objectives"] = [{"metric": "motor_force_rms"}]
    document["constraints"] = []
    problem = _robust(document, {"stiction_force": {"distribution": "uniform", "low": 2.0,
                                                    "high": 15.0}}, 3)
    evaluation = evaluate(problem, np.array([[0.0, 20.0], [0.0, 1e9], [150.0, 300.0]]),
                          batch_size=2)
    failed = np.array([False, True, False])
    np.testing.assert_array_equal(evaluation.status != 1, np.repeat(failed[:, None], 3, 1))
    assert [[bool(m) for m in row] for row in evaluation.messages] == [[f] * 3 for f in failed]
    values = evaluation.values["motor_force_rms"]
    assert np.isnan(values[1]).all() and np.isfinite(values[[0, 2]]).all()
