"""Findings and their report, shared by the paper's studies and the six-axis study.

What the numbers say and how it is written, one concept a room: the paper's claims decided
(:mod:`.verdicts`), the metric tables, cells and documents both reports write
(:mod:`.tables`), the figures and their curves as data (:mod:`.figures`), the paper's
``report.html`` (:mod:`.html`) and the six-axis study's ``report.md`` (:mod:`.markdown`).
:mod:`qzs.workflows.paper.report` and :mod:`qzs.workflows.hexapod.study` run their studies
and use these rooms to write.

============  ==================================================================
``verdicts``  the paper's claims decided from the trusted bins: one verdict each
``tables``    metric rows with reasons, run settings, table cells with footnotes,
              a document's head, atomic text files
``figures``   each study's views drawn, and the curves behind them as data
``html``      the paper's report.html: claims, settings, figures, verdicts, tables
``markdown``  the six-axis study's report.md and its console summary
============  ==================================================================
"""
