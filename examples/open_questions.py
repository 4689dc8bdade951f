"""The paper's two open questions as studies: friction compensation and damping design.

Runs both quick studies (pass --full for the full ones: about 2 and 0.5 minutes on two cores),
writes each one's report.html, study.json and figures under results/, and prints the verdicts.
The same as ``qzs study friction_compensation --quick`` and ``qzs study damping_design --quick``
(docs/workflows/questions.md).
"""
import sys

from qzs.workflows.questions import QUESTIONS, run_question

quick = "--full" not in sys.argv[1:]
for name in QUESTIONS:
    result, written, seconds = run_question(name, f"results/{name}", quick=quick)
    answer = result["answer"]
    print(f"{name}: [{answer.label}] {answer.answer}\n  {answer.evidence}\n"
          f"  report: {written['report']} ({seconds:.0f} s)")
