"""The tuning page's widgets and callbacks, driven from Python (no server, no browser).

The page is built outside a Bokeh server with a synchronous executor, so every request is
computed and delivered before the call returns; the browser tests (test_browser.py)
drive the same page through Chromium.
"""
import dataclasses
import io
from concurrent.futures import Future

import numpy as np
import pytest

pytest.importorskip("panel", reason='the page needs Panel: pip install -e ".[app]"')

from qzs.app import page as page_module  # noqa: E402
from qzs.app.compute import MODEL_PARAMETERS, page_request, page_values  # noqa: E402
from qzs.iotools.config import load_config  # noqa: E402
from qzs.model.registry import ALL_PARAMETERS  # noqa: E402


class NowExecutor:
    """Runs each computation at once, in the caller's thread."""

    def submit(self, function, request):
        future = Future()
        try:
            future.set_result(function(request))
        except Exception as error:  # noqa: BLE001 - the page shows it
            future.set_exception(error)
        return future


def make_page():
    return page_module.TuningPage(schedule=lambda f: f(), executor=NowExecutor())


@pytest.fixture(scope="module")
def page():
    return make_page()


def label(widget):
    return widget.label if "label" in widget.param else widget.name


def set_value(page, name, value):
    page.widgets[name].value = value
    return page.request_update()


def test_the_page_draws_the_default_request(page):
    page.reset()
    assert page.data.request == page_request()
    source = page.sources["transmissibility"].data
    np.testing.assert_array_equal(source["x"], page.data.frequency)
    np.testing.assert_array_equal(source["y"], page.data.transmissibility_db)
    assert not page.alert.visible
    assert page.status.object.startswith("ready")
    assert "dt = 1 ms" in page.summary.object
    # each locked share on the bar named for its run
    bars = dict(zip(*(page.sources["locked"].data[key] for key in ("run", "share"))))
    assert bars == {"time-response sine": 100 * page.data.locked_share["sine"],
                    "chirp or stepped sine": 100 * page.data.locked_share["excitation"]}


def test_every_label_carries_the_registry_unit(page):
    for name in MODEL_PARAMETERS:
        info = ALL_PARAMETERS[name]
        assert label(page.widgets[name]) == f"{info.doc} [{info.unit}]"
    for name, widget in page.widgets.items():
        if name != "excitation.kind":
            assert label(widget).endswith("]"), name
    for plot in page.plots.values():
        for axis in (*plot.xaxis, *plot.yaxis):
            assert axis.axis_label == "run" or axis.axis_label.endswith("]"), axis.axis_label


def test_a_changed_value_redraws(page):
    page.reset()
    before = np.array(page.sources["transmissibility"].data["y"])
    set_value(page, "stiction_force", 4.0)
    assert page.data.request.isolator.stiction_force == 4.0
    after = np.array(page.sources["transmissibility"].data["y"])
    assert before.shape != after.shape or not np.array_equal(before, after)
    page.reset()


def test_the_compensation_slider_adds_friction_compensation(page, tmp_path):
    """0 (its default) is no block; a fraction adds FrictionCompensation with it, and the
    motor then cancels that share of the sliding friction: the time-response sine sticks
    for less of its time; beyond 1.5 the API's message; the TOML download carries it."""
    import qzs

    page.reset()
    widget = page.widgets["compensation.fraction"]
    assert (widget.start, widget.end, widget.value) == (0.0, 1.5, 0.0)
    assert page.data.request.controller.compensation is None
    assert page.data.request == page_request()
    locked = page.data.locked_share["sine"]
    set_value(page, "compensation.fraction", 1.0)
    assert page.data.request.controller == qzs.PIDamping() + qzs.FrictionCompensation(
        fraction=1.0)
    assert page.data.locked_share["sine"] < locked
    path = tmp_path / "page.toml"
    path.write_text(page._toml_file().getvalue(), encoding="utf-8")
    assert load_config(path)["controller"] == page.data.request.controller
    drawn = page.data
    assert set_value(page, "compensation.fraction", 1.6) is None  # typed past the slider
    assert page.alert.visible and "`compensation.fraction`" in page.alert.object
    assert "[0, 1.5]" in page.alert.object and page.data is drawn
    page.reset()
    assert page.data.request.controller.compensation is None and not page.alert.visible


