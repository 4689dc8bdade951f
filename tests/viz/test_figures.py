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


@pytest.mark.parametrize("value, expected", [(0.061, 0.05), (0.3, 0.2), (0.1, 0.1), (1.0, 1.0),
                                             (4.99, 2.0), (5.0, 5.0), (0.0305, 0.02),
                                             (17.0, 10.0)])
def test_nice_floor_is_the_largest_1_2_5_number_not_above(value, expected):
    assert figures.nice_floor(value) == pytest.approx(expected)


def test_a_log_axis_starts_at_the_lowest_positive_bin_and_labels_plain_numbers():
    """0 Hz cannot be drawn on a log axis: it starts at the lowest positive bin drawn,
    rounded down to 1-2-5; ticks read 0.1, 1, 10 (and 2, 5 between), never 10^-1."""
    import matplotlib.pyplot as plt

    frequency = np.array([0.0, 0.061, 0.122, 1.0, 20.0])
    fig, (ax,) = figures.new_figure(1)
    low, high = figures.frequency_axis(ax, (0.0, 20.0), frequency, label="frequency [Hz]")
    assert ax.get_xscale() == "log" and (low, high) == (0.05, 20.0)
    assert ax.get_xlim() == pytest.approx((0.05, 20.0))
    fig.canvas.draw()
    labels = [t.get_text() for t in ax.get_xticklabels() if low <= t.get_position()[0] <= high]
    assert labels == ["0.05", "0.1", "0.2", "0.5", "1", "2", "5", "10", "20"]
    # a wide span, or a small panel, labels the decades only
    ax.set_xscale("linear")
    figures.frequency_axis(ax, (0.0, 50.0), frequency, decades_only=True)
    fig.canvas.draw()
    labels = [t.get_text() for t in ax.get_xticklabels() if 0.05 <= t.get_position()[0] <= 50]
    assert labels == ["0.1", "1", "10"]
    plt.close(fig)


def test_a_positive_start_is_kept_and_a_linear_axis_takes_the_range_as_given():
    assert figures.frequency_limits((0.5, 20.0), [0.01, 1.0]) == (0.5, 20.0)
    assert figures.frequency_limits((0.0, 20.0), [0.01], "linear") == (0.0, 20.0)
    assert figures.frequency_limits((0.0, 20.0), [0.0, np.nan]) == (0.1, 20.0)  # the floor


def test_the_default_scale_is_the_one_setting_and_others_are_refused():
    from qzs.defaults import FIGURES
    from qzs.errors import ParameterError

    assert figures.check_frequency_scale(None) == FIGURES["frequency_scale"] == "log"
    assert figures.check_frequency_scale("linear") == "linear"
    with pytest.raises(ParameterError, match=r"`--frequency-axis` must be one of log, linear, "
                                             r"got 'semilog'"):
        figures.check_frequency_scale("semilog", argument="--frequency-axis")
    np.testing.assert_array_equal(figures.drawn([0.0, 1.0, np.nan]), [False, True, False])
    np.testing.assert_array_equal(figures.drawn([0.0, 1.0], "linear"), [True, True])


@pytest.mark.parametrize("suffix, magic", [(".png", b"\x89PNG\r\n\x1a\n"), ("", b"\x89PNG")])
def test_figure_bytes_are_the_file_save_figure_writes(tmp_path, suffix, magic):
    """Two fresh, equal figures: one written by save_figure, one turned into bytes."""
    import matplotlib.pyplot as plt

    def draw():
        fig, axes = figures.new_figure(2)
        axes[0].plot(np.arange(50.0), np.sin(np.arange(50.0)), label="x")
        axes[1].set_ylabel("acceleration [m/s$^2$]")
        return fig

    path = tmp_path / f"figure{suffix or '.png'}"
    figures.save_figure(draw(), path)
    data = figures.figure_bytes(draw(), suffix)
    plt.close("all")
    assert data.startswith(magic)
    assert data == path.read_bytes()
