"""The engine: numba kernels, the single and lockstep drivers, and the runs built on them.

==================  ==================================================================
``arithmetic``      own exp/tanh and explicit fused multiply-adds (no fast-math)
``laws``            the force laws, written once as numba functions
``base_motion``     the excitation kernels
``stickslip``       the stick-slip decisions and event location, once for every kernel
``kernels``         right-hand side, Runge-Kutta steps, stick-slip events (one case)
``lanes``           the drivers: one case, or many in lockstep
``stability``       the solvers and their linear stability limit
``prepare``         validation and packing shared by single and batch runs
``single``          :func:`~qzs.engine.single.integrate`, one run at a given step
``simulate``        :func:`simulate`, a run resolved then integrated
``batch``           :func:`simulate_batch`, many parameter sets at once
``channels``        the output channels and flags of a run, and its file schema
``metadata``        a run's parameters and settings with units, its file's global attributes
``result``          :class:`SimulationResult`
``result_file``     a run's file: :class:`~qzs.engine.result_file.ResultWriter`, save, read, size
``step_search``     the one step search, its fallback and its record (:class:`StepChoice`)
``step_choice``     :func:`~qzs.engine.step_choice.choose`: a request and a probe, one call
``step_views``      a step choice's candidates as a dataset (its ``to_xarray``, ``save``)
``accuracy``        :func:`choose_step`, the step of one axis: its probe and measures
``accuracy_batch``  :func:`~qzs.engine.accuracy_batch.choose_batch_step`, one step for a batch
``run_spec``        :func:`resolve`, a run resolved once: inputs, duration, step and record
``step_cache``      the step choices kept on disk, keyed by their inputs and the code
``driver``          the one run loop: plan, chunks, memory guard, preview, progress, signals
``periodic``        :class:`~qzs.engine.periodic.PeriodicRun`, a run advanced one period per call
``compiling``       :func:`~qzs.engine.compiling.compile_notice`: say so while kernels compile
``progress``        :func:`~qzs.engine.progress.progress_bar`: tqdm's bar, or plain lines
``hexapod``         subpackage: :func:`simulate_hexapod`, six isolator legs under a rigid platform
==================  ==================================================================
"""
from qzs._lazy import lazy_exports

_EXPORTS = {
    "simulate": "qzs.engine.simulate", "simulate_batch": "qzs.engine.batch",
    "BatchResult": "qzs.engine.batch", "SimulationResult": "qzs.engine.result",
    "CHANNELS": "qzs.engine.channels", "FLAGS": "qzs.engine.channels",
    "simulation_schema": "qzs.engine.channels", "ResultWriter": "qzs.engine.result_file",
    "save_result": "qzs.engine.result_file", "read_result": "qzs.engine.result_file",
    "estimated_size": "qzs.engine.result_file",
    "SOLVERS": "qzs.engine.stability", "largest_stable_step": "qzs.engine.stability",
    "prepare_run": "qzs.engine.prepare", "steps_per_sample": "qzs.engine.prepare",
    "base_motion_series": "qzs.engine.base_motion",
    "choose_step": "qzs.engine.accuracy", "StepChoice": "qzs.engine.step_search",
    "resolve": "qzs.engine.run_spec", "ResolvedRun": "qzs.engine.run_spec",
    "simulate_hexapod": "qzs.engine.hexapod.simulate",
    "HexapodResult": "qzs.engine.hexapod.result",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
