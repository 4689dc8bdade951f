"""The benchmarks' C baseline: qzs's own C model of the isolator, run from Python.

    from reference import build, run_reference
    lib = build()                                   # cc -O3 -march=native ... (once a process)
    r = run_reference(qzs.Chirp(duration=200.0))    # same arguments as qzs.simulate

The C is the one C implementation of the single-axis model that ships with qzs
(``src/qzs/export/csrc``: plant, sampled controller, closed loop; the FMU's model too). It
mirrors the numba kernels operation for operation -- stick-slip events located inside the
step, compliant and plastic stops, the sampled controller, the energy ledger, the 24 channels
-- and tests/export/test_cmodel.py holds it to them bit for bit. Here it is compiled for this
CPU (``qzs.export.csource.NATIVE_CFLAGS``: -O3 -march=native, no fast-math, no implicit
contraction, as numba compiles qzs) into a temporary folder and loaded with ``ctypes``.
Parameters, the initial state (with the PI preload) and the packed excitation come from
``qzs.engine.prepare.prepare_run``, so the C integrates exactly the case qzs would.

``python benchmarks/c_reference/reference.py`` times 20 s of the paper's chirp in C and in
the numba kernel (``qzs.engine.lanes.run_single``), side by side.
"""
import shutil
import time

import numpy as np

from qzs.engine.kernels import N_CHANNELS  # noqa: E402 - the C writes every column of a row
STATUS = {False: "ok", True: "diverged"}


def _csource():
    from qzs.export import csource

    return csource


CFLAGS = ()  # filled on first use from qzs.export.csource.NATIVE_CFLAGS


def compiler():
    """Path of the system C compiler (``$CC``, cc or gcc), or None."""
    from qzs.errors import CompilerError

    try:
        return _csource().find_compiler()
    except CompilerError:
        return shutil.which("gcc")


def build(force=False):
    """Compile qzs's C model for this CPU (once a process) and load it: the ctypes library.

    Raises ``RuntimeError`` (qzs's ``CompilerError``) without a working compiler.
    """
    global CFLAGS
    csource = _csource()
    CFLAGS = csource.NATIVE_CFLAGS
    return csource.load_model(native=True)


def prepare(excitation=None, isolator=None, controller=None, **kwargs):
    """qzs' own packing of the case: ``qzs.engine.prepare.prepare_run`` (same arguments)."""
    from qzs.engine.prepare import prepare_run

    return prepare_run(excitation, isolator, controller, **kwargs)


def run_prepared(run, out=None, out_flags=None):
    """Integrate a :class:`qzs.engine.prepare.PreparedRun` in C.

    ``out`` (rows, N_CHANNELS) and ``out_flags`` (rows, 2) may be given to reuse a buffer. Returns a
    dict: ``out``, ``flags``, ``rows``, ``steps``, ``seconds`` (the C call only),
    ``state`` (the final 8 states), ``stop_contacts``, ``stick_events``, ``status``.
    """
    from qzs.engine import kernels as K
    from qzs.export.cmodel import run_prepared as run_c

    build()
    r = run_c(run, native=True, out=out, out_flags=out_flags)
    return dict(out=r.data, flags=r.flags, rows=len(r.data), steps=r.steps, seconds=r.seconds,
                state=r.state[:K.N_ODE], stop_contacts=int(r.run_flags[K.I_N_CONTACTS]),
                stick_events=int(r.run_flags[K.I_N_STICKS]), status=STATUS[r.diverged])


def run_reference(excitation=None, isolator=None, controller=None, **kwargs):
    """Prepare the case as ``qzs.simulate`` would (same arguments) and integrate it in C."""
    return run_prepared(prepare(excitation, isolator, controller, **kwargs))


def numba_seconds(run, out=None, out_flags=None):
    """Wall time [s] of the numba kernel (``lanes.single_kernel`` of the run's controller, one
    call) on the same prepared run; ``out`` and ``out_flags``, if given, receive its rows."""
    from qzs.engine import kernels as K
    from qzs.engine import lanes

    steps = int(round(run.duration / run.dt))
    rows = steps // run.decimation + 1
    out = np.zeros((rows, K.N_CHANNELS)) if out is None else out
    out_flags = np.zeros((rows, 2), dtype=bool) if out_flags is None else out_flags
    state, flags = run.state.copy(), run.flags.copy()
    kernel = lanes.single_kernel(run.model)
    kernel(run.solver_code, 0, run.decimation, state, flags, run.params, run.model,
           *run.packed, out, out_flags, 1)  # compiled or loaded: not timed
    start = time.perf_counter()
    kernel(run.solver_code, steps, run.decimation, state, flags, run.params, run.model,
           *run.packed, out, out_flags, 1)
    return time.perf_counter() - start


if __name__ == "__main__":  # quick look: the paper's chirp, 20 s, C beside numba
    import qzs

    run = prepare(qzs.Chirp(amplitude=0.01, f0=0.0, f1=20.0, duration=2000.0),
                  duration=20.0, dt=1e-4, sample_rate=1000.0)
    r = run_prepared(run)
    seconds = numba_seconds(run)
    print(f"{build().path}: {r['steps']:,} steps in {r['seconds']:.3f} s "
          f"({r['steps'] / r['seconds']:,.0f} steps/s), {r['rows']} rows, {r['status']}; "
          f"numba kernel {seconds:.3f} s ({r['steps'] / seconds:,.0f} steps/s)")
