"""The tuning page of one browser session: Panel widgets and Bokeh plots (docs/app.md).

:func:`build_page` makes a fresh :class:`TuningPage` per browser session. The page only
collects values and draws: every value goes through :func:`qzs.app.compute.page_request`
(the API's own validation), the computation through :func:`qzs.app.compute.compute_page`
in the shared background thread, one request at a time and the newest only
(:class:`qzs.app.updates.LatestOnly`). A slider asks for a computation when it is
released (``value_throttled``), a field when its value is entered.

Panel is imported here, never by the layers below; :func:`qzs.app.server.serve` checks
that it is installed before this module is imported.
"""
import asyncio
import dataclasses
import io
import logging
import sys
import traceback
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import panel as pn
from bokeh.models import (ColumnDataSource, FactorRange, Legend, LogTicker, NumeralTickFormatter,
                          Range1d, Span)
from bokeh.plotting import figure

from qzs._format import markdown_table, number
from qzs.app.compute import (CONTROLLER_RATES, LIMITS, SAMPLE_RATES, compute_page, config_text,
                             law_slider_range, page_parameters, page_request, page_values)
from qzs.app.figure import PIN_COLORS, describe_request, figure_png
from qzs.app.platform import PLATFORM_PARAMETERS, compute_platform
from qzs.app.updates import LatestOnly
from qzs.errors import DataError, ParameterError, SimulationError
from qzs.model.registry import ALL_PARAMETERS, PARAMETERS, SPRING_PARAMETERS, parameter_info
from qzs.viz.figures import frequency_limits

__all__ = ["TuningPage", "PlatformTab", "build_page", "css_class", "SLIDERS", "SOURCE_NAMES",
           "EXECUTOR", "DISPLAY_UNITS"]

LOG = logging.getLogger("qzs.app")

#: The one background thread of the server: every session's computations queue here, one
#: at a time, so that the machine's cores serve the kernels and the event loop stays free.
EXECUTOR = ThreadPoolExecutor(max_workers=1, thread_name_prefix="qzs-app")

#: Settings the page shows in another unit than the registry's SI one: name -> (unit,
#: factor from the registry's unit). Displacements are in mm on the whole page, controls
#: and plots alike: the paper quotes them in mm (a 10 mm chirp, strokes of tens of mm), and
#: 10 reads better than 0.0100 m. Everything else keeps the registry's unit; the request,
#: the TOML export and the API stay SI.
DISPLAY_UNITS = {"excitation.amplitude": ("mm", 1e3)}
#: Slider ranges of the page (start, end, step) in the units the labels show (the
#: registry's, or :data:`DISPLAY_UNITS`); typed values may leave them (the API's validation
#: decides), except where :data:`LIMITS` bounds a size.
SLIDERS = {
    "stiction_force": (0.0, 40.0, 0.5),
    "coulomb_force": (0.0, 20.0, 0.25),
    "stribeck_decay": (0.0, 1000.0, 10.0),
    "viscous_damping": (0.0, 500.0, 5.0),
    "mass": (1.0, 20.0, 0.1),
    "spring_force": (0.0, 120.0, 0.5),
    "spring_shape": (10.0, 300.0, 1.0),
    "pi_kp": (0.0, 500.0, 1.0),
    "pi_ki": (0.0, 200.0, 1.0),
    "damping_gain": (0.0, 500.0, 5.0),
    "velocity_highpass": (0.0, 10.0, 0.1),
    "compensation.fraction": (0.0, 1.5, 0.05),
    "excitation.amplitude": (0.0, 50.0, 0.5),
    "excitation.duration": (*LIMITS["excitation.duration"][:2], 10.0),
    "band": (0.0, LIMITS["excitation.f1"][1], 0.1),
    "frequency_count": (*LIMITS["frequency_count"][:2], 1),
    "sine.frequency": (*LIMITS["sine.frequency"][:2], 0.1),
    "sine.duration": (*LIMITS["sine.duration"][:2], 1.0),
}
#: Slider ranges of the platform's tab (start, end, step), registry units.
PLATFORM_SLIDERS = {"pi_kp": (0.0, 5000.0, 50.0), "pi_ki": (0.0, 2000.0, 20.0),
                    "damping_gain": (0.0, 500.0, 5.0), "viscous_damping": (0.0, 500.0, 5.0)}
