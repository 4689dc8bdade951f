"""
A controller design's figures
=============================

:meth:`DesignResult.plot <qzs.workflows.design.result.DesignResult.plot>` (that is,
:func:`qzs.viz.design.plot_design`) draws one figure per question ``qzs design`` answers, in
this order:

1. the static design at the setpoint: what the spring carries and what is left for control;
2. the search for the smallest PI gains that keep every case of a stiction and mass range in
   the spring's constant-force band;
3. hunting at rest: the stick-slip relay's describing function against simulations;
4. the damping gain against the transmissibility cost;
5. the sampled loop's margins against the controller rate;
6. the effect of active damping beside the guide's viscous friction ("did not help much").

The design is the quick one (the ranges' ends, shorter runs, about half a minute).
"""
import qzs
from qzs.viz.design import plot_design

design = qzs.design_controller(quick=True, workers=2)
print(design.summary())
figures = plot_design(design)  # every figure; design.plot(figure=...) draws one
# sphinx_gallery_thumbnail_number = 4
