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


def test_cli_spring_file_is_read_and_handed_to_serve(monkeypatch, tmp_path):
    """`qzs app --spring FILE.toml` reads the law (qzs.iotools.config.load_spring) and hands
    it to serve; without --spring serve gets no law (the call above)."""
    import qzs.app.server
    from qzs.cli import main
    from qzs.iotools.config import load_spring
    from qzs.model.springs import ObliqueSpringQZS

    path = tmp_path / "spring.toml"
    path.write_text('[spring]\nlaw = "oblique"\nvertical_stiffness = 180.0\n', encoding="utf-8")
    seen = {}
    monkeypatch.setattr(qzs.app.server, "serve", lambda **kw: seen.update(kw) or 0)
    assert main(["app", "--no-browser", "--spring", str(path)]) == 0
    assert seen["spring"] == load_spring(path) == ObliqueSpringQZS(vertical_stiffness=180.0)


@pytest.mark.parametrize("text, named", [
    ('[spring]\nlaw = "oblique"\nvertical_stiffness = -1.0\n', "vertical_stiffness"),
    ('[spring]\nlaw = "helical"\n', "helical"),
    (None, "spring file"),
])
def test_cli_bad_spring_file_exits_2_before_serving(monkeypatch, tmp_path, capsys, text, named):
    import qzs.app.server
    from qzs.cli import main

    path = tmp_path / "spring.toml"
    if text is not None:
        path.write_text(text, encoding="utf-8")
    monkeypatch.setattr(qzs.app.server, "serve", lambda **kw: pytest.fail("served"))
    assert main(["app", "--no-browser", "--spring", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("qzs: error:") and named in err and "Traceback" not in err