def test_an_invalid_value_shows_the_api_message_and_keeps_the_plot(page):
    page.reset()
    drawn = page.data
    assert set_value(page, "coulomb_force", 20.0) is None
    assert page.alert.visible
    assert "must be >= `coulomb_force`" in page.alert.object
    assert "Traceback" not in page.alert.object
    assert page.data is drawn
    page.reset()
    assert not page.alert.visible and page.widgets["coulomb_force"].value == 1.0


def test_an_oversize_request_is_refused_on_the_page(page):
    page.reset()
    set_value(page, "excitation.duration", 5000.0)  # typed past the slider
    assert page.alert.visible and "must lie in [10, 600] s" in page.alert.object
    page.reset()


def test_an_internal_error_shows_a_message_not_a_traceback(monkeypatch):
    def broken(request):
        raise RuntimeError("kaputt")

    monkeypatch.setattr(page_module, "compute_page", broken)
    broken_page = make_page()
    assert broken_page.alert.visible
    assert broken_page.alert.object.startswith("internal error (RuntimeError: kaputt)")
    assert "Traceback" not in broken_page.alert.object


def test_pins_and_reset(page):
    page.reset()
    page.pin()
    set_value(page, "pi_kp", 20.0)
    page.pin()
    pinned = page.sources["pinned"].data
    assert len(pinned["xs"]) == 2 and pinned["label"][0].startswith("pin 1: Fs = 10 N")
    assert "Kp = 20 N/m" in pinned["label"][1]
    np.testing.assert_array_equal(pinned["ys"][1], page.data.transmissibility_db)
    page.reset()
    assert page.values() == page_values()
    assert len(page.sources["pinned"].data["xs"]) == 2  # reset keeps the pins
    page.clear_pins()
    assert page.sources["pinned"].data["xs"] == []


def test_toml_download_round_trips(page, tmp_path):
    page.reset()
    set_value(page, "stiction_force", 6.5)
    set_value(page, "excitation.kind", "stepped")
    text = page._toml_file().getvalue()
    path = tmp_path / "page.toml"
    path.write_text(text, encoding="utf-8")
    config = load_config(path)
    assert config["isolator"] == page.data.request.isolator
    assert config["simulation"]["dt"] == page.data.dt
    assert config["excitation"]["kind"] == "sine"  # a stepped sine exports its time response
    page.reset()


def test_png_download_is_a_png(page):
    page.reset()
    data = page._png_file()
    assert isinstance(data, io.BytesIO) and data.getvalue()[:4] == b"\x89PNG"


def test_displacements_are_in_mm_in_the_controls_as_in_the_plots(page):
    """One unit for displacements on the page: the amplitude's control shows mm (its label
    says so), the request it makes stays SI (m), and the plots are in mm."""
    page.reset()
    widget = page.widgets["excitation.amplitude"]
    assert label(widget).endswith("[mm]")
    assert widget.value == pytest.approx(1e3 * page_request().amplitude)
    request = set_value(page, "excitation.amplitude", 4.0)
    assert request.amplitude == pytest.approx(0.004)
    assert page.plots["response"].yaxis[0].axis_label.endswith("[mm]")
    assert page.plots["stroke"].yaxis[0].axis_label.endswith("[mm]")
    page.reset()
    assert page.values()["excitation.amplitude"] == pytest.approx(page_request().amplitude)


def test_frequency_axis_is_log_and_legends_lie_outside_the_frames(page):
    """The transmissibility's frequency axis is logarithmic, starting at the lowest bin
    drawn (no 0 Hz bin on it); its legend and the sine response's lie beside the frame,
    never in it (Bokeh's ``center`` holds what is drawn over the data)."""
    from bokeh.models import Legend, LogScale

    page.reset()
    trans = page.plots["transmissibility"]
    assert isinstance(trans.x_scale, LogScale)
    for key in ("transmissibility", "linear"):
        assert np.min(page.sources[key].data["x"]) > 0
    lowest = min(np.min(page.sources[key].data["x"]) for key in ("transmissibility", "linear"))
    assert 0 < trans.x_range.start <= lowest
    assert trans.x_range.end == pytest.approx(max(page.data.request.band))
    for name, side in (("transmissibility", "below"), ("response", "right")):
        plot = page.plots[name]
        assert not [r for r in plot.center if isinstance(r, Legend)], name
        assert [r for r in getattr(plot, side) if isinstance(r, Legend)], name


