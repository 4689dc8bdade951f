"""Six-leg Stewart platform of isolator legs: rigid-body dynamics with exact stick-slip per leg.

The dynamics of docs/hexapod.md ("Dynamics"): a rigid platform on six single-axis isolator
legs (:mod:`qzs.engine.laws`: MagSpring, Stribeck friction, compliant stops, PI + active
damping), driven by a base moving in up to six axes. The modules mirror the single axis's
(:mod:`qzs.engine.kernels`, :mod:`~qzs.engine.prepare`, :mod:`~qzs.engine.simulate`,
:mod:`~qzs.engine.result`), one concept each:

==============  ====================================================================
``layout``      the packed layouts: per-leg rows, platform constants, state, outputs
``dynamics``    kernels: base frame, kinematics, the locked legs' solve, right-hand side
``stepping``    kernels: Runge-Kutta, events and transitions, output samples, the run
``prepare``     validation and packing, :func:`hexapod_stability_test`
``simulate``    :func:`simulate_hexapod` and :func:`simulate_hexapods`, the drivers
``result``      :class:`HexapodResult`, its channels, flags, schema and writer
``statistics``  run statistics over every sample and the summary text
``accuracy``    :func:`choose_hexapod_step`, the largest step meeting a tolerance
==============  ====================================================================
"""
from qzs._lazy import lazy_exports

_EXPORTS = {
    "simulate_hexapod": "qzs.engine.hexapod.simulate",
    "simulate_hexapods": "qzs.engine.hexapod.simulate",
    "hexapod_stability_test": "qzs.engine.hexapod.prepare",
    "check_hexapod_run": "qzs.engine.hexapod.prepare",
    "choose_hexapod_step": "qzs.engine.hexapod.accuracy",
    "HexapodResult": "qzs.engine.hexapod.result",
    "AXES": "qzs.engine.hexapod.layout",
    "HEXAPOD_CHANNELS": "qzs.engine.hexapod.result",
    "HEXAPOD_FLAGS": "qzs.engine.hexapod.result",
    "hexapod_schema": "qzs.engine.hexapod.result",
    "hexapod_file_layout": "qzs.engine.hexapod.result",
    "HexapodWriter": "qzs.engine.hexapod.result",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
