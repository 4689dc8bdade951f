"""Every figure qzs draws (matplotlib, Agg when there is no display).

====================  ================================================================
``figures``           the figure factory, the atomic writer, long-trace envelopes
``simulation``        a run's time series and energy ledger
``transmissibility``  transmissibility curves as the paper draws them
``identify``          spring, friction and transmissibility fits
``experiment``        a measured log beside its simulation
``sweeps``            sweep stores: metrics against parameters, transmissibility bands
``design``            a controller design's figures (``qzs design``)
``design_space``      a design search's Pareto front (``qzs optimize``)
``response``          the steady-state response: branches, harmonic balance, chirp
``hexapod``           a hexapod run: platform pose, leg strokes, motor forces
``hexapod_matrix``    the six-axis platform's 6x6 transmissibility as a grid
``hexapod_study``     the hexapod study's cases side by side
``sensitivity``       Sobol and Morris indices as bars with their intervals
``questions``         the paper's open questions: compensation fraction, damping loops
``step``              a step choice: each candidate's estimated error and the tolerance
====================  ================================================================
"""
from qzs.viz.figures import envelope, new_figure, save_figure
from qzs.viz.hexapod import plot_hexapod
from qzs.viz.identify import plot_friction_fit, plot_spring_fit, plot_transmissibility_fit
from qzs.viz.simulation import plot_energy, plot_simulation
from qzs.viz.transmissibility import plot_transmissibility

__all__ = ["envelope", "new_figure", "save_figure", "plot_simulation", "plot_energy",
           "plot_transmissibility", "plot_spring_fit", "plot_friction_fit",
           "plot_transmissibility_fit", "plot_hexapod"]
