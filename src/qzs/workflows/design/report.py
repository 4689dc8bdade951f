"""The design for people: the text summary and the HTML report."""
import html
import math

from qzs._format import html_figure, html_head, html_table, number
from qzs._version import __version__
from qzs.defaults import DAMPING_CLAIM

__all__ = ["design_text"]


#: How the damping metrics relate to the paper report's damping claim.
_METRICS_NOTE = ("The band RMS change and the largest per-bin reduction against Kd = 0 are "
                 "the two metrics qzs paper decides \"active damping did not help much\" "
                 "with (qzs.analysis.damping; there over the trusted bins of "
                 f"{DAMPING_CLAIM['band'][0]:g}-{DAMPING_CLAIM['band'][1]:g} Hz, small below "
                 f"{DAMPING_CLAIM['small_db']:g} dB each; here over the design's band). Both "
                 "compare the two curves on the bins trusted in both: the band RMS change is "
                 "what damping does to the band as a whole, the per-bin reduction where it "
                 "helps most. The change of the cost compares each curve's own trusted bins.")


def _fmt(value, digits=4, unit=""):
    """A number of the summary and the report (4 significant digits; +-inf "infinite")."""
    return number(value, digits, unit, infinite="infinite")


def design_text(result):
    """The design's summary for people: gains, evidence in numbers, answers.

    Parameters
    ----------
    result : DesignResult
        The design.

    Returns
    -------
    str
    """
    g, s = result.gains, result.settings
    pi = result.pi_search
    lines = [f"qzs design ({'quick' if s['quick'] else 'full'}; {result.seconds['total']:.0f} s)",
             f"  gains            Kp = {_fmt(g['pi_kp'])} N/m, Ki = {_fmt(g['pi_ki'])} N/(m*s), "
             f"Kd = {_fmt(g['damping_gain'])} N*s/m"]
    band = s["stroke_band"]
    if pi["found"]:
        lines.append(f"  PI search        smallest Kp keeping {pi['cases']} cases in "
                     f"[{1e3 * band[0]:.1f}, {1e3 * band[1]:.1f}] mm and off the stops: "
                     f"{_fmt(pi['pi_kp'])} N/m (fails at {_fmt(pi['failing_kp'])} N/m)")
    else:
        lines.append(f"  PI search        {pi['reason']}")
    v = result.verification["summary"]
    lines.append(f"  verification     final gains: {'pass' if v['passes'] else 'FAIL'} "
                 f"(worst use of the band {100 * v['usage']:.0f} %: {v['worst_case']})")
    st = result.static
    lines.append(f"  static           spring {st.spring_force_at_setpoint:.2f} N at the setpoint "
                 f"(carries {st.balanced_mass:.3f} kg), deficit {st.static_deficit:+.2f} N, "
                 f"motor force left {st.motor_force_left:.1f} N of {st.motor_force_max:g} N")
    rh = result.stability
    lines.append(f"  stability        Routh-Hurwitz {'stable' if rh.stable else 'UNSTABLE'} "
                 f"(python-control poles agree: {rh.agrees}); Kd range "
                 f"[{_fmt(rh.damping_gain_limits[0])}, {_fmt(rh.damping_gain_limits[1])}] N*s/m, "
                 f"Ki < {_fmt(rh.integral_gain_limit)} N/(m*s)")
    for row in result.hunting["rows"]:
        p, m = row["prediction"], row["simulation"]
        sim = (f"hunts, +-{1e3 * m['amplitude']:.1f} mm, period {_fmt(m['period'], 3)} s"
               if m.get("hunts") else "settles")
        pred = (f"hunts, plateau {1e3 * p['amplitude']:.1f} mm, period {_fmt(p['period'], 3)} s "
                f"(relay {_fmt(p['relay_period'], 3)} s)" if p["hunts"] else "no hunting")
        lines.append(f"  hunting          {row['loop']}, Fs = {row['stiction_force']:g} N: "
                     f"DF {pred}; simulated {sim}")
    cycles = sum(len(row["prediction"]["friction_intersections"])
                 for row in result.hunting["rows"])
    memoryless = ("no cycle in any row" if cycles == 0 else
                  f"{cycles} cycle(s) over the rows")
    lines.append(f"                   (the friction law alone as a describing function predicts "
                 f"{memoryless}; Kp keeping the predicted plateau in the band at the highest "
                 f"stiction: {_fmt(result.hunting['kp_for_band'])} N/m)")
    d = result.damping
    lines.append(f"  damping          Kd = {_fmt(d['chosen'])} N*s/m minimises the "
                 f"{s['cost']} cost over {s['band'][0]:g}-{s['band'][1]:g} Hz"
                 + (f" ({d['reason']})" if d["reason"] else ""))
    mg = result.margins
    design = mg["design"]
    rate = f"{s['controller_rate']:g} Hz" if s["controller_rate"] > 0 else "continuous"
    held = (f"gain {_fmt(design['gain_margin'], 3)} dB, phase "
            f"{_fmt(design['phase_margin'], 3)} deg" if design["stable"] else
            f"none ({design['reasons'].get('gain_margin', 'the loop is unstable')})")
    lines.append(f"  margins          {rate}, delay {s['delay']:g} s: {held}; needed rate "
                 f"{_fmt(mg['required_rate'], 3, 'Hz')}"
                 + (f" ({mg['required_rate_reason']})" if mg["required_rate_reason"] else ""))
    lines.append(f"  why damping      {result.why['answer']}")
    return "\n".join(lines)


