"""One BLAS thread for the small dense linear algebra of harmonic balance."""
from contextlib import contextmanager

__all__ = []


@contextmanager
def _single_threaded_blas():
    """Run the enclosed linear algebra on one BLAS thread, then restore the count.

    Hill matrices are small (a few hundred rows): OpenBLAS's threads only cost there, and
    on a loaded machine they cost a lot (a 153 x 153 eigenproblem: 81 ms with numpy's
    default threads on two busy cores, 8.5 ms on one). numpy's bundled OpenBLAS is reached
    through its own ``set_num_threads`` symbol; elsewhere this does nothing.
    """
    setter, getter = _blas_thread_control()
    if setter is None:
        yield
        return
    previous = getter()
    setter(1)
    try:
        yield
    finally:
        setter(previous)


_BLAS_CONTROL: list[tuple] = []


def _blas_thread_control():
    """``(set_num_threads, get_num_threads)`` of numpy's OpenBLAS, or ``(None, None)``."""
    if not _BLAS_CONTROL:
        found = (None, None)
        try:
            import ctypes

            with open("/proc/self/maps", encoding="ascii", errors="replace") as maps:
                paths = sorted({line.split()[-1] for line in maps
                                if "numpy" in line and "openblas" in line.lower()})
            for path in paths:
                library = ctypes.CDLL(path)
                for prefix, suffix in (("scipy_openblas", "64_"), ("openblas", "64_"),
                                       ("openblas", "")):
                    setter = getattr(library, f"{prefix}_set_num_threads{suffix}", None)
                    getter = getattr(library, f"{prefix}_get_num_threads{suffix}", None)
                    if setter is not None and getter is not None:
                        setter.argtypes, getter.restype = [ctypes.c_int], ctypes.c_int
                        found = (setter, getter)
                        break
                if found[0] is not None:
                    break
        except (OSError, AttributeError, IndexError):
            found = (None, None)
        _BLAS_CONTROL.append(found)
    return _BLAS_CONTROL[0]
