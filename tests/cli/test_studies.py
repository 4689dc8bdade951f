"""``qzs study`` (qzs.cli.studies): a user's study file runs and writes its figures and metrics."""
from qzs.cli import main


def test_study_runs_a_user_file(tmp_path, capsys):
    study = tmp_path / "mine.toml"
    study.write_text("""
[study]
name = "mine"
title = "Two stictions"
kind = "transmissibility"
claims = []
[[study.view]]
figure = "mine"
frequency_range = [0.0, 10.0]
[analysis]
quick_fft_length = 2048
quick_n_averages = 4
band = [0.0, 10.0]
[excitation]
f1 = 10.0
[[case]]
label = "a"
stiction_force = 2.0
[[case]]
label = "b"
stiction_force = 8.0
""")
    out = tmp_path / "out"
    assert main(["study", str(study), "--quick", "--out", str(out), "--workers", "1",
                 "--quiet"]) == 0
    assert (out / "mine.png").exists() and (out / "mine.svg").exists()
    assert (out / "metrics.csv").read_text().count("\nmine,") == 2


def test_study_with_a_spring_file_runs_that_law_and_says_so(tmp_path, capsys):
    """``qzs study spring --spring FILE.toml``: the spring study measures and fits the file's
    law (docs/model.md §3.1); the summary and metrics.json name it. An open question takes
    no --spring (exit 2, naming it), and a bad spring file exits 2 before any run."""
    import json

    spring = tmp_path / "spring.toml"
    spring.write_text('[spring]\nlaw = "polynomial"\ncoefficients = [62.78, -100.0, 0.0, -5e4]\n'
                      'center = -0.06\n')
    out = tmp_path / "out"
    assert main(["study", "spring", "--quick", "--out", str(out), "--workers", "1", "--quiet",
                 "--spring", str(spring)]) == 0
    assert "spring: polynomial spring about z = -0.06 m" in capsys.readouterr().out
    assert json.loads((out / "metrics.json").read_text())["spring"]["law"] == "polynomial"
    assert (out / "fig05_spring.png").exists()
    assert main(["study", "friction_compensation", "--spring", str(spring),
                 "--out", str(tmp_path / "q")]) == 2
    assert "--spring" in capsys.readouterr().err and not (tmp_path / "q").exists()
    spring.write_text('[spring]\nlaw = "cubic"\n')
    assert main(["study", "spring", "--spring", str(spring), "--out", str(tmp_path / "b")]) == 2
    assert "law = 'cubic'" in capsys.readouterr().err and not (tmp_path / "b").exists()