_STYLE = """body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;
color:#222}section{border-top:1px solid #ccc;padding-top:1em;margin-top:2em}
figure{margin:1em 0}figure img{width:100%;height:auto;border:1px solid #eee}
figcaption{font-size:.9em;color:#444}table{border-collapse:collapse;font-size:.85em;margin:.5em 0}
td,th{border:1px solid #ddd;padding:.2em .5em;text-align:right}th{background:#eee}
td:first-child,th:first-child{text-align:left}.answer{padding:.6em 1em;border-left:6px solid
#2a8a2a;background:#f7f7f7}.warn{border-color:#c0392b}pre{white-space:pre-wrap;font-size:.85em}"""


def _figure(written, name, caption):
    return html_figure(written[name], name, html.escape(caption)) if name in written else ""


def _html(result, record, written):
    """The HTML report: one section per stage of the design, in reading order."""
    return "\n".join([*_html_opening(result), _html_problem(result.settings),
                      _html_static(result.static, written), _html_pi(result, written),
                      _html_stability(result.stability), _html_hunting(result, written),
                      _html_damping(result, written), _html_margins(result, written),
                      _html_why(result, written), _html_run(result)])


def _html_opening(result):
    """The page's head, title, chosen gains and the text summary (a list of parts)."""
    e = html.escape
    g, s = result.gains, result.settings
    return [html_head("qzs design", _STYLE),
            "<h1>Semi-active QZS isolator: controller design</h1>",
            f"<p>qzs {e(__version__)}; {'quick' if s['quick'] else 'full'} design, "
            f"{result.seconds['total']:.0f} s. Method and decisions: docs/design.md. Every "
            "number comes from simulations of the nonlinear model (stick-slip friction, stops, "
            "saturation) unless it says linear.</p>",
            "<h2>Chosen gains</h2>",
            html_table(["quantity", "value", "unit", "evidence"], [
                ["Kp", _fmt(g["pi_kp"]), "N/m", "PI search (smallest passing gain)"],
                ["Ki", _fmt(g["pi_ki"]), "N/(m*s)", f"Ki/Kp = {s['integral_ratio']:g} 1/s kept"],
                ["Kd", _fmt(g["damping_gain"]), "N*s/m", "damping search (least cost"
                 + (", at the bound)" if result.damping.get("at_bound") else ")")]]),
            f"<pre>{e(design_text(result))}</pre>"]


