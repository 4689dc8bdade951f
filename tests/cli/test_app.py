"""``qzs app`` (qzs.cli.app): it parses and hands its options to qzs.app.server.serve."""
import pytest


@pytest.mark.parametrize("argv", [["app", "--port", "70000"], ["app", "--port", "x"],
                                  ["app", "--unknown"]])
def test_cli_refuses_bad_options(argv, capsys):
    from qzs.cli import main

    assert main(argv) == 2
    assert "error:" in capsys.readouterr().err


def test_cli_delegates_to_serve(monkeypatch):
    """`qzs app` parses and hands its options to qzs.app.server.serve."""
    import qzs.app.server
    from qzs.cli import main

    seen = {}
    monkeypatch.setattr(qzs.app.server, "serve", lambda **kw: seen.update(kw) or 0)
    assert main(["app", "--no-browser", "--port", "6123", "--host", "::1"]) == 0
    assert seen == {"port": 6123, "host": "::1", "open_browser": False}
    assert main(["app"]) == 0
    assert seen == {"port": None, "host": "127.0.0.1", "open_browser": True}