#: Bokeh ``name`` of each data source (the browser tests read them by name).
SOURCE_NAMES = {"transmissibility": "qzs-transmissibility", "linear": "qzs-linear",
                "pinned": "qzs-pinned", "base": "qzs-base", "payload": "qzs-payload",
                "relative_position": "qzs-relative-position", "motor_force": "qzs-motor-force",
                "locked": "qzs-locked", "stops": "qzs-stops", "limits": "qzs-limits",
                "platform_legs": "qzs-platform-legs"}
_GROUPS = (("Friction", ("stiction_force", "coulomb_force", "stribeck_decay",
                         "viscous_damping")),
           ("Payload and spring", ("mass", "spring_force", "spring_shape")),
           ("Controller", ("pi_kp", "pi_ki", "damping_gain", "velocity_highpass",
                           "controller_rate", "compensation.fraction")))
_MM = 1e3
_WIDGET_WIDTH = 330
_EXPECTED = (ParameterError, SimulationError, DataError)


def _label(name, spring=None):
    """A setting's label, its unit in brackets; a ``spring.*`` parameter described as
    ``spring``'s own field (the registry's ``spring.center`` speaks of every law)."""
    fields = {f"spring.{f.name}": f for f in dataclasses.fields(spring)} if spring else {}
    if name in fields:
        return f"{fields[name].metadata['doc']} [{ALL_PARAMETERS[name].unit}]"
    if name in ALL_PARAMETERS:
        info = ALL_PARAMETERS[name]
        return f"{info.doc} [{info.unit}]"
    labels = {
        "excitation.amplitude": f"base displacement amplitude "
                                f"[{DISPLAY_UNITS['excitation.amplitude'][0]}]",
        "excitation.duration": f"chirp {parameter_info('excitation.duration', 'chirp').doc} "
                               f"[{parameter_info('excitation.duration', 'chirp').unit}]",
        "band": f"band f0-f1 [{parameter_info('excitation.f0', 'chirp').unit}]",
        "frequency_count": "stepped sine: frequencies [-]",
        "sine.frequency": f"time response: {parameter_info('excitation.frequency', 'sine').doc} "
                          f"[{parameter_info('excitation.frequency', 'sine').unit}]",
        "sine.duration": f"time response: duration [{LIMITS['sine.duration'][2]}]",
        "sample_rate": f"output sample rate [{LIMITS['sample_rate'][2]}]",
    }
    return labels[name]


def _legend_outside(plot, place, **properties):
    """Move the legend the glyphs made out of ``plot``'s frame to its ``place`` side
    (``"below"``, ``"right"``): it never covers a curve."""
    legend = plot.legend[0]
    plot.center.remove(legend)
    legend.update(border_line_alpha=0, location="top_left", **properties)
    plot.add_layout(legend, place)


def _shown(name, value):
    """A setting's registry value as its widget shows it (:data:`DISPLAY_UNITS`)."""
    return value * DISPLAY_UNITS[name][1] if name in DISPLAY_UNITS else value


def _registry(name, value):
    """A widget's value in the registry's unit (:data:`DISPLAY_UNITS`)."""
    return value / DISPLAY_UNITS[name][1] if name in DISPLAY_UNITS else value


def _named(cls, label, *, style=None, **params):
    """A Panel widget labelled ``label`` in the button style ``style``: ``label=`` and
    ``color=`` where this Panel has them, the older ``name=`` and ``button_type=`` else."""
    params["label" if "label" in cls.param else "name"] = label
    if style is not None:
        params["color" if "color" in cls.param else "button_type"] = style
    return cls(**params)


def css_class(name):
    """The CSS class of a setting's widget (``qzs-w-`` and the name, dots as dashes).

    Parameters
    ----------
    name : str
        A page setting (``stiction_force``, ``excitation.amplitude``, ``band``, ...).

    Returns
    -------
    str
    """
    return "qzs-w-" + name.replace(".", "-")


def _running_loop():
    """The event loop running in this thread (the server's, when a session builds its
    page), or None."""
    try:
        return asyncio.get_running_loop()
    except RuntimeError:
        return None


def _message(error):
    """What the page says about an exception: its message, never a traceback."""
    if isinstance(error, _EXPECTED):
        return str(error)
    return (f"internal error ({type(error).__name__}: {error}); the server's log has the "
            "details. Please report it with the settings (Export TOML).")


