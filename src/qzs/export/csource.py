"""qzs's C sources and the system C compiler: find, compile, load.

The C model (``csrc/``: the plant, the sampled controller and their closed loop) ships with
the package; it is compiled at run time with the system compiler (``$CC``, else ``cc``, else
``gcc``) into a temporary folder and loaded with :mod:`ctypes`. A missing compiler, or one
that fails, is a :class:`~qzs.errors.CompilerError` naming it.

The flags keep the arithmetic the kernels': no fast-math and no implicit contraction into
fused multiply-adds (``-ffp-contract=off``; the fused ones are explicit ``fma()`` calls, as
in :mod:`qzs.engine.arithmetic`), so the C model and :func:`qzs.simulate` compute the same
bits (docs/fmu.md).
"""
import ctypes
import os
import shutil
import subprocess
import tempfile
from importlib import resources
from pathlib import Path

from qzs.errors import CompilerError

__all__ = ["SOURCES", "CFLAGS", "NATIVE_CFLAGS", "source_folder", "source_text",
           "find_compiler", "compile_shared", "load_model"]

#: The C model's translation units, in ``csrc/``: controller, spring laws, plant, closed loop.
SOURCES = ("qzs_controller.c", "qzs_spring.c", "qzs_plant.c", "qzs_model.c")
#: Portable flags (an FMU's binary, the tests): optimised, IEEE arithmetic as the kernels'.
CFLAGS = ("-O2", "-std=c99", "-ffp-contract=off", "-fno-math-errno", "-fPIC")
#: The benchmarks' flags: as numba compiles, for this CPU (``fma()`` becomes one instruction).
NATIVE_CFLAGS = ("-O3", "-march=native", "-std=c99", "-ffp-contract=off", "-fno-math-errno",
                 "-fPIC")
#: How long a compilation may take [s] before it is stopped.
COMPILE_TIMEOUT = 300.0

_LOADED: dict = {}


def source_folder():
    """The folder of the shipped C sources (``qzs/export/csrc``).

    Returns
    -------
    pathlib.Path
    """
    return Path(str(resources.files("qzs.export") / "csrc"))


def source_text(name):
    """The text of one shipped C source or header.

    Parameters
    ----------
    name : str
        File name in ``csrc/`` (e.g. ``"qzs_controller.h"``).

    Returns
    -------
    str
    """
    return (source_folder() / name).read_text(encoding="utf-8")


def find_compiler():
    """The system C compiler: ``$CC`` if set, else ``cc``, else ``gcc``.

    Returns
    -------
    str
        Its path.

    Raises
    ------
    CompilerError
        None found (naming the one asked for).
    """
    wanted = os.environ.get("CC")
    for name in ([wanted] if wanted else ["cc", "gcc"]):
        found = shutil.which(name)
        if found:
            return found
    raise CompilerError(wanted or "cc", "was not found on PATH")


def compile_shared(sources, target, *, flags=CFLAGS, include=(), compiler=None):
    """Compile C sources into a shared library at ``target``.

    Parameters
    ----------
    sources : sequence of path-like
        The ``.c`` files.
    target : path-like
        The library to write (``.so``, ``.dylib`` or ``.dll``).
    flags : sequence of str
        Compiler flags (:data:`CFLAGS`).
    include : sequence of path-like
        Extra include folders.
    compiler : str, optional
        Default :func:`find_compiler`.

    Returns
    -------
    pathlib.Path
        ``target``.

    Raises
    ------
    CompilerError
        No compiler, or it failed (its messages in ``reason``).
    """
    compiler = compiler or find_compiler()
    command = [compiler, *flags, "-shared", *(f"-I{folder}" for folder in include),
               "-o", str(target), *map(str, sources), "-lm"]
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=COMPILE_TIMEOUT)
    except (OSError, subprocess.TimeoutExpired) as error:
        raise CompilerError(compiler, f"could not be run ({error})") from None
    if done.returncode != 0:
        raise CompilerError(compiler, "failed to compile qzs's C sources:\n"
                            + (done.stderr or done.stdout).strip(),
                            "report it with the messages above, or try another compiler "
                            "(the CC environment variable)")
    return Path(target)


def _declare(library):
    """The argument types of the C model's entry points."""
    double_p = ctypes.POINTER(ctypes.c_double)
    long_p = ctypes.POINTER(ctypes.c_int64)
    byte_p = ctypes.POINTER(ctypes.c_ubyte)
    run = library.qzs_model_run
    run.argtypes = [ctypes.c_int, ctypes.c_int64, ctypes.c_int64, double_p, long_p, double_p,
                    double_p, double_p, double_p, ctypes.c_int64, double_p, byte_p,
                    ctypes.c_int64, long_p]
    run.restype = ctypes.c_int
    evaluate = library.qzs_model_evaluate
    evaluate.argtypes = [ctypes.c_double, double_p, long_p, double_p, double_p, double_p,
                         double_p, ctypes.c_int64, double_p, byte_p]
    evaluate.restype = None
    return library


def load_model(native=False):
    """The compiled C model, built once per process (and per flag set).

    Parameters
    ----------
    native : bool
        Compile with :data:`NATIVE_CFLAGS` (for this CPU, as the benchmarks do) instead of
        the portable :data:`CFLAGS`.

    Returns
    -------
    ctypes.CDLL
        With ``qzs_model_run`` and ``qzs_model_evaluate`` declared (qzs_model.h); its
        ``path`` attribute is the library's file.

    Raises
    ------
    CompilerError
        No compiler, or it failed.
    """
    key = "native" if native else "portable"
    if key not in _LOADED:
        folder = tempfile.TemporaryDirectory(prefix="qzs-cmodel-")
        source = source_folder()
        target = Path(folder.name) / f"qzs_model{_suffix()}"
        compile_shared([source / name for name in SOURCES], target,
                       flags=NATIVE_CFLAGS if native else CFLAGS, include=[source])
        library = _declare(ctypes.CDLL(str(target)))
        library.path = target
        _LOADED[key] = (library, folder)  # the folder lives as long as the library
    return _LOADED[key][0]


def _suffix():
    """The shared-library suffix of this platform."""
    import sys

    if sys.platform == "win32":
        return ".dll"
    return ".dylib" if sys.platform == "darwin" else ".so"
