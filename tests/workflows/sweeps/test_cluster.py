"""The Dask client of a sweep (qzs.workflows.sweeps.cluster): a scheduler that does not
answer is named at once, with what the connection waited for; a client given is left open,
one it opened is closed."""
import pytest


def test_connecting_to_a_scheduler_says_what_it_waits_for(monkeypatch, capsys):
    """A scheduler that does not answer at once (a filtered port, a slow network): stderr
    says where it connects and how long it waits, before it waits."""
    pytest.importorskip("distributed")
    from qzs.errors import SchedulerError
    from qzs.workflows.sweeps import cluster

    class Silent:  # the client of a scheduler that never answers
        def __init__(self, address, timeout):
            assert "connecting to the Dask scheduler at tcp://10.1.2.3:8786" in \
                capsys.readouterr().err  # said before the wait
            raise OSError(f"Timed out trying to connect to {address} after {timeout}")

    monkeypatch.setattr(cluster, "_probe", lambda address: None)
    with pytest.raises(SchedulerError, match=r"'tcp://10.1.2.3:8786': Timed out"):
        cluster._connect(Silent, "tcp://10.1.2.3:8786")


def test_a_client_given_is_left_open_and_one_started_is_closed():
    distributed = pytest.importorskip("distributed")
    from qzs.workflows.sweeps.cluster import dask_client

    with dask_client() as nothing:  # neither a scheduler nor workers: run locally
        assert nothing is None
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            with dask_client(client) as used:
                assert used is client
            assert client.status == "running"  # the caller's: not closed
    with dask_client(workers=1) as started:
        assert started.status == "running"
        assert len(started.nthreads()) == 1
    assert started.status == "closed"


def test_nothing_listening_fails_at_once():
    """A refused connection is a SchedulerError naming the port, without waiting for the
    client's own timeout."""
    pytest.importorskip("distributed")
    import socket
    import time

    from qzs.errors import SchedulerError
    from qzs.workflows.sweeps.cluster import dask_client

    with socket.socket() as free:  # a port nothing listens on
        free.bind(("127.0.0.1", 0))
        port = free.getsockname()[1]
    began = time.perf_counter()
    with pytest.raises(SchedulerError, match=f"nothing listens on port {port}"):
        with dask_client(f"tcp://127.0.0.1:{port}"):
            pass
    assert time.perf_counter() - began < 5.0


def test_the_workers_of_a_local_cluster_show_warnings_as_one_line():
    """A warning in a worker process (its stderr is the user's console): one line, no file."""
    import io
    import warnings

    pytest.importorskip("distributed")
    from qzs.engine.progress import show_warning
    from qzs.workflows.sweeps.cluster import dask_client

    def display():
        stream = io.StringIO()
        warnings.showwarning("a band with no trusted bin", RuntimeWarning, "x.py", 394,
                             file=stream)
        return warnings.showwarning is show_warning, stream.getvalue()

    with dask_client(workers=1) as client:
        (shown,) = client.run(display).values()
    assert shown == (True, "qzs: warning: a band with no trusted bin\n")
