"""The Bokeh server behind ``qzs app``: warm kernels, a safe address, one page per session.

The server is one persistent Python process: the numba kernels are compiled (or loaded
from their cache) and run once before it listens (:func:`warm_up`), so the first slider a
person moves answers as fast as the later ones. It binds to 127.0.0.1 unless told
otherwise, warns on stderr when it is told otherwise, accepts the page's websocket only
from the address it serves, and reads and writes no file: exports are browser downloads
(docs/app.md).
"""
import ipaddress
import signal
import socket
import sys
import threading
import time

from qzs._optional import require
from qzs.errors import ParameterError

__all__ = ["serve", "warm_up", "choose_port", "is_loopback", "DEFAULT_PORT", "DEFAULT_HOST"]

#: Port tried first when none is given (Bokeh's own default) [-].
DEFAULT_PORT = 5006
#: Address bound when none is given: this machine only.
DEFAULT_HOST = "127.0.0.1"
_WILDCARDS = ("0.0.0.0", "::", "")


def is_loopback(host):
    """True if ``host`` names this machine only (127.0.0.0/8, ::1, ``localhost``).

    Parameters
    ----------
    host : str
        An address or host name.

    Returns
    -------
    bool
    """
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def choose_port(host=DEFAULT_HOST, preferred=DEFAULT_PORT):
    """``preferred`` if it is free on ``host``, else a free port the system picks.

    Parameters
    ----------
    host : str
        The address the server will bind.
    preferred : int
        The port tried first.

    Returns
    -------
    int
    """
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    for port in (preferred, 0):
        with socket.socket(family, socket.SOCK_STREAM) as probe:
            try:
                probe.bind((host, port))
            except OSError:
                continue
            return probe.getsockname()[1]
    raise ParameterError(f"no free port on {host!r}; pass --port.")  # pragma: no cover


def warm_up(stream=None):
    """Compile (or load) the kernels and run each computation of the page once.

    Parameters
    ----------
    stream : file, optional
        Where to say what it does (default stderr).

    Returns
    -------
    float
        Wall time of the warm-up [s].
    """
    from qzs.app.compute import compute_page, page_request
    from qzs.app.figure import figure_png

    stream = stream or sys.stderr
    start = time.perf_counter()
    print("qzs app: warming the kernels (the first time they compile, about a minute; "
          "later a few seconds) ...", file=stream, flush=True)
    data = compute_page(page_request())
    compute_page(page_request({"excitation.kind": "stepped", "frequency_count": 2}))
    figure_png(data)
    elapsed = time.perf_counter() - start
    print(f"qzs app: warm in {elapsed:.1f} s", file=stream, flush=True)
    return elapsed


def serve(*, port=None, host=DEFAULT_HOST, open_browser=True, warm=True):
    """Serve the tuning page until Ctrl-C (docs/app.md).

    Parameters
    ----------
    port : int, optional
        Port to listen on; default :data:`DEFAULT_PORT` if it is free, else a free one.
    host : str
        Address to bind; default 127.0.0.1 (this machine only). Another address is
        served with a warning on stderr: the page has no login, and anyone who reaches
        it can run simulations here.
    open_browser : bool
        Open the page in the default browser once the server listens.
    warm : bool
        Run :func:`warm_up` before listening.

    Raises
    ------
    KeyboardInterrupt
        When Ctrl-C (SIGINT) has stopped the server; ``qzs app`` exits with 130.
    MissingDependencyError
        Panel is not installed (``pip install "qzs[app]"``).
    ParameterError
        A port outside 0-65535.
    """
    require("panel", "the tuning page (qzs app)")
    if port is not None and (isinstance(port, bool) or not isinstance(port, int)
                             or not 0 <= port <= 65535):
        raise ParameterError(f"`port` must be an integer in [0, 65535], got {port!r}.")
    if port is None or port == 0:
        port = choose_port(host, DEFAULT_PORT if port is None else 0)
    if is_loopback(host):
        origins = [f"{name}:{port}" for name in ("127.0.0.1", "localhost")]
    else:
        print(f"qzs app: warning: serving on {host!r}, not only on this machine: the page has "
              "no login, and anyone who can reach this address can run simulations here. "
              "Use the default --host 127.0.0.1 unless you mean it.", file=sys.stderr,
              flush=True)
        origins = ["*"] if host in _WILDCARDS else [f"{host}:{port}", f"localhost:{port}",
                                                     f"127.0.0.1:{port}"]
    if warm:
        warm_up()

    import panel as pn

    from qzs.app.page import build_page

    pn.extension(notifications=False)
    shown = f"[{host}]" if ":" in host else host
    print(f"qzs app: serving http://{shown}:{port}/ (Ctrl-C to stop)", file=sys.stderr,
          flush=True)
    previous = signal.getsignal(signal.SIGINT)
    try:
        pn.serve(build_page, port=port, address=host, websocket_origin=origins,
                 show=open_browser, title="qzs tuning page", verbose=False, start=True,
                 threaded=False, admin=False)
    finally:  # Panel stops the server on SIGINT with a handler of its own
        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGINT, previous)
    # the loop returns only when Panel's handler stopped it: Ctrl-C, as for every command
    raise KeyboardInterrupt
