"""What a step choice shows besides its text: its candidates as a dataset, a figure and files.

:class:`~qzs.engine.step_search.StepChoice` gets the result protocol by delegation (issue 42):
:func:`step_dataset` for ``to_xarray`` (one row per candidate step tried: the step, its
difference to the next finer one and the estimated error, with the record's attributes),
:func:`qzs.viz.step.plot_step_choice` for ``plot``, and
:func:`qzs.iotools.result_files.save_by_extension` for ``save`` (the dataset as .nc, .csv or
.mat; the record, :meth:`~qzs.engine.step_search.StepChoice.to_dict`, as .json).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from qzs.iotools.schema import Schema, Variable, to_dataset

if TYPE_CHECKING:
    import xarray as xr

__all__ = ["step_dataset", "step_schema"]


def step_schema(choice: Any) -> Schema:
    """The CF layout of a step choice: its candidates on ``candidate``.

    Parameters
    ----------
    choice : StepChoice
        The record.

    Returns
    -------
    Schema
    """
    on = ("candidate",)
    unit, note = (choice.unit if choice.chosen else None), {}
    if unit == "dB":  # UDUNITS has no logarithmic unit: CF's "1", the decibels said
        unit, note = "1", {"comment": "in decibels (dB): 20 log10 of a ratio of the "
                                      "transmissibility's magnitudes"}
    what = ("the transmissibility's largest difference over the band's trusted bins"
            if choice.measure == "transmissibility_db"
            else "the relative position's largest difference over the output samples")
    variables = (
        Variable(name="step", dims=on, units="s", long_name="candidate integration step"),
        Variable(name="difference", dims=on, units=unit, attributes=note,
                 long_name=f"{what} between this step's probe run and the next finer one's"),
        Variable(name="estimated_error", dims=on, units=unit, attributes=note,
                 long_name="estimated error of a run at this step (Richardson extrapolation "
                           "of the differences; NaN where the differences do not shrink)"))
    return Schema(kind="an integration step choice", dimensions={"candidate": len(choice.history)},
                  variables=variables)


def step_dataset(choice: Any) -> xr.Dataset:
    """A step choice's candidates, with its record as attributes.

    Parameters
    ----------
    choice : StepChoice
        The record.

    Returns
    -------
    xarray.Dataset
        ``step`` [s], ``difference`` and ``estimated_error`` (in the measure's unit, [dB] or
        [m]; dB is written as CF's units "1" with a comment saying decibels) per candidate, coarsest first (none for a literal step); attributes ``dt`` [s],
        ``solver``, ``sample_rate`` [Hz], ``stability_limit`` [s] and the run entries of
        :meth:`~qzs.engine.step_search.StepChoice.attributes`.
    """
    rows = np.array([row[:3] for row in choice.history], dtype=float).reshape(-1, 3)
    attrs = {"title": f"integration step choice: dt = {choice.dt:.6g} s",
             "dt": float(choice.dt), "solver": choice.solver,
             "sample_rate": float(choice.sample_rate),
             "stability_limit": float(choice.stability_limit), **choice.attributes()}
    return to_dataset(step_schema(choice), {"step": rows[:, 0], "difference": rows[:, 1],
                                            "estimated_error": rows[:, 2]}, attrs)
