"""A built probe of made-up runs, for the tests of the one search (``search_step``)."""
from qzs.engine.step_choice import Probe
from qzs.engine.step_search import MAX_HALVINGS, SAFETY, search_step


def search(*, run, compare, dt0, order, measure, tolerance, sample_rate, solver, probe,
           probe_duration, band, stability_limit, notes=(), cases=1, labels=None,
           max_halvings=MAX_HALVINGS, safety=SAFETY, finest=None, fallback=False,
           progress=False, give_up_early=False, per_case=False, unit_name="run"):
    """``search_step`` on a probe made of these pieces (``start`` unused: ``dt0`` given)."""
    built = Probe(measure=measure, order=order, sample_rate=sample_rate, solver=solver,
                  excitation=probe, duration=probe_duration, band=band, shortened=False,
                  start=None, run=run, compare=compare, cases=cases, labels=labels,
                  max_halvings=max_halvings, safety=safety,
                  search=dict(give_up_early=give_up_early, per_case=per_case,
                              unit_name=unit_name))
    return search_step(built, tolerance=tolerance, dt0=dt0, stability_limit=stability_limit,
                       notes=notes, finest=finest, fallback=fallback, progress=progress)
