"""Build and run the C reference model (isolator.c) from Python.

    from reference import build, run_reference
    lib = build()                                   # gcc -O3 ... into a cache folder
    r = run_reference(qzs.Chirp(duration=200.0))    # same arguments as qzs.simulate

The shared library is compiled with the system ``gcc`` into a cache folder outside the
repository (``$QZS_C_REFERENCE_CACHE``, else ``$XDG_CACHE_HOME/qzs-c-reference``, else
``~/.cache/qzs-c-reference``), named by a hash of the source and the flags, and loaded with
``ctypes``. Parameters, the initial state (with the PI preload) and the packed excitation
come from ``qzs.engine.prepare.prepare_run``, so the C integrates exactly the case qzs would.
"""
import ctypes
import hashlib
import os
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

SOURCE = Path(__file__).with_name("isolator.c")
#: Comparable to numba's code generation for qzs: full optimisation for this CPU, no
#: fast-math, no implicit fused multiply-add (qzs' fmas are explicit fma() calls, which
#: -march=native turns into the FMA instruction), and libm calls that need not set errno
#: (as LLVM's math intrinsics, which numba emits, do not).
CFLAGS = ("-O3", "-march=native", "-ffp-contract=off", "-fno-math-errno", "-fPIC", "-shared")
N_CHANNELS = 24
STATUS = {0: "ok", 1: "diverged", 2: "unsupported case", 3: "output buffer too small"}

_LIB = None


def compiler():
    """Path of the system C compiler (``$CC`` or gcc), or None."""
    return shutil.which(os.environ.get("CC", "gcc"))


def cache_dir():
    root = os.environ.get("QZS_C_REFERENCE_CACHE")
    if root:
        return Path(root)
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "qzs-c-reference"


def build(force=False):
    """Compile isolator.c (once per source and flags) and load it; returns the ctypes library."""
    global _LIB
    if _LIB is not None and not force:
        return _LIB
    cc = compiler()
    if cc is None:
        raise RuntimeError("no C compiler found (gcc, or $CC)")
    source = SOURCE.read_bytes()
    key = hashlib.sha256(source + " ".join((cc,) + CFLAGS).encode()).hexdigest()[:16]
    folder = cache_dir()
    folder.mkdir(parents=True, exist_ok=True)
    target = folder / f"isolator-{key}.so"
    if force or not target.exists():
        with tempfile.TemporaryDirectory(dir=folder) as tmp:
            built = Path(tmp) / target.name
            proc = subprocess.run([cc, *CFLAGS, "-o", str(built), str(SOURCE), "-lm"],
                                  capture_output=True, text=True)
            if proc.returncode != 0:
                raise RuntimeError(f"gcc failed:\n{proc.stderr}")
            os.replace(built, target)  # atomic: concurrent builds do not see half a file
    lib = ctypes.CDLL(str(target))
    f = lib.qzs_ref_run
    dp = ctypes.POINTER(ctypes.c_double)
    lp = ctypes.POINTER(ctypes.c_long)
    f.argtypes = [dp, dp, dp, lp, ctypes.c_long, ctypes.c_long, ctypes.c_long, ctypes.c_int,
                  dp, ctypes.POINTER(ctypes.c_ubyte), ctypes.c_long, lp]
    f.restype = ctypes.c_int
    lib.path = target
    _LIB = lib
    return lib


def _ptr(a, kind=ctypes.c_double):
    return a.ctypes.data_as(ctypes.POINTER(kind))


def prepare(excitation=None, isolator=None, controller=None, **kwargs):
    """qzs' own packing of the case: ``qzs.engine.prepare.prepare_run`` (same arguments)."""
    from qzs.engine.prepare import prepare_run

    run = prepare_run(excitation, isolator, controller, **kwargs)
    if run.solver_code != 1:
        raise ValueError("the C reference integrates ode3 only")
    if run.isolator.friction_regularisation > 0:
        raise ValueError("the C reference has the exact model's friction law only "
                         "(friction_regularisation = 0)")
    return run


def run_prepared(run, out=None, out_flags=None):
    """Integrate a :class:`qzs.engine.prepare.PreparedRun` in C.

    ``out`` (rows, 24) and ``out_flags`` (rows, 2) may be given to reuse a buffer. Returns a
    dict: ``out``, ``flags``, ``rows``, ``steps``, ``seconds`` (the C call only),
    ``state`` (the final 8 states), ``stop_contacts``, ``status``.
    """
    lib = build()
    from qzs.engine import kernels as K

    n_steps = int(round(run.duration / run.dt))
    rows = n_steps // run.decimation + 1
    if out is None:
        out = np.empty((rows, N_CHANNELS))
    if out_flags is None:
        out_flags = np.zeros((rows, 2), dtype=np.uint8)
    assert out.flags.c_contiguous and out.dtype == np.float64 and out.shape[1] == N_CHANNELS
    assert out_flags.flags.c_contiguous and out_flags.dtype == np.uint8
    params = np.ascontiguousarray(run.params, dtype=np.float64)
    ex = np.ascontiguousarray(run.packed[0], dtype=np.float64)
    state = np.ascontiguousarray(run.state[:K.N_ODE], dtype=np.float64).copy()
    direction = ctypes.c_long(int(run.flags[K.I_DIRECTION]))
    counters = np.zeros(3, dtype=np.int64)
    if run.flags[K.I_MODE] != K.MODE_SLIP:
        state[K.S_V] = 0.0  # qzs starts stuck; the C model has no locking and starts slipping
    start = time.perf_counter()
    status = lib.qzs_ref_run(_ptr(params), _ptr(ex), _ptr(state), ctypes.byref(direction), 0,
                             n_steps, run.decimation, 1, _ptr(out),
                             _ptr(out_flags, ctypes.c_ubyte), out.shape[0],
                             _ptr(counters, ctypes.c_long))
    seconds = time.perf_counter() - start
    if status not in (0, 1):
        raise ValueError(f"C reference: {STATUS.get(status, status)}")
    written = int(counters[1])
    return dict(out=out[:written], flags=out_flags[:written], rows=written,
                steps=int(counters[2]), seconds=seconds, state=state,
                stop_contacts=int(counters[0]), status=STATUS[status])


def run_reference(excitation=None, isolator=None, controller=None, **kwargs):
    """Prepare the case as ``qzs.simulate`` would (same arguments) and integrate it in C."""
    return run_prepared(prepare(excitation, isolator, controller, **kwargs))


if __name__ == "__main__":  # quick look: the paper's chirp, 20 s
    import qzs

    r = run_reference(qzs.Chirp(amplitude=0.01, f0=0.0, f1=20.0, duration=2000.0),
                      duration=20.0, dt=1e-4, sample_rate=1000.0)
    print(f"{build().path}: {r['steps']:,} steps in {r['seconds']:.3f} s "
          f"({r['steps'] / r['seconds']:,.0f} steps/s), {r['rows']} rows, {r['status']}")
