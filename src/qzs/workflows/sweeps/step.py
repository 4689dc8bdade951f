"""A sweep's integration step, chosen for its tolerance on a few of its cases.

A sweep whose file gives no ``dt`` is integrated at the step :func:`choose_sweep_step`
chooses for ``[simulation] tolerance`` on :data:`STEP_CASES` cases spread over it.
"""
import warnings

import numpy as np

from qzs.engine.step_choice import fallback_step
from qzs.errors import DataWarning, ParameterError
from qzs.workflows.sweeps.cases import build_case

__all__ = ["choose_sweep_step", "STEP_CASES"]

#: Cases of a sweep the accuracy-driven step is chosen on: the first, the middle and the
#: last (for a grid, its two extreme corners and its centre).
STEP_CASES = 3



def choose_sweep_step(definition, settings, *, progress=False):
    """Fix a sweep's step: the largest meeting its ``tolerance`` on every case probed.

    A sweep whose file gives no ``dt`` is integrated at the step chosen for
    ``[simulation] tolerance`` (default :data:`qzs.defaults.ACCURACY`) on
    :data:`STEP_CASES` cases spread over the sweep, probed at once
    (:func:`qzs.engine.step_choice.choose` on a batch probe, each group of them sharing an
    excitation in one batch); the smallest of their steps serves every case (all cases of
    a batch share their steps). Choosing is deterministic, so a resumed sweep gets the
    same step.

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    settings : list of dict
        The varied parameters of each case (:func:`case_settings`).
    progress : bool
        Show the probes' progress.

    Returns
    -------
    definition : SweepDefinition
        With ``simulation["dt"]`` set (the same object if the file gave ``dt``).
    choices : tuple of (int, BatchStepChoice)
        The probed cases' indices and their choices, each with the case's own ``dt`` and
        ``error`` (empty if the file gave ``dt``; a case no step meets is left out).

    Raises
    ------
    ParameterError
        No probed case is valid.

    Warns
    -----
    DataWarning
        A probed case for which no step meets the tolerance (its response depends on
        the step): the step comes from the others (the paper's dt = 1e-4 s if none), and
        the note says so.
    """
    import dataclasses

    simulation = definition.simulation
    if simulation["dt"] is not None:
        return definition, ()
    picks = sorted({int(i) for i in np.linspace(0, len(settings) - 1, STEP_CASES).round()})
    groups, reasons = {}, []
    for i in picks:
        try:
            isolator, controller, (excitation, _), key = build_case(definition, settings[i])
        except (ParameterError, TypeError) as error:
            reasons.append(f"case {i}: {error}")
            continue
        groups.setdefault(key, (excitation, []))[1].append((i, (isolator, controller)))
    if not groups:
        raise ParameterError("no step could be chosen for `tolerance`: the cases probed "
                             f"are invalid ({'; '.join(reasons)}); fix them or give `dt`.")
    tolerance = simulation["tolerance_db"]
    choices, unmet = [], []
    for excitation, members in groups.values():  # the probed cases of one excitation at once
        labels = [f"case {i}" for i, _ in members]
        batch = _choose(definition, excitation, members, labels, progress)
        if not batch.met:  # the one fallback: no case of this excitation sets the step
            unmet.append(f"{', '.join(labels)}: {batch.unmet_note}")
            continue
        choices += [(i, dataclasses.replace(batch, dt=batch.case_steps[c],
                                            error=batch.case_errors[c]))
                    for c, (i, _) in enumerate(members) if c not in batch.unmet]
        unmet += [note for note in batch.notes if note.startswith(tuple(labels))]
    if choices:
        dt = min(choice.dt for _, choice in choices)
        note = (f"dt = {dt:g} s chosen for the transmissibility within {tolerance:g} dB on "
                "cases " + ", ".join(f"{i} (dt {c.dt:g} s, estimated error {c.error:.2g} dB)"
                                     for i, c in choices))
    else:
        dt = fallback_step()
        note = f"dt = {dt:g} s, the paper's step: no case probed meets {tolerance:g} dB"
    if unmet:
        note += "; " + "; ".join(unmet) + "; their curves carry that uncertainty"
        warnings.warn(note, DataWarning, stacklevel=2)
    simulation = {**simulation, "dt": dt, "step_note": note}
    return dataclasses.replace(definition, simulation=simulation), tuple(choices)


def _choose(definition, excitation, members, labels, progress):
    """The one call on a batch probe of the probed cases sharing ``excitation``."""
    from qzs.engine.accuracy_batch import BatchProbe
    from qzs.engine.step_choice import StepRequest, choose
    from qzs.engine.step_search import MAX_HALVINGS

    request = StepRequest(tolerance=definition.simulation["tolerance_db"])
    return choose(request, BatchProbe(cases=[pair for _, pair in members], excitation=excitation,
                                      solver=definition.simulation["solver"],
                                      sample_rate=definition.analysis["sample_rate"],
                                      max_halvings=MAX_HALVINGS, labels=labels),
                  fallback=True, progress=progress, cache=True)
