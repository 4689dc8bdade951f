"""One job run by a helper process forked now, which prepares while this process works.

A command that ends with a slow step needing imports (matplotlib, xarray's writers) forks
a :class:`Forked` helper before its long work: the helper, a copy of this process with its
modules and data, prepares (imports, a warm-up draw) on the second core meanwhile, then
runs the one job this process :meth:`~Forked.send`\\ s it and sends back its result or its
error (:meth:`~Forked.result`). ``qzs simulate --out``'s figure
(:mod:`qzs.workflows.figure_process`) and ``qzs optimize``'s files and Pareto figure
(:func:`qzs.workflows.design_space.result.file_writer`) use it.

The helper ignores Ctrl-C (a terminal sends it to the whole process group: this process
decides), dies with this process on Linux (``PR_SET_PDEATHSIG``), and is killed and waited
for when this process ends it early (:meth:`~Forked.close`, after ``grace`` seconds for a
job under way, so that a job writing files ends them). Where ``fork`` is missing or one
core is usable, :func:`start` returns a :class:`Here`: the same calls, the job run in this
process.

>>> from qzs.workflows.forked import start
>>> with start(len) as helper:  # doctest: +SKIP
...     helper.send([1, 2, 3])
...     helper.result()
3
"""
from __future__ import annotations

import multiprocessing
import os
import pickle
import signal
import sys
import threading
from collections.abc import Callable
from typing import Any

from qzs.errors import HelperProcessError

__all__ = ["Forked", "Here", "start", "available"]

_PR_SET_PDEATHSIG = 1


def available() -> bool:
    """Whether a forked helper can help: ``fork`` exists and two cores are usable."""
    if "fork" not in multiprocessing.get_all_start_methods():
        return False
    try:
        cpus = len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        cpus = os.cpu_count() or 1
    return cpus >= 2


def _die_with_parent():
    """Linux: the kernel sends this process SIGKILL when its parent dies."""
    if not sys.platform.startswith("linux"):
        return
    import ctypes

    try:
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
    except (OSError, AttributeError):  # pragma: no cover - another libc
        pass


def _lower_priority(nice):
    """This thread at ``nice`` more than its priority (Linux priorities are per thread)."""
    try:
        thread = threading.get_native_id()
        os.setpriority(os.PRIO_PROCESS, thread, os.getpriority(os.PRIO_PROCESS, thread) + nice)
    except (AttributeError, OSError):  # no such call here: at the same priority
        pass


def _send_item(connection, item):
    """Send ``item``, its large buffers (contiguous numpy arrays) out of band: each written
    from its own memory (pickle protocol 5), not copied into one pickle first (a streamed
    run's preview is 40 MB)."""
    buffers = []
    head = pickle.dumps(item, protocol=5, buffer_callback=buffers.append)
    connection.send((head, len(buffers)))
    for buffer in buffers:
        connection.send_bytes(buffer.raw())


def _receive_item(connection):
    """What :func:`_send_item` sent."""
    head, count = connection.recv()
    return pickle.loads(head, buffers=[connection.recv_bytes() for _ in range(count)])


def _report(connection, error):
    """Send ``("error", error)``; as text in a RuntimeError if ``error`` does not pickle."""
    try:
        connection.send(("error", error))
    except OSError:  # this process's parent is gone
        pass
    except Exception:  # noqa: BLE001 - the error does not pickle: its text does
        try:
            connection.send(("error", RuntimeError(f"{type(error).__name__}: {error}")))
        except OSError:
            pass


