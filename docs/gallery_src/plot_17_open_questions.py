"""
The paper's two open questions
==============================

``qzs study friction_compensation`` and ``qzs study damping_design``
(:mod:`qzs.workflows.questions`, docs/workflows/questions.md): can the motor remove stiction by
compensating the guide's friction, and can a damping loop designed with python-control
attenuate the peaks better than the paper's Kd? Each answers with one verdict; here the quick
studies (about 30 s and 10 s once the kernels are compiled).
"""
from qzs.viz.questions import plot_damping_design, plot_friction_compensation
from qzs.workflows.questions import damping, friction

study = friction.run_friction_study(quick=True, workers=2)
print(f"[{study['answer'].label}] {study['answer'].answer}")
plot_friction_compensation(study["table"], study["reference"], friction.BAND,
                           study["boundaries"]["paper loop"])

study = damping.run_damping_study(quick=True, workers=2)
print(f"[{study['answer'].label}] {study['answer'].answer}")
plot_damping_design(study["curves"], study["rows"], (1.5, 20.0))
# sphinx_gallery_thumbnail_number = 1
