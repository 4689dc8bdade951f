"""The engine: numba kernels, the single and lockstep drivers, and the runs built on them.

==================  ==========================================================="""
from qzs._lazy import lazy_exports

_EXPORTS = {
    "simulate": "qzs.engine.simulate", "simulate_batch": "qzs.engine.batch",
    "BatchResult": "qzs.engine.batch", "SimulationResult": "qzs.engine.results",
    "CHANNELS": "qzs.engine.results", "FLAGS": "qzs.engine.results",
    "SOLVERS": "qzs.engine.stability", "largest_stable_step": "qzs.engine.stability",
    "prepare_run": "qzs.engine.prepare", "steps_per_sample": "qzs.engine.prepare",
    "base_motion_series": "qzs.engine.base_motion",
    "choose_step": "qzs.engine.accuracy", "StepChoice": "qzs.engine.accuracy",
    "simulate_hexapod": "qzs.engine.hexapod.simulate",
    "HexapodResult": "qzs.engine.hexapod.result",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
