"""What every frequency figure must show (qzs.viz.figures.frequency_axis): checked the same
way for each figure kind."""
import numpy as np
import pytest


def check_frequency_axes(axes, scale):
    """Each of ``axes`` has a frequency axis of ``scale``, labelled in Hz where labelled,
    and on a log axis no finite point at or below 0 Hz (dropped, not left to warnings)."""
    for ax in axes:
        assert ax.get_xscale() == scale, (ax.get_title(), ax.get_xscale())
        label = ax.get_xlabel()
        assert label == "" or label.endswith("[Hz]"), label
        if scale != "log":
            continue
        low, high = ax.get_xlim()
        assert 0 < low < high
        for line in ax.get_lines():
            if line.get_transform() is not ax.transData:
                continue  # a line in axes coordinates (axhline), not data
            x = np.asarray(line.get_xdata(), dtype=float)
            y = np.asarray(line.get_ydata(), dtype=float)
            drawn = np.isfinite(x) & np.isfinite(y)
            assert np.all(x[drawn] > 0), line.get_label()


@pytest.fixture
def frequency_axes():
    """:func:`check_frequency_axes`, for the tests of each figure kind."""
    return check_frequency_axes