class TuningPage:
    """The widgets, plots and callbacks of one browser session.

    Parameters
    ----------
    schedule : callable, optional
        ``schedule(callback)`` runs ``callback`` on the session's event loop; default:
        the current Bokeh document's ``add_next_tick_callback``, called on that loop.
    executor : concurrent.futures.Executor, optional
        Where computations run; default :data:`EXECUTOR`.
    spring : SpringLaw, optional
        The spring law the page starts with (``qzs app --spring``): its ``spring.*``
        parameters get the sliders of the MagSpring's ``spring_force`` and
        ``spring_shape`` (ranges :func:`qzs.app.compute.law_slider_range`; a table has
        none, a line describes it), and "Reset" returns to it. None: the MagSpring.
    """

    def __init__(self, *, schedule=None, executor=None, spring=None):
        self.spring = spring
        self.start = page_request(spring=spring)  # what "Reset" returns to
        self.document = pn.state.curdoc
        self._loop = _running_loop() if self.document is not None else None
        self.data = None
        self.pins = []
        self._resetting = False
        self._closed = False
        self.widgets = self._make_widgets()
        self.sources = {key: ColumnDataSource(name=name, data=self._empty(key))
                        for key, name in SOURCE_NAMES.items()}
        self.plots = self._make_plots()
        self.spinner = pn.indicators.LoadingSpinner(value=False, size=22, margin=(5, 5))
        self.status = pn.pane.Markdown("starting", margin=(0, 5), css_classes=["qzs-status"])
        self.alert = pn.pane.Alert("", alert_type="danger", visible=False, width=_WIDGET_WIDTH,
                                   css_classes=["qzs-error"])
        self.summary = pn.pane.Markdown("", sizing_mode="stretch_width",
                                        css_classes=["qzs-summary"])
        # the law computed, in words (read-only: a table's law has no slider)
        self.law_line = pn.pane.Markdown(self._law_text(self.start), width=_WIDGET_WIDTH,
                                         margin=(0, 5), css_classes=["qzs-spring-law"])
        self.updates = LatestOnly(compute_page, self._deliver,
                                  executor=executor or EXECUTOR,
                                  schedule=schedule or self._schedule, busy=self._busy)
        self.layout = self._make_layout()
        for widget in self.widgets.values():
            event = "value_throttled" if "value_throttled" in widget.param else "value"
            widget.param.watch(self._changed, event)
        if self.document is not None:
            pn.state.on_session_destroyed(self._destroyed)
        self.request_update()

    # ------------------------------------------------------------ widgets
    def _make_widgets(self):
        values = page_values(self.start)
        widgets = {}
        for name in page_parameters(self.spring):
            if name == "controller_rate":
                widgets[name] = _named(
                    pn.widgets.DiscreteSlider, _label(name), options=list(CONTROLLER_RATES),
                    value=values[name], width=_WIDGET_WIDTH)
                continue
            start, end, step = (law_slider_range(self.spring, name)
                                if name in SPRING_PARAMETERS else SLIDERS[name])
            widgets[name] = _named(
                pn.widgets.EditableFloatSlider, _label(name, self.start.isolator.spring),
                start=start, end=end, step=step,
                value=float(values[name]), width=_WIDGET_WIDTH)
        widgets["excitation.kind"] = _named(
            pn.widgets.RadioButtonGroup, "excitation",
            options={"chirp (Welch)": "chirp", "stepped sine (steady state)": "stepped"},
            value=values["excitation.kind"], width=_WIDGET_WIDTH)
        for name in ("excitation.amplitude", "excitation.duration", "sine.frequency",
                     "sine.duration"):
            start, end, step = SLIDERS[name]
            widgets[name] = _named(
                pn.widgets.EditableFloatSlider, _label(name), start=start, end=end, step=step,
                value=_shown(name, float(values[name])), width=_WIDGET_WIDTH)
        start, end, step = SLIDERS["band"]
        widgets["band"] = _named(
            pn.widgets.EditableRangeSlider, _label("band"), start=start, end=end, step=step,
            value=(values["excitation.f0"], values["excitation.f1"]), width=_WIDGET_WIDTH)
        start, end, step = SLIDERS["frequency_count"]
        widgets["frequency_count"] = _named(
            pn.widgets.EditableIntSlider, _label("frequency_count"), start=start, end=end,
            step=step,
            value=values["frequency_count"], width=_WIDGET_WIDTH)
        widgets["sample_rate"] = _named(
            pn.widgets.Select, _label("sample_rate"), options={f"{r:g}": r for r in SAMPLE_RATES},
            value=values["sample_rate"], width=_WIDGET_WIDTH)
        for name, widget in widgets.items():  # a class per widget: the browser tests find it
            widget.css_classes = [css_class(name)]
        return widgets

    def values(self):
        """The page's values as :func:`qzs.app.compute.page_request` takes them."""
        values = {}
        for name, widget in self.widgets.items():
            if name == "band":
                values["excitation.f0"], values["excitation.f1"] = widget.value
            else:
                values[name] = _registry(name, widget.value)
        return values

    # ------------------------------------------------------------ plots
    @staticmethod
    def _empty(key):
        if key == "pinned":
            return {"xs": [], "ys": [], "label": [], "color": []}
        if key == "locked":
            return {"run": ["time-response sine", "chirp or stepped sine"], "share": [0.0, 0.0]}
        if key == "stops":
            return {"x": [], "low": [], "high": [], "setpoint": []}
        if key == "limits":
            return {"x": [], "low": [], "high": []}
        return {"x": [], "y": []}

    def _make_plots(self):
        source = self.sources
        tools = "pan,wheel_zoom,box_zoom,reset,save,hover"
        # the frequency axis as every figure of qzs draws it (qzs.viz.figures.frequency_axis):
        # log, 1-2-5 ticks labelled as plain numbers; the legend below the frame, never on
        # the curves; the frame's height fixed, the width following the window
        trans = figure(frame_height=300, sizing_mode="stretch_width", min_width=420,
                       tools=tools, name="qzs-transmissibility-plot", x_axis_type="log",
                       x_range=Range1d(0.1, 20.0),
                       title="Transmissibility, payload over base acceleration (trusted bins)",
                       x_axis_label="frequency [Hz]", y_axis_label="transmissibility [dB]")
        trans.xaxis.ticker = LogTicker(mantissas=[1, 2, 5])
        trans.xaxis.formatter = NumeralTickFormatter(format="0.[00]")
        trans.multi_line("xs", "ys", source=source["pinned"], color="color", line_width=1.5,
                         alpha=0.8, legend_field="label")
        trans.line("x", "y", source=source["transmissibility"], color="#1f77b4",
                   line_width=2, legend_label="simulated")
        self._stepped_marks = trans.scatter("x", "y", source=source["transmissibility"],
                                            color="#1f77b4", size=6, visible=False)
        trans.line("x", "y", source=source["linear"], color="#ff7f0e", line_width=1.5,
                   line_dash="dashed", legend_label="linear model")
        trans.add_layout(Span(location=0.0, dimension="width", line_color="#999999",
                              line_width=1))
        # one item a line: the pins' labels are long
        _legend_outside(trans, "below", name="qzs-transmissibility-legend",
                        label_text_font_size="9pt", orientation="vertical", spacing=0,
                        padding=4)

        def timeplot(title, label, **kw):
            return figure(frame_height=170, sizing_mode="stretch_width", min_width=250,
                          tools=tools, title=title, x_axis_label="time [s]",
                          y_axis_label=label, **kw)

        response = timeplot("Response to the sine", "displacement from rest [mm]",
                            name="qzs-response-plot")
        response.line("x", "y", source=source["base"], color="#888888", legend_label="base y")
        response.line("x", "y", source=source["payload"], color="#1f77b4",
                      legend_label="payload x")
        # beside the frame, so that the three time plots keep one height
        _legend_outside(response, "right", name="qzs-response-legend",
                        label_text_font_size="8pt", orientation="vertical", padding=2,
                        margin=2, glyph_width=14, label_standoff=3)
        stroke = timeplot("Stroke used (red: the stops)", "relative position z [mm]",
                          x_range=response.x_range)
        stroke.line("x", "y", source=source["relative_position"], color="#1f77b4")
        # the stops and the limit as data, so that the axes take them in: the stroke used
        # is seen against the whole stroke, the motor force against the whole range
        for column, dash in (("low", "solid"), ("high", "solid"), ("setpoint", "dotted")):
            stroke.line("x", column, source=source["stops"], line_dash=dash, line_width=2,
                        color="#888888" if column == "setpoint" else "#d62728")
        motor = timeplot("Motor force (red: its limit)", "motor force [N]",
                         x_range=response.x_range)
        motor.line("x", "y", source=source["motor_force"], color="#1f77b4")
        for column in ("low", "high"):
            motor.line("x", column, source=source["limits"], line_width=2, color="#d62728")
        locked = figure(frame_height=300, width=300, tools="save,hover", title="Locked share",
                        x_range=FactorRange(factors=self._empty("locked")["run"]),
                        y_range=(0, 100), x_axis_label="run",
                        y_axis_label="time locked (stuck or on a stop) [%]")
        locked.vbar(x="run", top="share", source=source["locked"], width=0.6,
                    color="#1f77b4")
        locked.xaxis.major_label_text_font_size = "8pt"
        return {"transmissibility": trans, "response": response, "stroke": stroke,
                "motor": motor, "locked": locked}

    # ------------------------------------------------------------ layout
    def _make_layout(self):
        w = self.widgets
        self.pin_button = _named(pn.widgets.Button, "Pin curve", style="primary", width=95)
        self.clear_button = _named(pn.widgets.Button, "Clear pins", width=95)
        self.reset_button = _named(pn.widgets.Button, "Reset to paper" if self.start ==
                                   page_request() else "Reset", style="warning", width=110)
        self.pin_button.on_click(lambda event: self.pin())
        self.clear_button.on_click(lambda event: self.clear_pins())
        self.reset_button.on_click(lambda event: self.reset())
        self.toml_download = _named(
            pn.widgets.FileDownload, "Export TOML config", style="success",
            callback=self._toml_file, filename="qzs-config.toml", width=145)
        self.png_download = _named(
            pn.widgets.FileDownload, "Export figure PNG", style="success",
            callback=self._png_file, filename="qzs-figure.png", width=145)
        sidebar = [pn.pane.Markdown("## qzs tuning page", margin=(0, 5)),
                   pn.Row(self.spinner, self.status), self.alert]
        shown = page_parameters(self.spring)
        for title, names in _GROUPS:
            sidebar.append(pn.pane.Markdown(f"### {title}", margin=(0, 5)))
            # the MagSpring's two, or the page's law's spring.* parameters
            sidebar.extend(w[name] for name in shown
                           if name in names or name in SPRING_PARAMETERS and "mass" in names)
            if "mass" in names and self.start.isolator.spring is not None:
                sidebar.append(self.law_line)
        sidebar.append(pn.pane.Markdown("### Excitation", margin=(0, 5)))
        sidebar.extend(w[name] for name in ("excitation.kind", "excitation.amplitude", "band",
                                            "excitation.duration", "frequency_count",
                                            "sine.frequency", "sine.duration", "sample_rate"))
        buttons = pn.Column(pn.Row(self.pin_button, self.clear_button, self.reset_button),
                            pn.Row(self.toml_download, self.png_download))
        p = self.plots
        wide = {"sizing_mode": "stretch_width"}  # the plots share what the sidebar leaves
        main = pn.Column(
            buttons, self.summary,
            pn.Row(pn.pane.Bokeh(p["transmissibility"], **wide), pn.pane.Bokeh(p["locked"]),
                   **wide),
            pn.Row(pn.pane.Bokeh(p["response"], **wide), pn.pane.Bokeh(p["stroke"], **wide),
                   pn.pane.Bokeh(p["motor"], **wide), **wide), **wide)
        for plot in p.values():
            plot.toolbar.logo = None
        return pn.Row(pn.Column(*sidebar, width=_WIDGET_WIDTH + 30), main, **wide)

    # ------------------------------------------------------------ updates
    def _schedule(self, callback):
        """Run ``callback()`` on the session's event loop, the document locked.

        Called on the computing thread when a computation ends. The Bokeh document is
        touched on the event loop's thread only: ``callback`` goes to the loop first
        (``call_soon_threadsafe``), which then adds it as the document's next-tick
        callback. Added from the computing thread directly (as Bokeh allows), the
        callback was lost when it came while Panel rendered a new page's HTML: that holds
        the document and puts back the events it held before
        (``panel.io.resources.patch_model_css``), dropping the one that hands the callback
        to the session; the page never drew and its later requests waited behind the lost
        one (tests/app/test_page_scheduling.py).
        """
        if self._closed or self.document is None:
            return
        document = self.document

        def run():
            from panel.io.state import set_curdoc

            with set_curdoc(document):
                callback()

        def add():
            if self._closed:
                return
            try:
                document.add_next_tick_callback(run)
            except Exception:  # the session went away meanwhile  # pragma: no cover
                pass

        if self._loop is None:  # a document outside a running server
            add()
            return
        try:
            self._loop.call_soon_threadsafe(add)
        except RuntimeError:  # the loop is closed: the server stopped  # pragma: no cover
            pass

    def _destroyed(self, session_context):
        self._closed = True

    def _changed(self, event):
        if not self._resetting:
            self.request_update()

    def request_update(self):
        """Validate the page's values and ask for their computation; returns the request.

        An invalid value shows its message at once and drops any computation under way
        (its result would be for another setting); None is returned then.
        """
        try:
            request = page_request(self.values(), spring=self.spring)
        except ParameterError as error:
            self.updates.cancel()
            self._show_error(error)
            self.status.object = "not computed: see the message"
            return None
        self._stepped_marks.visible = request.excitation == "stepped"
        self.updates.submit(request)
        return request

    def _busy(self, flag):
        self.spinner.value = flag
        if flag:
            self.status.object = "computing..."

    def _show_error(self, error):
        if not isinstance(error, _EXPECTED):
            LOG.error("computation failed:\n%s", "".join(
                traceback.format_exception(type(error), error, error.__traceback__)))
        self.alert.object = _message(error)
        self.alert.visible = True

    def _deliver(self, request, outcome):
        if isinstance(outcome, BaseException):
            self._show_error(outcome)
            self.status.object = "not updated: see the message"
            return
        self.alert.visible = False
        self.data = outcome
        self._draw(outcome)
        self.status.object = f"ready (computed in {outcome.elapsed:.2f} s)"

    @staticmethod
    def _law_text(request):
        law = request.isolator.spring
        return "" if law is None else f"spring law (--spring): {law.describe()}"

    def _draw(self, data):
        source, request = self.sources, data.request
        self.law_line.object = self._law_text(request)
        # a log axis draws no bin at or below 0 Hz (the chirp's trusted bins and the
        # linear curve have none; the mask keeps it so)
        shown, linear = data.frequency > 0, data.linear_frequency > 0
        source["transmissibility"].data = {"x": data.frequency[shown],
                                           "y": data.transmissibility_db[shown]}
        source["linear"].data = {"x": data.linear_frequency[linear],
                                 "y": data.linear_db[linear]}
        low, high = frequency_limits(
            (min(request.band), max(request.band)),
            np.concatenate([data.frequency[shown], data.linear_frequency[linear]]))
        self.plots["transmissibility"].x_range.update(start=low, end=high)
        for key, trace in (("base", "base_displacement"), ("payload", "payload_displacement"),
                           ("relative_position", "relative_position")):
            time_, values = data.traces[trace]
            source[key].data = {"x": time_, "y": values * _MM}
        time_, force = data.traces["motor_force"]
        source["motor_force"].data = {"x": time_, "y": force}
        source["locked"].data = {"run": self._empty("locked")["run"],
                                 "share": [100 * np.nan_to_num(data.locked_share["sine"]),
                                           100 * np.nan_to_num(data.locked_share["excitation"])]}
        ends = [0.0, request.sine_duration]
        source["stops"].data = {"x": ends, "low": [data.stop_low * _MM] * 2,
                                "high": [data.stop_high * _MM] * 2,
                                "setpoint": [data.position_setpoint * _MM] * 2}
        source["limits"].data = {"x": ends, "low": [-data.motor_force_max] * 2,
                                 "high": [data.motor_force_max] * 2}
        self.plots["response"].title.text = (
            f"Response to a {request.sine_frequency:g} Hz, {request.amplitude * _MM:g} mm sine")
        self.summary.object = self._summary_text(data)

    @staticmethod
    def _summary_text(data):
        request, s = data.request, data.summary
        half = request.isolator.stroke_half * _MM
        if request.excitation == "chirp":
            run = (f"**chirp** {request.band[0]:g}-{request.band[1]:g} Hz in "
                   f"{request.chirp_duration:g} s")
            error = (f"estimated error {data.step_error:.2g} dB"
                     if np.isfinite(data.step_error) else "no step met the tolerance")
            motor = f"motor peak {s['motor_force_peak']:.1f} N of {data.motor_force_max:g} N; "
        else:
            run = (f"**stepped sine** {request.frequency_count} frequencies "
                   f"{request.band[0]:g}-{request.band[1]:g} Hz")
            error = (f"estimated error {data.step_error:.2g} dB"
                     if np.isfinite(data.step_error) else "no step met the tolerance")
            motor = ""
        lines = [f"{run}, dt = {data.dt * 1e3:.3g} ms ({error}); computed in "
                 f"{data.elapsed:.2f} s",
                 f"peak stroke {s['peak_stroke'] * _MM:.1f} mm of ±{half:g} mm; {motor}"
                 f"motor at its limit {100 * s['saturated_fraction']:.1f} % of the time; "
                 f"stop contacts {s['stop_contacts']:g}; locked "
                 f"{100 * data.locked_share['excitation']:.1f} % of the time"]
        lines += [f"note: {note}" for note in data.notes]
        return "  \n".join(lines)

    # ------------------------------------------------------------ actions
    def pin(self):
        """Keep the current transmissibility drawn (at most as many pins as colours)."""
        if self.data is None:
            return
        if len(self.pins) >= len(PIN_COLORS):
            self.pins.pop(0)
        shown = np.asarray(self.data.frequency) > 0  # a log axis draws no 0 Hz bin
        self.pins.append((describe_request(self.data.request).split(";")[0],
                          np.asarray(self.data.frequency)[shown],
                          np.asarray(self.data.transmissibility_db)[shown]))
        self._draw_pins()

    def clear_pins(self):
        """Remove every pinned curve."""
        self.pins = []
        self._draw_pins()

    def _draw_pins(self):
        self.sources["pinned"].data = {
            "xs": [p[1] for p in self.pins], "ys": [p[2] for p in self.pins],
            "label": [f"pin {i + 1}: {p[0]}" for i, p in enumerate(self.pins)],
            "color": list(PIN_COLORS[:len(self.pins)])}

    def reset(self):
        """Every widget back to the paper's defaults (and the page's; the spring law's to
        the page's law), one computation."""
        values = page_values(self.start)
        self._resetting = True
        try:
            for name, widget in self.widgets.items():
                if name == "band":
                    widget.value = (values["excitation.f0"], values["excitation.f1"])
                else:
                    widget.value = _shown(name, values[name])
        finally:
            self._resetting = False
        self.request_update()

    def _toml_file(self):
        try:
            request = page_request(self.values(), spring=self.spring)
        except ParameterError as error:
            self._show_error(error)
            return io.StringIO(f"# not exported: {error}\n")
        dt = self.data.dt if self.data is not None and self.data.request == request else None
        return io.StringIO(config_text(request, dt))

    def _png_file(self):
        if self.data is None:
            return io.BytesIO()
        return io.BytesIO(figure_png(self.data, self.pins))


