"""Session-scoped simulation runs shared by the test modules, and the validation recorder.

Every run here is short (seconds of simulated time) so that the whole suite stays fast
once numba has compiled (and cached) the kernel.

A test that checks a closed form or a published result takes the ``validation`` fixture
and records what it measured; ``make docs`` runs those tests (``pytest -m validation``,
the marker is added to every test that uses the fixture) with ``QZS_VALIDATION_OUT`` set,
and the documentation's validation page (docs/validation.md) is built from the records.
"""
import json
import math
import os

import pytest
from helpers import PASSIVE, SHORT_CHIRP

from qzs import ControllerParameters, IsolatorParameters, Sine, simulate


@pytest.fixture(scope="session")
def default_chirp_run():
    """Table 1 defaults, default PI, 20 s of the paper's chirp, sampled at every step."""
    return simulate(SHORT_CHIRP, dt=1e-4, sample_rate=1e4)


@pytest.fixture(scope="session")
def passive_chirp_run():
    """The passive isolator (no PI) on the same chirp: it reaches the compliant stops."""
    return simulate(SHORT_CHIRP, controller=PASSIVE, dt=1e-4, sample_rate=1e4)


@pytest.fixture(scope="session")
def plastic_sine_run():
    """The passive isolator on a perfectly plastic stop, 3 Hz sine for 10 s (sinks to it)."""
    return simulate(Sine(amplitude=0.010, frequency=3.0), IsolatorParameters(stop_model="plastic"),
                    PASSIVE, duration=10.0, dt=1e-4, sample_rate=1e4)


@pytest.fixture(scope="session")
def sampled_chirp_run():
    """Default plant, PI plus active damping sampled at 1 kHz with zero-order hold."""
    controller = ControllerParameters(controller_rate=1000.0, damping_gain=20.0)
    return simulate(SHORT_CHIRP, controller=controller, dt=1e-4, sample_rate=1e4)


@pytest.fixture
def read_only_folder(tmp_path):
    """A folder nobody can write into, even root (a read-only mount), or skip."""
    from pathlib import Path

    from qzs.iotools.paths import _writable

    folder = tmp_path / "read-only"
    folder.mkdir()
    folder.chmod(0o555)
    if not _writable(folder):
        yield folder
    elif Path("/sys").is_dir() and not _writable(Path("/sys")):  # root ignores the mode bits
        yield Path("/sys")
    else:
        pytest.skip("no read-only folder available")
    folder.chmod(0o755)


# ---------------------------------------------------------------- validation records
#: Environment variable naming the JSON Lines file the records are appended to.
VALIDATION_OUT = "QZS_VALIDATION_OUT"


def pytest_configure(config):
    # the step cache (qzs.engine.step_cache) of the tests' own: a choice made by the code
    # under test, never one left on this machine by an earlier version or another checkout;
    # subprocesses of the tests inherit it
    import tempfile

    config._qzs_cache = os.environ["QZS_CACHE_DIR"] = tempfile.mkdtemp(prefix="qzs-test-cache-")

    config.addinivalue_line(
        "markers", "validation: checks a closed form or published result and records the "
                   "measured error for the documentation's validation page (added to every "
                   "test that uses the `validation` fixture)")


def pytest_unconfigure(config):
    import shutil

    folder = getattr(config, "_qzs_cache", None)
    if folder:
        shutil.rmtree(folder, ignore_errors=True)


@pytest.hookimpl(tryfirst=True)  # before `-m` deselects by marker
def pytest_collection_modifyitems(config, items):
    for item in items:
        if "validation" in getattr(item, "fixturenames", ()):
            item.add_marker(pytest.mark.validation)


@pytest.fixture
def validation(request):
    """Record a check against a closed form or a published result (docs/validation.md).

    Returns ``record(check, reference, error, tolerance, *, measure="relative error")``:

    check : str
        What is compared, e.g. "Den Hartog peak amplitude, beta = 0.6".
    reference : str
        The closed form or published result, with its source.
    error : float
        The measured error, in the units of ``measure``.
    tolerance : float
        The bound the test asserts for it (the test's own assertion stays; the record only
        reports).
    measure : str
        What ``error`` is: "relative error", "absolute error [m]", "|slope - 3|" ...

    With ``QZS_VALIDATION_OUT`` unset, ``record`` does nothing but return ``error``; set, it
    appends one JSON object per call to that file, with the test's id and its module's
    one-line docstring (the page's section).
    """
    path = os.environ.get(VALIDATION_OUT)

    def record(check, reference, error, tolerance, *, measure="relative error"):
        error, tolerance = float(error), float(tolerance)
        if path:
            doc = (request.module.__doc__ or request.module.__name__).strip()
            entry = {"check": check, "reference": reference,
                     "error": error if math.isfinite(error) else repr(error),
                     "tolerance": tolerance, "measure": measure,
                     "test": request.node.nodeid,
                     # the test module's path under tests/, dotted (importlib mode names
                     # it tests.engine.test_driver): the key of the page's SECTIONS
                     "module": request.module.__name__.removeprefix("tests."),
                     "section": " ".join(doc.split("\n\n")[0].split())}
            with open(path, "a", encoding="utf-8") as stream:
                stream.write(json.dumps(entry) + "\n")
        return error

    return record


@pytest.fixture(autouse=True)
def _close_figures():
    """Close every pyplot figure a test left open: matplotlib warns (an error here) once more
    than 20 are open, which made a later test fail by the order the tests happen to run in."""
    yield
    import sys

    pyplot = sys.modules.get("matplotlib.pyplot")
    if pyplot is not None:
        pyplot.close("all")


@pytest.fixture(autouse=True)
def _no_start_notice(monkeypatch):
    """Commands run in-process say nothing while they load (``qzs.cli.common.start_notice``):
    on a busy test machine a quick error could otherwise come after the notice, and tests
    read exact output. tests/cli/test_common.py tests the notice with its own delay."""
    from qzs.cli import common

    monkeypatch.setattr(common, "START_NOTICE_DELAY", 3600.0)