def _html_problem(s):
    """The problem as solved, from the result's settings."""
    return "<section><h2>Problem</h2>" + html_table(["setting", "value"], [
        ["base motion", f"{s['excitation']['kind']} "
                        + ", ".join(f"{k} = {v} {s['excitation']['units'].get(k, '')}".rstrip()
                                    for k, v in s["excitation"].items()
                                    if k not in ("kind", "units"))],
        ["simulated", f"{s['duration']:g} s, dt = {s['dt']:.3g} s ({s['dt_note']}), output "
                      f"{s['sample_rate']:g} Hz"],
        ["stiction range [N]", f"{s['stiction_range'][0]:g} - {s['stiction_range'][1]:g}"],
        ["mass range [kg]", f"{s['mass_range'][0]:g} - {s['mass_range'][1]:g}"],
        ["force steps [N] (upward +)", ", ".join(f"{x:+g}" for x in s["force_steps"]) or "none"],
        ["stroke band [mm]", f"{1e3 * s['stroke_band'][0]:.1f} to {1e3 * s['stroke_band'][1]:.1f} "
                             "(the constant-force region about the setpoint)"],
        ["cost", f"{s['cost']} of T over the trusted bins of {s['band'][0]:g}-{s['band'][1]:g} "
                 f"Hz (Welch {s['fft_length']} samples)"],
        ["controller", (f"{s['controller_rate']:g} Hz" if s["controller_rate"] > 0 else
                        "continuous") + f", delay {s['delay']:g} s (margins only)"],
        ["cases", f"{len(s['cases'])}: " + "; ".join(s["cases"])]]) + "</section>"


def _html_static(st, written):
    """The static design section."""
    return "<section><h2>Static design</h2>" + html_table(["quantity", "value"], [
        ["spring force at the setpoint [N]", f"{st.spring_force_at_setpoint:.3f}"],
        ["payload the spring alone carries [kg]", _fmt(st.balanced_mass)],
        ["weight m*g [N]", f"{st.weight:.3f}"],
        ["static deficit m*g - F_spring [N]", f"{st.static_deficit:+.3f}"],
        ["motor force left for control [N]",
         f"{st.motor_force_left:.2f} of {st.motor_force_max:g}"],
        ["least force left over the mass range [N]", f"{st.motor_force_left_min:.2f}"],
        ["payloads spring + motor can hold [kg]",
         f"{_fmt(st.holdable_mass[0])} - {_fmt(st.holdable_mass[1])}"],
        ["spring force over the constant-force band [N]",
         f"{st.spring_force_band[0]:.2f} - {st.spring_force_band[1]:.2f}"],
        ["moving mass without the paper's 5.5 kg [kg]", _fmt(st.moving_mass_without_added)],
        ["its static deficit [N]", _fmt(st.deficit_without_added)]]) \
        + _figure(written, "static_design", "Motor force needed to hold a payload at the "
                  "setpoint against its mass, with the motor's limits.") + "</section>"


def _html_pi(result, written):
    """The PI search section: one row per gain tried."""
    e = html.escape
    s, pi = result.settings, result.pi_search
    rows = [[_fmt(t["pi_kp"]), _fmt(t["pi_ki"]), "pass" if t["passes"] else "fail",
             f"{100 * t['usage']:.0f}" if math.isfinite(t["usage"]) else "diverged",
             f"{1e3 * t['z_min']:.1f}", f"{1e3 * t['z_max']:.1f}", t["stop_contacts"],
             t["worst_case"]] for t in pi.get("table", [])]
    return "<section><h2>PI gains</h2><p>" + e(
        f"Smallest Kp (Ki = {s['integral_ratio']:g}*Kp) keeping every case inside the band and "
        f"off the stops: {_fmt(pi['pi_kp'])} N/m; {_fmt(pi['failing_kp'])} N/m fails. "
        + (pi["reason"] or "")) + "</p>" \
        + html_table(["Kp [N/m]", "Ki [N/(m*s)]", "all cases", "band used [%]", "z min [mm]",
                  "z max [mm]", "stop contacts", "worst case"], rows) \
        + _figure(written, "pi_search", "Largest excursion above and below the setpoint over "
                  "every case, against the proportional gain.") + "</section>"


