"""The Bokeh server behind ``qzs app`` (qzs.app.server): Panel imported lazily and named when
missing, loopback addresses, a warning before serving a public one, Ctrl-C ends it with 130."""
import subprocess
import sys

import pytest

from qzs.errors import MissingDependencyError


def test_without_panel_the_app_names_its_extra(monkeypatch):
    from qzs.app.server import serve

    monkeypatch.setitem(sys.modules, "panel", None)  # import panel -> ImportError
    with pytest.raises(MissingDependencyError) as error:
        serve(open_browser=False, warm=False)
    assert (error.value.package, error.value.extra) == ("panel", "app")


def test_qzs_and_the_page_logic_import_without_panel():
    code = ("import sys; import qzs, qzs.cli, qzs.app, qzs.app.compute, qzs.app.updates, "
            "qzs.app.server; assert 'panel' not in sys.modules and 'bokeh' not in sys.modules")
    subprocess.run([sys.executable, "-c", code], check=True)


def test_addresses_and_ports():
    from qzs.app.server import choose_port, is_loopback

    assert is_loopback("127.0.0.1") and is_loopback("127.8.0.1") and is_loopback("::1")
    assert is_loopback("localhost")
    assert not is_loopback("0.0.0.0") and not is_loopback("192.168.1.4")
    assert not is_loopback("example.org")
    port = choose_port("127.0.0.1", 0)
    assert 0 < port < 65536


def test_serve_warns_on_a_public_address(monkeypatch, capsys):
    """Another address than loopback is served with a warning, before anything else."""
    import qzs.app.server as server

    class Stop(Exception):
        pass

    def stop():
        raise Stop

    monkeypatch.setattr(server, "warm_up", stop)
    with pytest.raises(Stop):
        server.serve(host="0.0.0.0", port=0, open_browser=False)
    assert "warning: serving on '0.0.0.0'" in capsys.readouterr().err
    with pytest.raises(Stop):
        server.serve(host="127.0.0.1", port=0, open_browser=False)
    assert "warning" not in capsys.readouterr().err


def test_ctrl_c_stops_the_server_with_130():
    """`qzs app` serves until SIGINT, then exits as every command does on Ctrl-C."""
    import signal
    import time
    import urllib.request

    pytest.importorskip("panel", reason='the page needs Panel: pip install -e ".[app]"')
    from qzs.app.browser import free_port

    port = free_port()
    process = subprocess.Popen(
        [sys.executable, "-m", "qzs", "app", "--no-browser", "--port", str(port)],
        stderr=subprocess.PIPE, text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        deadline = time.monotonic() + 600
        while time.monotonic() < deadline and process.poll() is None:
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=5) as answer:
                    assert answer.status == 200
                    break
            except OSError:
                time.sleep(0.25)
        process.send_signal(signal.SIGINT)
        _, err = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 130, err
    assert f"serving http://127.0.0.1:{port}/" in err and "Traceback" not in err


@pytest.mark.parametrize("host, port, argument, words", [
    ("no-such-host.invalid", None, "--host", "is not an address, nor a host name"),
    ("no-such-host.invalid", 8123, "--host", "is not an address, nor a host name"),
    ("999.1.1.1", None, "--host", "is not an address, nor a host name"),
    ("192.0.2.1", None, "--host", "is not an address of this machine"),   # TEST-NET-1
    ("192.0.2.1", 8123, "--host", "is not an address of this machine"),
])
def test_an_address_that_is_not_this_machines_is_named_with_its_option(host, port, argument,
                                                                       words):
    """It used to say "no free port; pass --port", even when a port was given."""
    from qzs.app.server import check_address
    from qzs.errors import AddressError, ParameterError

    with pytest.raises(AddressError) as caught:
        check_address(host, port)
    error = caught.value
    assert isinstance(error, ParameterError)
    assert (error.argument, error.host, error.port) == (argument, host, port)
    assert str(error).startswith(f"--host {host!r} {words}") and "127.0.0.1" in str(error)


