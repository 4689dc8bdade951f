"""Arithmetic of the kernels: an own ``exp`` and ``tanh``, explicit fused multiply-adds.

No fast-math at all (:data:`JIT`): without implicit contraction or reassociation a
lane of a vectorised loop computes the very same bits as scalar code, so a case
gives the same numbers alone and in a batch (docs/model.md §9). The fused
multiply-adds worth having are explicit (:func:`fma`), and ``exp`` is written in
plain arithmetic so that loops over cases vectorise; the divergence check needs
``isfinite`` too, which fast-math would drop.
"""
import math
import os

from typing import Any

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.extending import intrinsic, overload

__all__ = ["JIT", "fma", "exp", "tanh"]

#: Options of every kernel: cached on disk, numpy's error model, no fast-math.
JIT: dict[str, Any] = dict(cache=True, error_model="numpy")
_JIT = JIT


def _pow2(k):
    """``2.0**k`` for an integer ``-1022 <= k <= 1023`` (Python fallback of the intrinsic)."""
    return math.ldexp(1.0, int(k))


@intrinsic
def _pow2_bits(typingctx, k):
    """``2.0**k`` built from its exponent bits: one shift, vectorisable."""
    def codegen(context, builder, signature, args):
        i64 = ir.IntType(64)
        bits = builder.shl(builder.add(args[0], ir.Constant(i64, 1023)), ir.Constant(i64, 52))
        return builder.bitcast(bits, ir.DoubleType())
    return types.float64(types.int64), codegen


@overload(_pow2, jit_options=dict(cache=True))  # type: ignore[typeddict-unknown-key]
def _pow2_jit(k):
    return lambda k: _pow2_bits(k)


def fma(a, b, c):
    """``a * b + c`` rounded once (Python fallback of the intrinsic: rounded twice).

    Parameters
    ----------
    a, b : float
        The factors.
    c : float
        The addend.

    Returns
    -------
    float
    """
    return a * b + c


@intrinsic
def _fma_instruction(typingctx, a, b, c):
    """Fused multiply-add: the same single rounding in scalar and vector code."""
    def codegen(context, builder, signature, args):
        double = ir.DoubleType()
        function = builder.module.declare_intrinsic(
            "llvm.fma", [double], ir.FunctionType(double, [double, double, double]))
        return builder.call(function, args)
    return types.float64(types.float64, types.float64, types.float64), codegen


@overload(fma, jit_options=dict(cache=True))  # type: ignore[typeddict-unknown-key]
def _fma_jit(a, b, c):
    return lambda a, b, c: _fma_instruction(float(a), float(b), float(c))


@njit(**_JIT, inline="always")
def exp(x):
    """exp in plain arithmetic (no libm call), so that loops over cases vectorise.

    Cody-Waite reduction ``x = k*ln2 + r``, ``|r| <= ln2/2``, a degree-13 Taylor
    polynomial (truncation below 1e-17, Estrin's scheme) and ``2**k`` from the exponent bits;
    within 2 ulp of libm. ``x`` is clamped to [-700, 700]: ``exp(-700)`` ~ 1e-304
    stands in for 0. The same operations in every lane and in scalar code give
    the same bits, which keeps batched runs identical to single runs.

    Parameters
    ----------
    x : float
        The exponent.

    Returns
    -------
    float
    """
    x = min(max(x, -700.0), 700.0)
    k = np.floor(fma(x, 1.4426950408889634, 0.5))
    r = fma(k, -1.90821492927058770002e-10, fma(k, -6.93147180369123816490e-01, x))
    # Estrin's scheme: the same polynomial as Horner's, in a quarter of the latency
    r2 = r * r
    r4 = r2 * r2
    low = fma(fma(fma(r, 1.0 / 5040.0, 1.0 / 720.0), r2, fma(r, 1.0 / 120.0, 1.0 / 24.0)), r4,
              fma(fma(r, 1.0 / 6.0, 0.5), r2, 1.0 + r))
    high = fma(fma(r, 1.0 / 6227020800.0, 1.0 / 479001600.0), r4,
               fma(fma(r, 1.0 / 39916800.0, 1.0 / 3628800.0), r2,
                   fma(r, 1.0 / 362880.0, 1.0 / 40320.0)))
    p = fma(high, r4 * r4, low)
    return p * _pow2(np.int64(k))


