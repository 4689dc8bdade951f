"""An open question's outputs: figures, study.json with the verdict, report.html."""
import json

import matplotlib
import matplotlib.pyplot as plt

from qzs.workflows.questions.common import Answer
from qzs.workflows.questions.report import write_question

matplotlib.use("Agg")


def test_the_outputs_carry_the_verdict_and_the_tables(tmp_path):
    answer = Answer("q", "the paper's words", "no", "nothing <beats> Kd", "the numbers")
    fig = plt.figure()
    written = write_question({"answer": answer, "rows": [{"x": 1.5, "y": float("nan")}],
                              "curves": ["left out"]}, tmp_path / "out",
                             {"fig": (fig, "a caption")}, [("Rows", [{"x": 1.5, "y": 2}])],
                             title="T", how="how")
    record = json.loads((tmp_path / "out" / "study.json").read_text())
    assert record["answer"]["label"] == "no" and record["rows"][0]["y"] is None
    assert "curves" not in record
    page = written["report"].read_text()
    assert "nothing &lt;beats&gt; Kd" in page and "<th>x</th>" in page
    assert (tmp_path / "out" / "fig.png").exists() and (tmp_path / "out" / "fig.svg").exists()
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [
        "fig.png", "fig.svg", "report.html", "study.json"]