def test_a_busy_port_fails_before_the_warm_up(monkeypatch):
    """`qzs app --port <busy>` used to warm up, print "serving", then fail with 4 lines."""
    import socket

    import qzs.app.server as server
    from qzs.errors import AddressError

    monkeypatch.setattr(server, "warm_up", lambda: pytest.fail("warmed up before the check"))
    monkeypatch.setattr(server, "require", lambda *args: None)  # no Panel needed to fail
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        with pytest.raises(AddressError, match=f"--port {port} is in use on 127.0.0.1"):
            server.serve(port=port, open_browser=False)
        assert server.check_address("127.0.0.1", 0) != port  # 0: any free one
        assert server.choose_port("127.0.0.1", port) != port  # the default's fallback


@pytest.mark.parametrize("port", [True, 70000, -1, "8000", 5006.0])
def test_a_port_that_is_not_one_is_refused_with_the_range(port):
    from qzs.app import server
    from qzs.errors import ParameterError

    shown = "the boolean True" if port is True else repr(port)
    with pytest.raises(ParameterError) as info:
        server.serve(port=port, open_browser=False)
    assert str(info.value) == f"`port` must be an integer in [0, 65535], got {shown}; e.g. 5006."


def _compiled_signatures():
    """The number of compiled (or cache-loaded) signatures of every numba kernel of qzs."""
    from numba.core.registry import CPUDispatcher

    counts = {}
    for name, module in list(sys.modules.items()):
        if not name.startswith("qzs."):
            continue
        for attribute, value in vars(module).items():
            if isinstance(value, CPUDispatcher):
                counts[f"{name}.{attribute}"] = len(value.signatures)
    return counts


def test_the_warm_up_compiles_every_kernel_a_slider_can_reach():
    """After the warm-up no setting of the page compiles a kernel: a session that moves the
    compensation slider (a friction-compensation block: the blocks kernel) or asks for the
    stepped sine waits for a computation, never for numba (minutes on an empty cache, while
    the page's one computing thread serves nobody else)."""
    from qzs.app.compute import compute_page, page_request
    from qzs.app.server import warm_up

    warm_up(stream=open("/dev/null", "w"))
    before = _compiled_signatures()
    assert before, "no numba kernel found in qzs's modules"
    for values in ({"compensation.fraction": 0.5}, {"compensation.fraction": 1.5},
                   {"excitation.kind": "stepped", "frequency_count": 2,
                    "compensation.fraction": 0.8}, {"stiction_force": 4.0}):
        compute_page(page_request(values))
        after = _compiled_signatures()
        grown = {name: (before.get(name, 0), count) for name, count in after.items()
                 if count > before.get(name, 0)}
        assert not grown, f"{values} compiled after the warm-up: {grown}"


def test_a_spring_that_is_no_law_fails_before_the_warm_up(monkeypatch):
    import qzs.app.server as server
    from qzs.errors import ParameterError

    monkeypatch.setattr(server, "warm_up", lambda **kw: pytest.fail("warmed up before the check"))
    monkeypatch.setattr(server, "require", lambda *args: None)
    with pytest.raises(ParameterError, match="`spring` must be a spring law"):
        server.serve(port=0, open_browser=False, spring="oblique")


def test_the_warm_up_runs_the_pages_law(monkeypatch):
    """`qzs app --spring`: the warm-up runs the page's own runs, with its law (a law is data
    to the kernels the MagSpring's warm-up compiles, so this is what checks the law on the
    page's runs before the server listens)."""
    from qzs.app import compute
    from qzs.app.server import warm_up
    from qzs.model.springs import ObliqueSpringQZS

    law, laws = ObliqueSpringQZS(vertical_stiffness=180.0), []
    real = compute.compute_page

    def recorded(request):
        laws.append(request.isolator.spring)
        return real(request)

    monkeypatch.setattr(compute, "compute_page", recorded)
    warm_up(stream=open("/dev/null", "w"), spring=law)
    assert laws == [law] * 3
