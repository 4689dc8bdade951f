"""
The steady-state frequency response
===================================

:meth:`SteadyStateResponse.plot <qzs.workflows.response.result.SteadyStateResponse.plot>`
(that is, :func:`qzs.viz.response.plot_response`) draws a stepped-sine sweep, up and down in
frequency, each point run until the response is periodic: the fundamental transmissibility, the
harmonics, the locked share, and the harmonic balance of the smooth model beside it. Here the
paper's default isolator at a few frequencies (``qzs response`` runs 0.5-20 Hz).
"""
import qzs

response = qzs.steady_state_response([0.5, 1.0, 2.0, 3.0, 5.0, 8.0, 12.0], amplitude=0.010,
                                     workers=2)
print(response.summary())
fig = response.plot()
