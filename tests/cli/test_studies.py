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
