"""The Bokeh server behind ``qzs app``: warm kernels, a safe address, one page per session.

The server is one persistent Python process: the numba kernels are compiled (or loaded
from their cache) and run once before it listens (:func:`warm_up`), so the first slider a
person moves answers as fast as the later ones. It binds to 127.0.0.1 unless told
otherwise, warns on stderr when it is told otherwise, accepts the page's websocket only
from the address it serves, and reads and writes no file: exports are browser downloads
(docs/app.md).
"""
import errno
import functools
import ipaddress
import signal
import socket
import sys
import threading
import time

from qzs._optional import require
from qzs._validation import integer
from qzs.errors import AddressError

__all__ = ["serve", "warm_up", "choose_port", "check_address", "is_loopback", "DEFAULT_PORT",
           "DEFAULT_HOST"]

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

    Raises
    ------
    AddressError
        ``host`` is not a name this machine resolves, or not one of its addresses.
    """
    for port in dict.fromkeys((preferred, 0)):
        try:
            return _bind(host, port)
        except AddressError as error:
            if error.argument == "--host" or port == 0:
                raise
    raise AssertionError("unreachable")  # pragma: no cover - port 0 either binds or raises


def check_address(host=DEFAULT_HOST, port=None):
    """The port the server will listen on, checked before anything else starts.

    Asked of the operating system by binding a probe socket (closed at once), so a busy
    port or an address that is not this machine's fails in milliseconds, with the option
    to change, instead of after the warm-up.

    Parameters
    ----------
    host : str
        The address to bind (an IP address or a host name).
    port : int, optional
        The port asked for; None: :data:`DEFAULT_PORT` if it is free, else a free one; 0:
        a free one.

    Returns
    -------
    int
        The port, free on ``host`` a moment ago.

    Raises
    ------
    AddressError
        ``--host``: not a name this machine resolves (``no-such-host.invalid``,
        ``999.1.1.1``), or not one of its addresses (``192.0.2.1``); ``--port``: in use,
        or below 1024 without the rights.
    """
    if port is None:
        try:
            return choose_port(host, DEFAULT_PORT)
        except AddressError as error:  # the port was not asked for: say none was
            raise AddressError(error.argument, host, None, error.reason) from None
    return _bind(host, port)


def _bind(host, port):
    """Bind a probe socket to ``(host, port)`` like the server does; returns the port."""
    try:
        family, kind, protocol, _, address = socket.getaddrinfo(
            host, port, type=socket.SOCK_STREAM)[0]
    except (socket.gaierror, UnicodeError) as error:
        raise AddressError("--host", host, port, f"is not an address, nor a host name this "
                           f"machine resolves ({getattr(error, 'strerror', None) or error}); "
                           "use 127.0.0.1 (this machine only), 0.0.0.0 (every network "
                           "interface) or one of this machine's addresses") from None
    with socket.socket(family, kind, protocol) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as the server does
        try:
            probe.bind(address)
        except OSError as error:
            if error.errno == errno.EADDRINUSE:
                raise AddressError("--port", host, port, f"is in use on {host} by another "
                                   "program; choose another port, or leave out --port for a "
                                   "free one") from None
            if error.errno == errno.EACCES:
                raise AddressError("--port", host, port, "needs administrator rights (a port "
                                   "below 1024); choose a port above 1023") from None
            raise AddressError("--host", host, port, f"is not an address of this machine "
                               f"({error.strerror}), so nothing can listen there; use "
                               "127.0.0.1 (this machine only), 0.0.0.0 (every network "
                               "interface) or one of this machine's addresses") from None
        return probe.getsockname()[1]


def warm_up(stream=None, spring=None):
    """Compile (or load) the kernels and run each computation of the page once: the chirp,
    the stepped sine and a run with the compensation slider's block, so that no setting of
    the page compiles a kernel afterwards.

    Parameters
    ----------
    stream : file, optional
        Where to say what it does (default stderr).
    spring : SpringLaw, optional
        The page's spring law (``qzs app --spring``): the runs take it, as the page's do.

    Returns
    -------
    float
        Wall time of the warm-up [s].
    """
    from qzs.app.compute import compute_page, page_request
    from qzs.app.figure import figure_png

    request = functools.partial(page_request, spring=spring)
    stream = stream or sys.stderr
    start = time.perf_counter()
    print("qzs app: warming the kernels (a few seconds; the first time they compile, and "
          "`qzs: compiling the kernels once` says so) ...", file=stream, flush=True)
    data = compute_page(request())
    compute_page(request({"excitation.kind": "stepped", "frequency_count": 2}))
    # the compensation slider adds a block: the blocks kernel, compiled here rather than in
    # the first session that moves it (the page has one computing thread for every session)
    compute_page(request({"compensation.fraction": 0.5, "excitation.duration": 10.0,
                          "excitation.f1": 2.0}))
    figure_png(data)
    elapsed = time.perf_counter() - start
    print(f"qzs app: warm in {elapsed:.1f} s", file=stream, flush=True)
    return elapsed


def serve(*, port=None, host=DEFAULT_HOST, open_browser=True, warm=True, spring=None):
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
    spring : SpringLaw, optional
        The page's spring law (``qzs app --spring FILE.toml``): its ``spring.*`` parameters
        get sliders instead of the MagSpring's ``spring_force`` and ``spring_shape``
        (:class:`qzs.app.page.TuningPage`); checked before the warm-up. None: the MagSpring.

    Raises
    ------
    KeyboardInterrupt
        When Ctrl-C (SIGINT) has stopped the server; ``qzs app`` exits with 130.
    MissingDependencyError
        Panel is not installed (``pip install "qzs[app]"``).
    ParameterError
        A port outside 0-65535; a ``spring`` that is no spring law.
    AddressError
        A busy port, or a host that is not this machine's (:func:`check_address`), before
        the warm-up.
    """
    if port is not None:
        port = integer("port", port, 0, maximum=65535, fix="e.g. 5006")
    port = check_address(host, port)  # a busy port, an address not this machine's: fail now
    require("panel", "the tuning page (qzs app)")
    if spring is not None:
        from qzs.app.compute import page_request

        page_request(spring=spring)  # the law checked once, before the warm-up
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
        if spring is None:
            warm_up()
        else:
            warm_up(spring=spring)

    import panel as pn

    from qzs.app.page import build_page

    def page():  # a function: Panel serves a functools.partial as its text
        return build_page(spring=spring)

    pn.extension(notifications=False)
    shown = f"[{host}]" if ":" in host else host
    print(f"qzs app: serving http://{shown}:{port}/ (Ctrl-C to stop)", file=sys.stderr,
          flush=True)
    previous = signal.getsignal(signal.SIGINT)
    try:
        pn.serve(page, port=port, address=host, websocket_origin=origins,
                 show=open_browser, title="qzs tuning page", verbose=False, start=True,
                 threaded=False, admin=False)
    finally:  # Panel stops the server on SIGINT with a handler of its own
        if threading.current_thread() is threading.main_thread():
            signal.signal(signal.SIGINT, previous)
    # the loop returns only when Panel's handler stopped it: Ctrl-C, as for every command
    raise KeyboardInterrupt
