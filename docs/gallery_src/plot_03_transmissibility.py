"""
Transmissibility curves, as the paper draws them
================================================

:func:`qzs.viz.plot_transmissibility` draws transmissibility curves in dB with their
coherence below, trusted bins solid and untrusted ones faint, and the linearised model of each
case dashed in its colour. It draws every figure of ``qzs paper``; here the paper's Fig. 7,
the stiction study, from its quick runs.
"""
from qzs.viz import plot_transmissibility
from qzs.workflows.paper.studies import run_study

study = run_study("stiction", quick=True, workers=2, progress=False)
curves = [dict(label=case.label, frequency=case.frequency, magnitude=case.magnitude,
               trusted=case.trusted, coherence=case.coherence,
               linear=case.linear.get("magnitude"))
          for case in study.cases]
fig = plot_transmissibility(curves, frequency_range=(0.0, 20.0), title=study.study.title)
