"""The response's figure (qzs.viz.response)."""
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