def _helper(connection, job, prepare, nice):
    """The forked process: prepare, receive the job's input, run it, send the outcome."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)   # Ctrl-C is the parent's to handle
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # the parent's handler is not this one's
    _die_with_parent()
    preparing = None
    failed = []
    try:
        if prepare is not None and nice is not None:  # beside the wait, at a lower priority
            def prepare_beside():
                _lower_priority(nice)
                try:
                    prepare()
                except BaseException as error:  # noqa: BLE001 - the job's error
                    failed.append(error)

            preparing = threading.Thread(target=prepare_beside, name="qzs-prepare",
                                         daemon=True)
            preparing.start()
        elif prepare is not None and not connection.poll():  # the job is not here yet
            prepare()
        try:
            item = _receive_item(connection)
        except (EOFError, OSError):  # told nothing (the parent stopped): nothing to do
            return
        if preparing is not None:
            preparing.join()
            if failed:
                raise failed[0]
        value = job(item)
    except BaseException as error:  # noqa: BLE001 - reported to the parent
        _report(connection, error)
    else:
        try:
            connection.send(("ok", value))
        except OSError:
            pass
    finally:
        connection.close()


class Forked:
    """A helper process forked now that runs one job (see the module's docstring).

    Parameters
    ----------
    job : callable
        Called in the helper with what :meth:`send` sends; its return value (picklable)
        is what :meth:`result` returns.
    prepare : callable, optional
        Called in the helper first, while this process works (imports, a warm-up).
    nice : int, optional
        None: ``prepare`` runs before the job is received, and not at all if the job is
        already there. An int: ``prepare`` runs in a thread of the helper at ``nice`` more
        than its priority, while the helper waits, and always; the job waits for it.
    grace : float, optional
        On an early :meth:`close`, the time [s] a job under way is given to end before it
        is killed; None: as long as it takes.
    name : str
        The helper's process name.
    """

    def __init__(self, job: Callable[[Any], Any], *, prepare: Callable[[], Any] | None = None,
                 nice: int | None = None, grace: float | None = 0.0,
                 name: str = "qzs-helper"):
        context = multiprocessing.get_context("fork")
        self._connection, child = context.Pipe()
        for stream in (sys.stdout, sys.stderr):  # nothing buffered is written twice
            stream.flush()
        # not daemonic, so that its job may fork helpers of its own (a daemonic process may
        # have no children); :meth:`close` ends it
        self._process = context.Process(target=_helper, name=name,
                                        args=(child, job, prepare, nice))
        self._process.start()
        child.close()
        self._grace = grace
        self._sender: threading.Thread | None = None
        self._answered = False

    @property
    def pid(self) -> int | None:
        """The helper's process id."""
        return self._process.pid

    def is_alive(self) -> bool:
        """Whether the helper is running."""
        return self._process.is_alive()

    def send(self, item: Any) -> None:
        """Send the job's input; the helper runs the job. Returns at once.

        Parameters
        ----------
        item : object
            The job's argument (pickled through a pipe).
        """
        def sending():
            try:
                _send_item(self._connection, item)
            except OSError:  # the helper is gone: :meth:`result` says so
                pass

        # in a thread: the helper may still be preparing, and this process goes on
        self._sender = threading.Thread(target=sending, name="qzs-send", daemon=True)
        self._sender.start()

    def result(self) -> Any:
        """The job's return value; waits for it.

        Returns
        -------
        object
            What ``job`` returned.

        Raises
        ------
        HelperProcessError
            The helper ended without an answer (killed, or :meth:`send` not called).
        Exception
            What ``job`` (or ``prepare``) raised, raised again here.
        """
        try:
            if self._sender is None:
                raise EOFError
            self._sender.join()
            outcome, value = self._connection.recv()
        except (EOFError, OSError) as error:
            self._process.join(timeout=1.0)
            raise HelperProcessError(self._process.name, self._process.exitcode) from error
        self._answered = True
        if outcome == "error":
            raise value
        return value

    def close(self) -> None:
        """End the helper and wait for it; a job under way first gets ``grace`` seconds.
        Idempotent."""
        if self._sender is not None and not self._answered and self._process.is_alive():
            self._process.join(timeout=self._grace)
        if self._process.is_alive():
            self._process.kill()
        self._process.join()
        if self._sender is not None:  # its send fails once the helper is gone
            self._sender.join()
        self._connection.close()

    def __enter__(self) -> Forked:
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()


class Here:
    """:class:`Forked`'s calls where no helper forks: the job runs in this process, at
    :meth:`send`.

    Parameters
    ----------
    job : callable
        Called with what :meth:`send` sends.
    **_ignored
        :class:`Forked`'s other arguments (``prepare`` is not needed: nothing runs beside).
    """

    def __init__(self, job: Callable[[Any], Any], **_ignored: Any):
        self._job = job
        self._outcome: tuple[str, Any] | None = None

    pid = None

    def is_alive(self) -> bool:
        """False: no process."""
        return False

    def send(self, item: Any) -> None:
        """Run the job on ``item`` now; :meth:`result` returns or raises its outcome.

        Parameters
        ----------
        item : object
            The job's argument.
        """
        try:
            self._outcome = ("ok", self._job(item))
        except Exception as error:  # noqa: BLE001 - raised again by :meth:`result`
            self._outcome = ("error", error)

    def result(self) -> Any:
        """The job's return value, or its error raised again (see :meth:`Forked.result`)."""
        if self._outcome is None:
            raise HelperProcessError("here", None)
        outcome, value = self._outcome
        if outcome == "error":
            raise value
        return value

    def close(self) -> None:
        """Nothing to end."""

    def __enter__(self) -> Here:
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()


def start(job: Callable[[Any], Any], *, prepare: Callable[[], Any] | None = None,
          nice: int | None = None, grace: float | None = 0.0,
          name: str = "qzs-helper") -> Forked | Here:
    """A :class:`Forked` helper where :func:`available`, else a :class:`Here`.

    Parameters
    ----------
    job, prepare, nice, grace, name
        As :class:`Forked` takes them.

    Returns
    -------
    Forked or Here
    """
    if available():
        return Forked(job, prepare=prepare, nice=nice, grace=grace, name=name)
    return Here(job)
