"""Run a case through qzs's C model of the isolator (``csrc/``), as :func:`qzs.simulate` would.

The case is validated and packed by :func:`qzs.engine.prepare.prepare_run` (the same
parameters, initial state with the PI preload, excitation and step as a qzs run); the C
closed loop (``qzs_model_run``: :func:`qzs.engine.lanes.run_single` operation for
operation) then integrates it in one call. Used by the tests that hold the C model to the
numba kernels, by the benchmarks' C baseline and by the FMU export.
"""
import ctypes
import time
from dataclasses import dataclass

import numpy as np

from qzs.engine import kernels as K
from qzs.engine.prepare import prepare_run
from qzs.errors import ParameterError
from qzs.export.csource import load_model

__all__ = ["CRun", "run_prepared", "simulate_c"]


@dataclass(frozen=True, kw_only=True)
class CRun:
    """What a run of the C model returns.

    Attributes
    ----------
    data : ndarray, shape (samples, N_CHANNELS)
        The recorded channels, columns as :data:`qzs.engine.channels.CHANNELS`.
    flags : ndarray of bool, shape (samples, 2)
        The locked and stop-contact flags.
    state : ndarray, shape (N_STATE,)
        The final state (``S_*``, the held controller outputs, the holding margin).
    run_flags : ndarray of int64, shape (N_FLAGS,)
        The final integer flags (``I_*``: mode, direction, step, contact and counters).
    diverged : bool
        The run stopped at ``run_flags[I_STEP]``: the state diverged, or the payload left a
        spring table that refuses positions outside it (``status``).
    status : int
        The C's status: ``K.STATUS_OK``, ``K.STATUS_DIVERGED`` or ``K.STATUS_OUTSIDE``.
    seconds : float
        Wall time of the C call [s].
    """

    data: np.ndarray
    flags: np.ndarray
    state: np.ndarray
    run_flags: np.ndarray
    diverged: bool
    status: int
    seconds: float

    @property
    def steps(self):
        """Integration steps taken [-]."""
        return int(self.run_flags[K.I_STEP])


def _pointer(array, kind=ctypes.c_double):
    return array.ctypes.data_as(ctypes.POINTER(kind))


def run_prepared(run, *, native=False, out=None, out_flags=None):
    """Integrate a prepared run in C, from t = 0 to its duration.

    Parameters
    ----------
    run : qzs.engine.prepare.PreparedRun
        The validated, packed case (not changed: its state is copied).
    native : bool
        Use the library compiled for this CPU (:data:`qzs.export.csource.NATIVE_CFLAGS`).
    out : ndarray, shape (samples, N_CHANNELS), optional
        A buffer to reuse (float64, C-contiguous, ``K.N_CHANNELS`` columns [various units]:
        the C writes whole rows, the blocks' columns too).
    out_flags : ndarray of uint8, shape (samples, 2), optional
        Its flags' buffer.

    Returns
    -------
    CRun

    Raises
    ------
    CompilerError
        No C compiler, or it failed.
    ParameterError
        ``out`` or ``out_flags`` of a shape, type or layout the C would overrun.
    """
    steps = int(round(run.duration / run.dt))
    samples = steps // run.decimation + 1
    if out is None:
        out = np.zeros((samples, K.N_CHANNELS))
    if out_flags is None:
        out_flags = np.zeros((samples, 2), dtype=np.uint8)
    _check_buffer("out", out, (samples, K.N_CHANNELS), np.float64)
    _check_buffer("out_flags", out_flags, (samples, 2), np.uint8)
    library = load_model(native)
    state = np.array(run.state, dtype=np.float64)
    flags = np.array(run.flags, dtype=np.int64)
    params = np.ascontiguousarray(run.params, dtype=np.float64)
    model = np.ascontiguousarray(run.model, dtype=np.float64)
    scalars = np.ascontiguousarray(run.packed[0], dtype=np.float64)
    table = np.ascontiguousarray(run.packed[1], dtype=np.float64)
    rows = np.zeros(1, dtype=np.int64)
    library.qzs_model_evaluate(0.0, _pointer(state), _pointer(flags, ctypes.c_int64),
                               _pointer(params), _pointer(model), _pointer(scalars),
                               _pointer(table), table.shape[1], _pointer(out),
                               _pointer(out_flags, ctypes.c_ubyte))
    start = time.perf_counter()
    status = library.qzs_model_run(run.solver_code, steps, run.decimation, _pointer(state),
                                   _pointer(flags, ctypes.c_int64), _pointer(params),
                                   _pointer(model), _pointer(scalars), _pointer(table), table.shape[1],
                                   _pointer(out), _pointer(out_flags, ctypes.c_ubyte), 1,
                                   _pointer(rows, ctypes.c_int64))
    seconds = time.perf_counter() - start
    written = 1 + int(rows[0])
    return CRun(data=out[:written], flags=out_flags[:written].astype(bool), state=state,
                run_flags=flags, diverged=status != K.STATUS_OK, status=int(status),
                seconds=seconds)


def _check_buffer(name, array, rows_columns, dtype):
    """Refuse a buffer the C would overrun or misread: it writes whole rows of ``dtype``."""
    rows, columns = rows_columns
    if (not isinstance(array, np.ndarray) or array.dtype != dtype or array.ndim != 2
            or array.shape[1] != columns or array.shape[0] < rows
            or not array.flags.c_contiguous or not array.flags.writeable):
        got = (f"{array.dtype} {array.shape}, C-contiguous {array.flags.c_contiguous}"
               if isinstance(array, np.ndarray) else type(array).__name__)
        raise ParameterError(f"`{name}` must be a writeable C-contiguous {np.dtype(dtype)} "
                             f"array of at least {rows} rows and exactly {columns} columns "
                             f"(the C writes whole rows), got {got}; pass None to have one "
                             f"made, or np.zeros(({rows}, {columns}), dtype=np.{np.dtype(dtype)}).",
                             options=(name,))


def simulate_c(excitation=None, isolator=None, controller=None, *, native=False, **settings):
    """:func:`qzs.simulate`'s case integrated by the C model.

    Parameters
    ----------
    excitation : Chirp, Sine, RandomExcitation or DisplacementRecord, optional
        Base motion (as :func:`qzs.simulate`).
    isolator : IsolatorParameters, optional
        Plant parameters.
    controller : ControllerParameters, optional
        PI and damping loops.
    native : bool
        Use the library compiled for this CPU.
    **settings
        ``duration``, ``dt``, ``sample_rate``, ``solver``, ``initial_state`` as
        :func:`qzs.simulate` takes them (validated the same way).

    Returns
    -------
    CRun
    """
    return run_prepared(prepare_run(excitation, isolator, controller, **settings), native=native)
