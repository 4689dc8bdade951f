"""The figure of a step choice."""
import numpy as np
import pytest

import qzs
from qzs.engine.accuracy import choose_step


@pytest.fixture(scope="module")
def choice():
    """A choice that tries several candidates (a tight tolerance on a short chirp)."""
    return choose_step(qzs.Chirp(duration=20.0, f1=20.0), tolerance=1e-4)


def test_the_figure_draws_each_estimate_and_the_tolerance(choice, tmp_path):
    figure = choice.plot(tmp_path / "step.png")
    assert (tmp_path / "step.png").stat().st_size > 0
    ax = figure.axes[0]
    lines = {line.get_label(): line for line in ax.get_lines()}
    estimate = lines["estimated error"]
    assert np.array_equal(estimate.get_xdata(), [row[0] for row in choice.history])
    assert np.array_equal(estimate.get_ydata(), [row[2] for row in choice.history])
    tolerance = next(line for label, line in lines.items() if label.startswith("tolerance"))
    assert set(tolerance.get_ydata()) == {choice.tolerance}
    assert ax.get_ylabel() == "error [dB]"
