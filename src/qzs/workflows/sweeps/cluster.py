"""The Dask client a sweep or a design search runs on: given, by address, or a local cluster.

:func:`dask_client` connects (failing at once where nothing answers, and saying on
stderr what it waits for) or starts a local cluster, and closes what it opened.
"""
import contextlib

from qzs._optional import require
from qzs.engine.progress import install_warning_lines
from qzs.errors import SchedulerError

__all__ = ["dask_client"]


def _client(scheduler, workers):
    """A Dask client (and whether to close it): given, by address, or on a new LocalCluster."""
    distributed = require("distributed", "running a sweep on a Dask cluster")
    Client, LocalCluster = distributed.Client, distributed.LocalCluster

    if isinstance(scheduler, Client):
        return scheduler, None
    if scheduler is not None:
        return _connect(Client, scheduler), None
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, dashboard_address=None,
                           processes=True)
    client = Client(cluster)
    # the workers write on the user's console: their warnings one line each, as here
    client.run(install_warning_lines)
    return client, cluster


@contextlib.contextmanager
def dask_client(scheduler=None, workers=None):
    """The Dask client a run uses, or None to run locally; what it starts, it closes.

    Parameters
    ----------
    scheduler : str or distributed.Client, optional
        A scheduler's address (connected to, and the connection closed on exit) or a
        client (used as it is, left open).
    workers : int, optional
        Start a local cluster of this many single-threaded worker processes (closed on
        exit).

    Yields
    ------
    distributed.Client or None
        None when neither is given.

    Raises
    ------
    SchedulerError
        Nothing answers at ``scheduler`` (at once, before any work).
    """
    if scheduler is None and workers is None:
        yield None
        return
    client, cluster = _client(scheduler, workers)
    try:
        yield client
    finally:
        if not _is_client(scheduler):
            client.close()
        if cluster is not None:
            cluster.close()


def _connect(client_class, address):
    """A client of the scheduler at ``address``, saying on stderr what it waits for."""
    import sys

    from dask import config

    _probe(address)
    timeout = config.get("distributed.comm.timeouts.connect")
    print(f"qzs: connecting to the Dask scheduler at {address} (giving up after {timeout}) ...",
          file=sys.stderr, flush=True)
    try:
        return client_class(address, timeout=timeout)
    except (OSError, TimeoutError, ValueError) as error:
        raise SchedulerError(address, str(error) or type(error).__name__) from None


def _probe(address):
    """Fail at once where nothing can answer: an unknown host, or a refused connection (a
    slow or filtered one is left to the client's own timeout)."""
    import socket

    from distributed.comm import get_address_host_port

    try:
        host, port = get_address_host_port(address)
    except (ValueError, TypeError):  # not a TCP address the probe understands: let Dask try
        return
    try:
        socket.create_connection((host, port), timeout=1.0).close()
    except socket.gaierror as error:
        raise SchedulerError(address, f"the host {host!r} is unknown ({error.strerror})") \
            from None
    except ConnectionRefusedError:
        raise SchedulerError(address, f"nothing listens on port {port} of {host!r} (the "
                             "connection was refused)") from None
    except OSError:
        pass


def _is_client(obj):
    try:
        from distributed import Client
    except ImportError:  # without Dask nothing is a client
        return False
    return isinstance(obj, Client)

