"""The forked helper: its job runs in another process and its result or error comes back;
it prepares first, ignores Ctrl-C, dies with its parent and is ended by ``close``."""
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

import qzs
from qzs.errors import HelperProcessError, ParameterError
from qzs.workflows import forked
from qzs.workflows.forked import Forked, Here, start

needs_fork = pytest.mark.skipif(not forked.available(), reason="needs fork and two cores")


def _gone(pid, timeout=10.0):
    """Whether process ``pid`` no longer exists (reaped) within ``timeout`` [s]."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return True
        time.sleep(0.02)
    return False


def where_and_what(item):
    return os.getpid(), item * 2


def fail_with_data(item):
    raise ParameterError(f"`item` must be positive, got {item}.", options=("item",))


class Unpicklable(Exception):
    def __reduce__(self):
        raise TypeError("no pickling")


def fail_unpicklably(item):
    raise Unpicklable("a lock inside")


@needs_fork
def test_the_job_runs_in_the_helper_and_its_result_comes_back():
    with Forked(where_and_what) as helper:
        helper.send(21)
        pid, value = helper.result()
    assert value == 42 and pid == helper.pid != os.getpid()
    assert not helper.is_alive() and _gone(pid)


@needs_fork
def test_the_jobs_error_is_raised_here_with_its_data():
    with Forked(fail_with_data) as helper:
        helper.send(-3)
        with pytest.raises(ParameterError, match="got -3") as error:
            helper.result()
    assert error.value.options == ("item",)
    with Forked(fail_unpicklably) as helper:  # only its text can come back
        helper.send(0)
        with pytest.raises(RuntimeError, match="Unpicklable: a lock inside"):
            helper.result()


@needs_fork
def test_a_killed_helper_or_one_told_nothing_is_an_error_naming_it():
    helper = Forked(where_and_what, name="qzs-test")
    try:
        os.kill(helper.pid, signal.SIGKILL)
        helper.send(1)
        with pytest.raises(HelperProcessError) as error:
            helper.result()
    finally:
        helper.close()
    assert (error.value.name, error.value.exitcode) == ("qzs-test", -signal.SIGKILL)
    with Forked(where_and_what) as helper, pytest.raises(HelperProcessError):
        helper.result()  # nothing sent


_PREPARED = {}


def prepare_here():
    _PREPARED["pid"] = os.getpid()
    thread = threading.get_native_id()
    _PREPARED["priority"] = os.getpriority(os.PRIO_PROCESS, thread)


def what_was_prepared(item):
    main = os.getpriority(os.PRIO_PROCESS, threading.get_native_id())
    return dict(_PREPARED), main


@needs_fork
@pytest.mark.parametrize("nice", [None, 5])
def test_preparing_happens_in_the_helper_before_the_job(nice):
    """Preparation runs in the helper (not here), before the job; in a thread at ``nice``
    more than the helper's priority when asked."""
    with Forked(what_was_prepared, prepare=prepare_here, nice=nice) as helper:
        time.sleep(0.3)  # the job is not there yet: preparation runs
        helper.send(None)
        prepared, main = helper.result()
    assert prepared["pid"] == helper.pid and "pid" not in _PREPARED
    assert prepared["priority"] - main == (0 if nice is None else min(nice, 19 - main))


def failing_preparation():
    raise ImportError("no module named 'matplotlib'")


@needs_fork
@pytest.mark.parametrize("nice", [None, 5])
def test_a_failed_preparation_is_the_jobs_error(nice):
    with Forked(where_and_what, prepare=failing_preparation, nice=nice) as helper:
        time.sleep(0.2)
        helper.send(1)
        with pytest.raises(ImportError, match="matplotlib"):
            helper.result()


@needs_fork
def test_the_helper_ignores_ctrl_c_and_still_answers():
    with Forked(where_and_what) as helper:
        time.sleep(0.2)
        os.kill(helper.pid, signal.SIGINT)
        time.sleep(0.2)
        assert helper.is_alive()
        helper.send(2)
        assert helper.result()[1] == 4


def write_after(path):
    time.sleep(0.5)
    Path(path).write_text("done")
    return path


@needs_fork
def test_close_kills_a_job_under_way_or_gives_it_grace(tmp_path):
    """An early close: grace 0 kills the job at once (the file never comes); grace None
    lets it end (the file is there); the helper is waited for either way."""
    helper = Forked(write_after, grace=0.0)
    helper.send(tmp_path / "killed")
    time.sleep(0.1)
    helper.close()
    assert not helper.is_alive() and _gone(helper.pid)
    time.sleep(0.8)
    assert not (tmp_path / "killed").exists()
    helper = Forked(write_after, grace=None)
    helper.send(tmp_path / "graced")
    time.sleep(0.1)
    helper.close()
    assert (tmp_path / "graced").read_text() == "done" and _gone(helper.pid)
    helper.close()  # idempotent


@needs_fork
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="PR_SET_PDEATHSIG")
def test_the_helper_dies_with_its_parent():
    """A parent killed outright (no ``close``): the kernel kills its helper."""
    env = dict(os.environ, PYTHONPATH=str(Path(qzs.__file__).parents[1]))
    script = ("import os, signal, sys, time\n"
              "from qzs.workflows.forked import Forked\n"
              "helper = Forked(len)\n"
              "print(helper.pid, flush=True)\n"
              "time.sleep(0.3)\n"
              "os.kill(os.getpid(), signal.SIGKILL)\n")
    proc = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == -signal.SIGKILL
    pid = int(proc.stdout.split()[0])
    assert _gone(pid)  # reaped by init once the kernel killed it


def test_here_runs_the_job_in_this_process_at_send():
    here = Here(where_and_what, prepare=failing_preparation)
    with pytest.raises(HelperProcessError):
        here.result()  # nothing sent
    here.send(5)
    assert here.result() == (os.getpid(), 10)
    failing = Here(fail_with_data)
    failing.send(-1)
    with pytest.raises(ParameterError, match="got -1"):
        failing.result()
    assert here.pid is None and not here.is_alive()


def test_start_forks_only_where_a_helper_can_help(monkeypatch):
    with start(where_and_what) as helper:
        assert isinstance(helper, Forked) == forked.available()
        helper.send(1)
        assert helper.result()[1] == 2
    monkeypatch.setattr(forked, "available", lambda: False)
    with start(where_and_what) as helper:
        assert isinstance(helper, Here)