# ---------------------------------------------------------------- a spring law (--spring)
def law_page(spring):
    return page_module.TuningPage(schedule=lambda f: f(), executor=NowExecutor(),
                                  spring=spring)


def sidebar_objects(page):
    """Every pane and widget of the sidebar (the layout's first column), in order."""
    return list(page.layout[0].objects)


def test_a_page_with_a_law_has_its_sliders_and_not_the_magsprings(tmp_path):
    """`qzs app --spring` with an oblique law: the law's six spring.* sliders (the law's
    field described with the registry's unit, the ranges of law_slider_range, the law's values) where
    spring_force and spring_shape were; a slider redraws the run of the changed law;
    "Reset" returns to the file's law; the TOML export carries the slider values in its
    [spring] table."""
    from qzs.app.compute import law_slider_range, page_parameters
    from qzs.model.registry import law_parameters
    from qzs.model.springs import ObliqueSpringQZS

    law = ObliqueSpringQZS()
    page = law_page(law)
    names = law_parameters(law)
    assert "spring_force" not in page.widgets and "spring_shape" not in page.widgets
    assert [n for n in page.widgets if n.startswith("spring")] == list(names)
    shown = sidebar_objects(page)
    for name in names:
        widget = page.widgets[name]
        field = {f.name: f for f in dataclasses.fields(law)}[name.split(".", 1)[1]]
        assert label(widget) == f"{field.metadata['doc']} [{ALL_PARAMETERS[name].unit}]"
        assert (widget.start, widget.end, widget.step) == law_slider_range(law, name)
        assert widget.value == getattr(law, name.split(".", 1)[1])
        assert widget in shown
    assert page.law_line in shown and law.describe() in page.law_line.object
    assert page.data.request == page_request(spring=law)
    assert label(page.reset_button) == "Reset"
    before = np.array(page.sources["transmissibility"].data["y"])
    linear = np.array(page.sources["linear"].data["y"])
    request = set_value(page, "spring.vertical_stiffness", 120.0)
    assert page.data.request == request
    assert request.isolator.spring == ObliqueSpringQZS(vertical_stiffness=120.0)
    assert "k_v = 120 N/m" in page.law_line.object
    assert not np.array_equal(before, page.sources["transmissibility"].data["y"])
    assert not np.array_equal(linear, page.sources["linear"].data["y"])  # the law's overlay
    path = tmp_path / "page.toml"
    path.write_text(page._toml_file().getvalue(), encoding="utf-8")
    assert "[spring]" in path.read_text(encoding="utf-8")
    assert load_config(path)["isolator"] == request.isolator
    page.reset()
    assert page.values() == page_values(page_request(spring=law))
    assert page.data.request.isolator.spring == law
    assert list(page.values()) == [*page_parameters(law), *list(page.values())[
        len(page_parameters(law)):]]


def test_a_table_law_has_no_slider_and_a_line_describing_it():
    from qzs.model.springs import TabulatedSpring

    z = np.linspace(-0.14, 0.02, 9)
    law = TabulatedSpring(positions=z, forces=62.78 - 150.0 * (z + 0.06))
    page = law_page(law)
    assert not [n for n in page.widgets if n.startswith("spring")]
    assert page.law_line in sidebar_objects(page)
    assert page.law_line.object == f"spring law (--spring): {law.describe()}"
    assert page.data.request.isolator.spring == law and not page.alert.visible


def test_the_magsprings_page_has_no_law_line(page):
    assert page.law_line not in sidebar_objects(page)
    assert label(page.reset_button) == "Reset to paper"
    assert {"spring_force", "spring_shape"} <= set(page.widgets)
