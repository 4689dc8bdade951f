"""
The shipped hexapod study
=========================

:func:`qzs.workflows.hexapod.study.run_hexapod_study` (``qzs hexapod study``) runs six paper legs
in the cubic configuration, carrying the payload their MagSprings hold, under chirps in ``z``
and in ``x``, with PI, with P only and with no position loop, and writes a report.
:meth:`HexapodStudyResult.plot <qzs.workflows.hexapod.study.HexapodStudyResult.plot>` draws its
comparison: the direct transmissibilities, the strongest coupled entries and the coherence.
The quick runs here (60 s chirps at dt = 1 ms); the report goes to a temporary folder.
"""
import tempfile

from qzs.workflows.hexapod.study import run_hexapod_study

with tempfile.TemporaryDirectory() as folder:
    study = run_hexapod_study(folder, quick=True, progress=False)
print(study.summary())
fig = study.plot()
