"""The response's figure (qzs.viz.response)."""
import pytest

from qzs.workflows.response import steady_state_response


def test_figure_has_units_on_every_axis(tmp_path):
    import matplotlib.pyplot as plt

    response = steady_state_response([2.0, 4.0, 8.0], direction="both", dt=1e-3, workers=1)
    fig = response.plot(path=tmp_path / "response.png")
    assert (tmp_path / "response.png").stat().st_size > 10_000
    labels = [ax.get_ylabel() for ax in fig.axes] + [fig.axes[-1].get_xlabel()]
    assert all("[" in label and "]" in label for label in labels), labels
    assert "[Hz]" in labels[-1]
    plt.close(fig)


def test_frequency_is_log_by_default_and_linear_on_request(frequency_axes):
    """Even over less than a decade (2-8 Hz) the axis is log unless linear is asked."""
    import matplotlib.pyplot as plt

    response = steady_state_response([2.0, 4.0, 8.0], direction="up", dt=1e-3, workers=1,
                                     harmonic_balance=False)
    figure = response.plot()
    frequency_axes(figure.axes, "log")
    assert figure.axes[0].get_xlim() == pytest.approx((1.9, 8.4))
    frequency_axes(response.plot(frequency_scale="linear").axes, "linear")
    plt.close("all")
