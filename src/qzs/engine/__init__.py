"""The engine: numba kernels, the single and lockstep drivers, and the runs built on them.

``arithmetic``   own exp/tanh and explicit fused multiply-adds (no fast-math)
``laws``         the force laws, written once as numba functions
``base_motion``  the excitation kernels
``kernels``      right-hand side, Runge-Kutta steps, stick-slip events (one case)
``lanes``        the drivers: one case, or many in lockstep
``stability``    the solvers and their linear stability limit
``prepare``      validation and packing shared by single and batch runs
``simulate``     :func:`simulate`, the validated single run
``batch``        :func:`simulate_batch`, many parameter sets at once
``results``      :class:`SimulationResult`
"""
from qzs.engine.base_motion import base_motion_series
from qzs.engine.batch import BatchResult, simulate_batch
from qzs.engine.prepare import prepare_run, steps_per_sample
from qzs.engine.results import CHANNELS, FLAGS, SimulationResult
from qzs.engine.simulate import simulate
from qzs.engine.stability import SOLVERS, largest_stable_step

__all__ = ["simulate", "simulate_batch", "BatchResult", "SimulationResult", "CHANNELS", "FLAGS",
           "SOLVERS", "largest_stable_step", "prepare_run", "steps_per_sample",
           "base_motion_series"]