@njit(**_JIT, inline="always")
def tanh(u):
    """tanh from one :func:`exp` (exactly +-1 beyond ``|u| = 20``; error below 3e-16).

    Parameters
    ----------
    u : float
        The argument.

    Returns
    -------
    float
    """
    a = min(abs(u), 20.0)
    r = 1.0 - 2.0 / (exp(2.0 * a) + 1.0)
    return r if u >= 0.0 else -r




# ---------------------------------------------------------------- stale kernel caches
#: The modules whose compiled kernels numba caches (below ``engine/``), and the source files
#: they are built from (the packed-layout constants of the excitation and of the six-axis
#: kernels are compiled in as globals).
_KERNEL_MODULES = ("arithmetic", "laws", "stickslip", "base_motion", "kernels", "lanes",
                   "hexapod/dynamics", "hexapod/stepping")
_KERNEL_SOURCES = (*(f"engine/{name}.py" for name in _KERNEL_MODULES), "engine/hexapod/layout.py",
                   "model/excitation.py", "model/sensors.py")
#: The fingerprint of those sources, kept beside numba's cache files.
_STAMP = "qzs-kernel-sources.sha256"


@njit(**JIT)
def _cache_probe():  # pragma: no cover - only its cache location is used
    return 0


def _cache_folder(source):
    """The folder numba caches the kernels of the module file ``source`` in.

    Found as numba finds :func:`_cache_probe`'s (the same locator: ``__pycache__`` beside the
    source, or below ``NUMBA_CACHE_DIR`` or the user's cache), for a subpackage's modules.
    """
    from pathlib import Path

    locator = _cache_probe._cache._impl.locator
    return Path(type(locator)(_cache_probe.py_func, str(source)).get_cache_path())


def _drop_stale_kernel_caches():
    """Delete qzs's cached kernels when any kernel source changed since they were compiled.

    numba checks a cached function against its own file only: after an edit of
    ``base_motion.py`` a cached ``kernels.py`` kernel that inlined the old code would be
    loaded unchanged (editable installs; a fresh install rewrites every file). The
    sources' fingerprint is kept beside the cache; when it differs, the cached kernels
    of :data:`_KERNEL_MODULES` are removed before any is loaded, and numba compiles them
    again. Best effort: a cache folder that cannot be read or written is left alone.
    """
    import hashlib
    from pathlib import Path

    try:
        folder = Path(_cache_probe._cache._cache_path)
        root = Path(__file__).resolve().parents[1]
        digest = hashlib.sha256()
        for name in _KERNEL_SOURCES:
            digest.update((root / name).read_bytes())
        stamp = folder / _STAMP
        fingerprint = digest.hexdigest()
        if stamp.exists() and stamp.read_text(encoding="ascii").strip() == fingerprint:
            return False
        for name in _KERNEL_MODULES:
            package, _, module = name.rpartition("/")
            where = _cache_folder(root / "engine" / f"{name}.py") if package else folder
            for path in where.glob(f"{module}.*.nb[ic]"):
                path.unlink(missing_ok=True)
        folder.mkdir(parents=True, exist_ok=True)
        partial = folder / f".{_STAMP}.{os.getpid()}"
        partial.write_text(fingerprint + "\n", encoding="ascii")
        os.replace(partial, stamp)
        return True
    except (OSError, AttributeError, TypeError):  # no cache folder, read-only, other numba
        return False


_drop_stale_kernel_caches()