def _html_stability(rh):
    """The linear stability section: the polynomial and its Routh-Hurwitz conditions."""
    e = html.escape
    conditions = [[text, f"{value:.4g}", "holds" if holds else "violated"]
                  for text, value, holds in rh.conditions]
    return (
        "<section><h2>Linear stability</h2><p>Characteristic polynomial (fractions cleared) "
        "m s^4 + (m w + Cv + Kd) s^3 + (Cv w + k + Kp) s^2 + ((k + Kp) w + Ki) s + Ki w, "
        "w = 2 pi f_hp: coefficients " + e(", ".join(f"{c:.5g}" for c in rh.coefficients))
        + ". Routh-Hurwitz conditions:</p>" + html_table(["condition", "value", ""], conditions)
        + "<p>" + e(f"Closed form: stable = {rh.stable}; python-control's poles: largest real "
                    f"part {rh.largest_real_part:.4g} 1/s (agree: {rh.agrees}). Stable Kd at these "
                    f"PI gains: {_fmt(rh.damping_gain_limits[0])} to "
                    f"{_fmt(rh.damping_gain_limits[1])} N*s/m; Ki < "
                    f"{_fmt(rh.integral_gain_limit)} N/(m*s); Kp > "
                    f"{_fmt(rh.proportional_gain_minimum)} N/m.") + "</p></section>")


def _html_hunting(result, written):
    """The hunting section: predictions against simulations, per stiction value."""
    e = html.escape
    hunt_rows = []
    for row in result.hunting["rows"]:
        p, m = row["prediction"], row["simulation"]
        hunt_rows.append([f"{row['stiction_force']:g}", "yes" if p["hunts"] else "no",
                          _fmt(1e3 * p["amplitude"] if p["amplitude"] is not None else None, 3),
                          _fmt(p["period"], 3), _fmt(p["relay_period"], 3),
                          "yes" if m.get("hunts") else "no",
                          _fmt(1e3 * m["amplitude"], 3) if m.get("hunts") else "-",
                          _fmt(m.get("period"), 3) if m.get("hunts") else "-",
                          len(p["friction_intersections"]),
                          {True: "confirmed", False: "refuted", None: "-"}[row["relay_confirmed"]]])
    return (
        "<section><h2>Hunting at rest</h2><p>Describing functions (python-control): the "
        "friction law alone, as a function of slip velocity, predicts no limit cycle for a "
        "stable loop; the payload and its friction as a stick-slip relay in the integral loop "
        "predicts one. Simulation: the base at rest, the payload stuck at the predicted plateau "
        "with the loop in balance.</p>" + html_table(
            ["Fs [N]", "relay DF: hunts", "plateau [mm]", "DF period [s]", "relay period [s]",
             "simulated: hunts", "amplitude [mm]", "period [s]", "memoryless DF cycles",
             "relay DF"], hunt_rows)
        + "<p>" + e(f"Kp keeping the predicted plateau inside the band at the highest stiction: "
                    f"{_fmt(result.hunting['kp_for_band'])} N/m.") + "</p>"
        + _figure(written, "hunting", "Top: the integral loop's Nyquist curve and the stick-slip "
                  "relay's -1/N. Bottom: simulated position at rest.") + "</section>")


def _html_damping(result, written):
    """The damping search section: one row per gain tried."""
    e = html.escape
    d = result.damping
    d_rows = [[_fmt(r["damping_gain"]), _fmt(r["cost"]), _fmt(r["linear_cost"]),
               _fmt(r.get("band_rms_change_db", math.nan), 3),
               _fmt(r.get("largest_reduction_db", math.nan), 3),
               f"{100 * r['trusted_share']:.0f}", _fmt(r["motor_force_rms"], 3), r["reason"]]
              for r in d["rows"]]
    return "<section><h2>Damping gain</h2><p>" + e(
        f"Bound: {_fmt(d['bound'])} N*s/m (" + "; ".join(d["bound_notes"]) + f"). Chosen: "
        f"{_fmt(d['chosen'])} N*s/m. {d['reason']}") + "</p>" \
        + html_table(["Kd [N*s/m]", "cost (simulated)", "cost (linear)",
                      "band RMS change [dB]", "largest per-bin reduction [dB]",
                      "bins trusted [%]", "motor force RMS [N]", "note"], d_rows) \
        + "<p>" + e(_METRICS_NOTE) + "</p>" \
        + _figure(written, "damping", "Cost against the damping gain, and the transmissibility "
                  "without damping and at the chosen gain.") + _curve_links(written) \
        + "</section>"


