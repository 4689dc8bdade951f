"""The report's figures (qzs.workflows.findings.figures): which curves, which files."""
import numpy as np

from qzs.workflows.findings.figures import curve_files, figure_curves, figure_names
from qzs.workflows.paper.studies import CaseResult, Study, StudyResult


def result(kind, cases, views=()):
    definition = Study(name="s", title="s", kind=kind, cases=tuple({} for _ in cases),
                       views=tuple(views))
    return StudyResult(definition, list(cases), quick=True)


def case(label, settings, extra=None):
    frequency = np.linspace(0.5, 10.0, 20)
    return CaseResult(label, dict(settings), frequency, 1.0 / frequency,
                      np.ones(frequency.size), frequency > 1.0, phase=np.zeros(frequency.size),
                      stats={"n_averages": 12}, linear={"magnitude": np.ones(frequency.size)},
                      extra=extra or {})


def test_a_transmissibility_study_draws_one_curve_per_case_with_its_parameters():
    """Each curve is its case's, with every swept parameter (the defaults where a case has
    none of its own)."""
    from qzs.model.registry import ALL_PARAMETERS

    cases = [case("a", {"pi_kp": 5.0}), case("b", {"stiction_force": 2.0})]
    curves = figure_curves(result("transmissibility", cases))
    assert [c["label"] for c in curves] == ["a", "b"]
    assert curves[0]["parameters"] == {"pi_kp": 5.0,
                                       "stiction_force": ALL_PARAMETERS["stiction_force"].default}
    np.testing.assert_array_equal(curves[1]["magnitude"], cases[1].magnitude)


def test_a_processing_study_draws_the_ideal_and_the_experiment_style_curve():
    extra = dict(frequency=np.array([1.0, 2.0]), magnitude=np.array([0.5, 0.4]), highpass=1.0,
                 n_averages=6)
    curves = figure_curves(result("processing", [case("x", {}, extra)]))
    assert [c["label"] for c in curves] == [
        "ideal: accelerations, 12 averages",
        "experiment-style: velocities through the 1 Hz high-pass, 6 averages"]
    np.testing.assert_array_equal(curves[1]["magnitude"], [0.5, 0.4])


def test_the_figures_and_curve_files_are_named_by_the_views_and_the_study(tmp_path):
    views = [{"figure": "fig07", "frequency_range": [0.1, 20.0]},
             {"figure": "fig07_zoom", "frequency_range": [1.0, 5.0]}]
    study = result("transmissibility", [case("a", {})], views)
    assert figure_names(study) == ["fig07", "fig07_zoom"]
    assert figure_names(result("spring_characteristic", [])) == ["fig05_spring"]
    assert [p.name for p in curve_files(study, tmp_path)] == [
        f"s_curves{suffix}" for suffix in (".nc", ".csv", ".mat")]


def test_the_experiment_style_curve_is_trusted_on_its_own_bins():
    """The experiment-style estimate has its own bins and its own trusted mask: the figure
    draws that mask (and its coherence, phase) with its curve, not the ideal's."""
    extra = dict(frequency=np.array([1.0, 2.0, 3.0]), magnitude=np.array([0.5, 0.4, 0.3]),
                 highpass=1.0, n_averages=6, trusted=np.array([False, True, True]),
                 coherence=np.array([0.2, 0.95, 0.97]), phase=np.array([0.0, -0.1, -0.2]))
    ideal, experiment = figure_curves(result("processing", [case("x", {}, extra)]))
    for key in ("frequency", "trusted", "coherence", "phase"):
        np.testing.assert_array_equal(experiment[key], extra[key])
    assert ideal["trusted"].shape == ideal["frequency"].shape
