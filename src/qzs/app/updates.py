"""One computation at a time per page, the newest request only (docs/app.md).

A slider released three times in a second asks for three computations; the page needs
only the last. :class:`LatestOnly` runs one at a time in an executor (a thread: the
kernels release the GIL, so the server's event loop stays free), keeps only the newest
request waiting, and drops the result of any computation a newer request superseded
(a generation counter). It knows nothing of Panel: the page passes ``schedule``, which
hands a callable to the server's event loop (and there to
``document.add_next_tick_callback``).
"""
import threading
from functools import partial

__all__ = ["LatestOnly"]


class LatestOnly:
    """Run ``compute(request)`` in ``executor``, one at a time, newest request only.

    Parameters
    ----------
    compute : callable
        ``compute(request) -> result``; may raise.
    deliver : callable
        ``deliver(request, outcome)`` with the result or the exception raised; called
        through ``schedule`` for the newest request only.
    executor : concurrent.futures.Executor
        Where ``compute`` runs.
    schedule : callable
        ``schedule(callback)``: runs ``callback()`` on the thread that owns the page
        (the event loop); ``lambda f: f()`` runs it at once (tests).
    busy : callable, optional
        ``busy(flag)``: True when a computation starts while none ran, False when the
        last one has finished.

    Attributes
    ----------
    generation : int
        Requests submitted so far [-]; a result is delivered only if it is the newest's.
    dropped : int
        Results dropped because a newer request superseded them [-].
    delivered : int
        Results delivered [-].
    """

    def __init__(self, compute, deliver, *, executor, schedule, busy=None):
        self._compute, self._deliver = compute, deliver
        self._executor, self._schedule = executor, schedule
        self._busy = busy or (lambda flag: None)
        self._lock = threading.Lock()
        self._running = False
        self._pending = None
        self.generation = 0
        self.dropped = 0
        self.delivered = 0

    @property
    def running(self):
        """True while a computation runs or waits [-]."""
        return self._running

    def submit(self, request):
        """Ask for ``request``; returns its generation [-].

        If a computation runs, ``request`` waits (replacing any request already
        waiting, which is never computed) and starts when the running one ends.

        Parameters
        ----------
        request : object
            What ``compute`` takes.

        Returns
        -------
        int
        """
        with self._lock:
            self.generation += 1
            generation = self.generation
            if self._running:
                self._pending = (generation, request)
                return generation
            self._running = True
        self._busy(True)
        self._start(generation, request)
        return generation

    def cancel(self):
        """Drop the computation under way and any waiting one (their results are not
        delivered); the page calls it when its values become invalid."""
        with self._lock:
            self.generation += 1
            self._pending = None

    def _start(self, generation, request):
        future = self._executor.submit(self._compute, request)
        future.add_done_callback(
            lambda done: self._schedule(partial(self._finished, generation, request, done)))

    def _finished(self, generation, request, future):
        error = future.exception()
        outcome = error if error is not None else future.result()
        with self._lock:
            waiting, self._pending = self._pending, None
            if waiting is None:
                self._running = False
            current = generation == self.generation
        if current:
            self.delivered += 1
            self._deliver(request, outcome)
        else:
            self.dropped += 1
        if waiting is not None:
            self._start(*waiting)
        else:
            self._busy(False)
