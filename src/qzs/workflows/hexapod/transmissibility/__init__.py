"""The simulated 6x6 transmissibility of a hexapod: one chirp per excited base axis.

Column ``j`` of the matrix comes from a run whose base moves along axis ``j`` alone
(x, y, z [m]; rx, ry, rz [rad]): each platform axis ``i`` is reduced against it by the
single axis's Welch estimator (:func:`qzs.analysis.spectral.transmissibility`, ``H1`` by
default), from the base point's velocity ``base_velocity[:, j]`` to the platform's twist
``platform_twist[:, i]`` (docs/hexapod.md §9.3). Both are taken at the top frame origin
(the cube's centre of a cubic geometry), the point :func:`qzs.analysis.hexapod_linear.
hexapod_linearize` calls ``frame="origin"``, so its transmissibility is the linear
overlay. A ratio of velocities is the ratio of displacements or accelerations; velocities
are used because a constant-displacement chirp's base velocity holds more of its power at
low frequency than its acceleration does.

**Trusted entries** (docs/hexapod.md §10.2). Each entry keeps its coherence and the single
axis's trusted bins (docs/model.md §10); bins below the frequency the chirp reaches a
quarter segment into the run are untrusted (:func:`sweep_trusted_from`: one segment holds
them, under its rising taper, so their coherence is 1 by construction); and an entry is
untrusted where its response is below a numerical floor (``floor_db``, -100 dB by
default) of the base motion. The floor is needed: the
cross-axis entries of a symmetric platform are zero in exact arithmetic, and what the
run gives there is rounding (1e-16 to 1e-7 of the base motion, amplified by the Stribeck
friction's negative slope), which is as deterministic as the chirp, so its coherence can
reach 0.99 in a few bins. The floor compares dimensionless magnitudes: a rotation is
turned into a length by the platform's size ``r`` (the top joints' RMS distance from their
centroid), so a rotation per translation counts as ``|T| r`` and a translation per
rotation as ``|T| / r``.

**Integration step.** Where ``dt`` is not given, each run's step is chosen for a tolerance
on the run's column of the matrix (``tolerance_db``, default ``ACCURACY["tolerance_db"]``,
0.01 dB) by :func:`qzs.engine.hexapod.accuracy.choose_hexapod_step` (the single axis's
method, docs/model.md §7): the probe of :func:`~qzs.engine.accuracy.probe_excitation`,
steps halved from the largest stable one that divides the output period down to the
set-up's ``dt``, the column's entries compared between successive steps over their trusted
bins above the numerical floor, the error extrapolated with the observed ratio (capped at
the scheme's order), a safety factor of 2. Where no step coarser than the set-up's meets it
(stick-slip whose pattern changes with the step, so that the differences do not shrink),
the run takes the set-up's ``dt`` and its record says why.

=============  ================================================================
``settings``   default chirp and amplitudes, the numerical floor, the platform's size
``plan``       validation and the plan of the runs (axes, amplitudes, step, segments)
``runs``       one run per excited base axis: its step, simulation and estimates
``matrix``     :func:`hexapod_transmissibility`, the runs assembled into the matrix
``result``     :class:`HexapodTransmissibility` and its views: summary, record, file
=============  ================================================================
"""
from qzs.analysis.hexapod_linear import entry_unit
from qzs.workflows.hexapod.transmissibility.matrix import hexapod_transmissibility
from qzs.workflows.hexapod.transmissibility.plan import sweep_trusted_from
from qzs.workflows.hexapod.transmissibility.result import (HexapodTransmissibility,
                                                           transmissibility_dataset,
                                                           transmissibility_record,
                                                           transmissibility_schema,
                                                           transmissibility_summary)
from qzs.workflows.hexapod.transmissibility.runs import axis_step
from qzs.workflows.hexapod.transmissibility.settings import (AMPLITUDE, CHIRP, ESTIMATORS,
                                                             FLOOR_DB, platform_size)

__all__ = ["HexapodTransmissibility", "hexapod_transmissibility", "AMPLITUDE", "CHIRP",
           "FLOOR_DB", "ESTIMATORS", "transmissibility_summary", "transmissibility_dataset",
           "transmissibility_record", "axis_step", "sweep_trusted_from",
           "platform_size", "entry_unit", "transmissibility_schema"]