def _curve_links(written):
    """Links to the damping search's curves as data, when they were written."""
    files = [written[k].name for k in ("curves_nc", "curves_csv") if k in written]
    if not files:
        return ""
    links = " and ".join(f"<a href='{html.escape(f)}'>{html.escape(f)}</a>" for f in files)
    return (f"<p>The curves of every gain tried, as data: {links} (NetCDF CF-1.10; CSV with a "
            "units row under the column names).</p>")


def _html_margins(result, written):
    """The sampled loop section: margins over rates and the rate needed per delay."""
    e = html.escape
    s, mg = result.settings, result.margins
    m_rows = [[f"{t['rate']:g}", "yes" if t["stable"] else "no", _fmt(t["gain_margin"], 3),
               _fmt(t["phase_margin"], 3), _fmt(t["gain_crossover_frequency"], 3)]
              for t in mg["table"]]
    return "<section><h2>Sampled loop</h2><p>" + e(
        f"At the design's rate and delay: gain margin {_fmt(mg['design']['gain_margin'], 3)} dB, "
        f"phase margin {_fmt(mg['design']['phase_margin'], 3)} deg; continuous: "
        f"{_fmt(mg['continuous']['gain_margin'], 3)} dB, "
        f"{_fmt(mg['continuous']['phase_margin'], 3)} deg. Rate needed for "
        f"{s['gain_margin_min']:g} dB and {s['phase_margin_min']:g} deg: "
        f"{_fmt(mg['required_rate'], 3, 'Hz')} with the delay, "
        f"{_fmt(mg['required_rate_without_delay'], 3, 'Hz')} without. "
        f"{mg['required_rate_reason']}") + "</p>" \
        + html_table(["rate [Hz]", "stable", "gain margin [dB]", "phase margin [deg]",
                  "crossover [Hz]"], m_rows) \
        + html_table(["delay [ms]", "needed rate [Hz]", "continuous: gain margin [dB]",
                  "continuous: phase margin [deg]"],
                 [[f"{1e3 * r['delay']:g}", _fmt(r["required_rate"], 3),
                   _fmt(r["continuous_gain_margin"], 3), _fmt(r["continuous_phase_margin"], 3)]
                  for r in mg.get("by_delay", [])]) \
        + _figure(written, "margins", "Margins of the sampled loop against the controller "
                  "rate.") + "</section>"


def _html_why(result, written):
    """Why active damping did not help much: the answer and its experiments."""
    e = html.escape
    w = result.why
    w_rows = [[r["factor"], r["value"], _fmt(r["damping_gain"]), _fmt(r["cost_undamped"]),
               _fmt(r["cost_damped"]), _fmt(r["change_db"], 3),
               _fmt(r.get("largest_reduction_db", math.nan), 3), _fmt(r["linear_change_db"], 3)]
              for r in w["rows"]]
    return ("<section><h2>Why active damping did not help much</h2>"
            f"<div class='answer'>{e(w['answer'])}</div>"
            + html_table(["factor", "value", "Kd [N*s/m]", "cost Kd = 0", "cost damped",
                          "change of the cost [dB]", "largest per-bin reduction [dB]",
                          "linear [dB]"], w_rows)
            + "<p>" + e(_METRICS_NOTE) + "</p>"
            + _figure(written, "damping_effect", "Change of the cost with damping against "
                      "each factor: simulated (markers), linear (lines).") + "</section>")


def _html_run(result):
    """The wall time of each stage, and the page's end."""
    return "<section><h2>Run</h2>" + html_table(["stage", "seconds"], [
        [k, f"{v:.1f}"] for k, v in result.seconds.items()]) + "</section></body></html>"
