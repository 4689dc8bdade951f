"""The plotting helpers: what a figure shows of a long trace is its true envelope; the
figure factory keeps any backend that needs no display (Jupyter's inline one)."""
import matplotlib
import numpy as np
import pytest

from qzs.viz import figures
from qzs.viz.figures import envelope


def test_envelope_keeps_every_sample_up_to_the_last():
    """181 819 samples into 1000 bins of 182: the last partial bin is kept, so the trace ends
    at its last time and its extremes (placed in the tail) are drawn."""
    n = 181_819
    time = np.arange(n) * 0.11
    values = np.sin(np.arange(n) * 0.3)
    values[-5] = 7.0  # extremes in the tail, beyond the last whole bin
    values[-3] = -9.0
    t, v = envelope(time, values, max_points=2000)
    assert t.size <= 2000
    assert t[-1] == time[-1] and v.max() == 7.0 and v.min() == -9.0
    assert np.all(np.diff(t) >= 0)
    assert t[0] < time[182]  # from the first bin


def test_envelope_of_a_short_trace_is_the_trace():
    time, values = np.arange(10.0), np.arange(10.0) ** 2
    t, v = envelope(time, values, max_points=2000)
    np.testing.assert_array_equal(v, values)


@pytest.mark.parametrize("backend, switched", [
    ("module://matplotlib_inline.backend_inline", False),  # Jupyter: figures shown inline
    ("agg", False), ("pdf", False), ("TkAgg", True), ("QtAgg", True), ("GTK4Agg", True)])
def test_new_figure_replaces_only_a_window_backend_without_a_display(monkeypatch, backend,
                                                                     switched):
    import matplotlib.pyplot as plt

    plt.close(plt.figure())  # pyplot's own backend is loaded before get_backend is patched
    used = []
    monkeypatch.setattr(matplotlib, "get_backend", lambda: backend)
    monkeypatch.setattr(matplotlib, "use", lambda name, **kwargs: used.append(name))
    monkeypatch.setattr(figures, "_has_display", lambda: False)
    fig, axes = figures.new_figure(1)
    plt.close(fig)
    assert used == (["Agg"] if switched else [])