class PlatformTab:
    """The six-axis platform's tab: leg settings, geometry, modes, the 6x6 grid.

    Computed in the same background thread as the single axis, newest request only, and
    only once the tab is shown (its first computation takes a few seconds: the grid's 36
    panels are drawn with matplotlib).

    Parameters
    ----------
    schedule : callable
        ``schedule(callback)`` runs ``callback`` on the session's event loop.
    executor : concurrent.futures.Executor, optional
        Where computations run; default :data:`EXECUTOR`.
    """

    def __init__(self, *, schedule, executor=None):
        from qzs.workflows.hexapod.setups import SHIPPED_DEFAULT, load_hexapod

        shipped = load_hexapod(SHIPPED_DEFAULT)
        self.data = None
        self.widgets = {}
        for name in PLATFORM_PARAMETERS:
            section = shipped.isolator if PARAMETERS[name].section == "isolator" \
                else shipped.controller
            start, end, step = PLATFORM_SLIDERS[name]
            self.widgets[name] = _named(
                pn.widgets.EditableFloatSlider, _label(name), start=start, end=end, step=step,
                value=float(getattr(section, name)), width=_WIDGET_WIDTH,
                css_classes=[css_class("platform." + name)])
            self.widgets[name].param.watch(lambda event: self.request_update(),
                                           "value_throttled")
        self.spinner = pn.indicators.LoadingSpinner(value=False, size=22, margin=(5, 5))
        self.status = pn.pane.Markdown("computed when this tab is first shown", margin=(0, 5))
        self.alert = pn.pane.Alert("", alert_type="danger", visible=False, width=_WIDGET_WIDTH)
        self.modes = pn.pane.Markdown("", sizing_mode="stretch_width", min_width=220)
        # the 6x6 grid follows the window's width (at most its drawn 1000 px)
        self.grid = pn.pane.PNG(None, sizing_mode="scale_width", max_width=1000)
        self.source = ColumnDataSource(name=SOURCE_NAMES["platform_legs"], data={
            "x0": [], "y0": [], "z0": [], "x1": [], "y1": [], "z1": []})
        views = []
        for title, (a, b) in (("Top view", ("x", "y")), ("Side view", ("x", "z"))):
            view = figure(height=300, width=300, title=f"{title} at home",
                          x_axis_label=f"{a} [mm]", y_axis_label=f"{b} [mm]",
                          tools="pan,wheel_zoom,reset,save", match_aspect=True)
            view.segment(f"{a}0", f"{b}0", f"{a}1", f"{b}1", source=self.source,
                         line_width=3, color="#555555")
            view.scatter(f"{a}0", f"{b}0", source=self.source, size=9, marker="square",
                         color="#888888")
            view.scatter(f"{a}1", f"{b}1", source=self.source, size=9, color="#1f77b4")
            view.toolbar.logo = None
            views.append(view)
        self.updates = LatestOnly(compute_platform, self._deliver,
                                  executor=executor or EXECUTOR, schedule=schedule,
                                  busy=self._busy)
        sidebar = pn.Column(
            pn.pane.Markdown("## Six-axis platform", margin=(0, 5)),
            pn.pane.Markdown("Six of the isolator's legs in the shipped cubic Stewart platform "
                             "(docs/hexapod.md); each leg takes these values, the rest the "
                             "shipped file's. The linear model only: friction, stops and the "
                             "motor limit are left out. Views: legs dark grey, base joints grey "
                             "squares, top joints blue.", width=_WIDGET_WIDTH),
            pn.Row(self.spinner, self.status), self.alert, *self.widgets.values(),
            width=_WIDGET_WIDTH + 30)
        self.layout = pn.Row(sidebar, pn.Column(pn.Row(*[pn.pane.Bokeh(v) for v in views],
                                                       self.modes, sizing_mode="stretch_width"),
                                                self.grid, sizing_mode="stretch_width"),
                             sizing_mode="stretch_width")

    def values(self):
        """The tab's leg settings (registry names -> SI values)."""
        return {name: widget.value for name, widget in self.widgets.items()}

    def request_update(self):
        """Ask for the tab's computation with its current values."""
        self.updates.submit(self.values())

    def _busy(self, flag):
        self.spinner.value = flag
        if flag:
            self.status.object = "computing (a few seconds) ..."

    def _deliver(self, settings, outcome):
        if isinstance(outcome, BaseException):
            self.alert.object = _message(outcome)
            self.alert.visible = True
            self.status.object = "not updated: see the message"
            return
        self.alert.visible = False
        self.data = outcome
        mm = outcome.base_joints * _MM, outcome.top_joints * _MM
        self.source.data = {f"{axis}{end}": mm[end][:, k] for end in (0, 1)
                            for k, axis in enumerate("xyz")}
        lines = [f"**platform {outcome.platform_mass:.3g} kg, "
                 f"{'statically stable' if outcome.stable else 'statically UNSTABLE'}**", "",
                 *markdown_table(["mode", "frequency [Hz]", "mostly"],
                                 [[j + 1, number(f, undefined="unstable"), axis]
                                  for j, (f, axis) in enumerate(zip(outcome.natural_frequencies,
                                                                    outcome.mode_axes))]),
                 "", *[f"note: {note}" for note in outcome.notes]]
        if not outcome.stable:
            lines.append("raise the PI proportional gain Kp (docs/hexapod.md §6)")
        self.modes.object = "\n".join(lines)
        self.grid.object = outcome.grid_png
        self.status.object = "ready"


def build_page(spring=None):
    """A fresh page for one browser session (what the server serves at ``/``): the single
    axis, and the six-axis platform in a second tab.

    Parameters
    ----------
    spring : SpringLaw, optional
        The single axis's spring law (``qzs app --spring``); None: the MagSpring.

    Returns
    -------
    panel.viewable.Viewable
    """
    page = TuningPage(spring=spring)
    platform = PlatformTab(schedule=page._schedule)
    tabs = pn.Tabs(("Single axis", page.layout), ("Six-axis platform", platform.layout),
                   dynamic=False, sizing_mode="stretch_width")

    def shown(event):
        if event.new == 1 and platform.data is None and not platform.updates.running:
            platform.request_update()

    tabs.param.watch(shown, "active")
    return tabs


def _log_to_stderr():
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("qzs app: %(message)s"))
    LOG.addHandler(handler)
    LOG.setLevel(logging.INFO)


_log_to_stderr()
