"""Why active damping did not help much in the paper: experiments and the answer in words.

The cost's change with damping against the charge amplifier's high-pass, the guide's
viscous friction and the controller rate (simulated), and against a delay (the linear
sampled model: the simulator has none).
"""
import dataclasses
import math

from qzs._format import decibels
from qzs.defaults import DAMPING_CLAIM
from qzs.engine.prepare import divides
from qzs.workflows.design.settings import DELAYS
from qzs.workflows.design.cost import _band_grid, _costs, _damping_metrics, _linear_cost


def _why(settings, kp, kd_chosen, damping_rows=(), bar=None):
    base_iso, base_ctrl = settings.isolator, settings.controller_at(kp, 0.0)
    variants = [("baseline", "baseline", base_iso, base_ctrl)]
    hp0 = base_ctrl.velocity_highpass
    for corner in (0.0, 0.1, 1.0, 3.0):
        if corner != hp0:
            variants.append(("high-pass", f"{corner:g} Hz", base_iso,
                             dataclasses.replace(base_ctrl, velocity_highpass=corner)))
    cv0 = base_iso.viscous_damping
    for cv in (10.0, 30.0, 100.0, 300.0):
        if cv != cv0:
            variants.append(("viscous friction", f"{cv:g} N*s/m",
                             dataclasses.replace(base_iso, viscous_damping=cv), base_ctrl))
    rates = [0.0] + [r for r in (1000.0, 200.0, 100.0, 50.0) if divides(r, settings.dt)]
    for rate in rates:
        if rate != settings.controller_rate:
            variants.append(("controller rate", "continuous" if rate == 0 else f"{rate:g} Hz",
                             base_iso, dataclasses.replace(base_ctrl, controller_rate=rate)))
    moderate = float(cv0)
    gains = sorted({0.0, moderate, float(kd_chosen)})
    sweep = sorted({0.0, *(g for g in (20.0, 50.0, 200.0, 500.0, 1000.0)
                           if g <= settings.damping_gain_max), *gains})
    plan = [(v, g) for v, variant in enumerate(variants)
            for g in (sweep if variant[0] == "baseline" else gains)]
    pairs = [(variants[v][2], dataclasses.replace(variants[v][3], damping_gain=g))
             for v, g in plan]
    costs = dict(zip(plan, _costs(pairs, settings)))
    if bar is not None:
        bar.update(len(pairs))
    frequency = _band_grid(settings.band)
    rows = []
    for v, (factor, value, iso, ctrl) in enumerate(variants):
        reference, reference_estimate = costs[(v, 0.0)][0], costs[(v, 0.0)][2]
        linear_reference = _linear_cost(frequency, iso, ctrl, settings,
                                        rate=ctrl.controller_rate, delay=0.0)
        for g in (sweep if factor == "baseline" else gains):
            if g == 0:
                continue
            cost = costs[(v, g)][0]
            damped = dataclasses.replace(ctrl, damping_gain=g)
            linear = _linear_cost(frequency, iso, damped, settings, rate=ctrl.controller_rate,
                                  delay=0.0)
            change = decibels(cost / reference) if (
                math.isfinite(cost) and math.isfinite(reference) and reference > 0) else math.nan
            rows.append({"factor": factor, "value": value, "damping_gain": g,
                         "viscous_damping": iso.viscous_damping,
                         "velocity_highpass": ctrl.velocity_highpass,
                         "controller_rate": ctrl.controller_rate, "cost_undamped": reference,
                         "cost_damped": cost, "change_db": change,
                         **_damping_metrics(reference_estimate, costs[(v, g)][2],
                                            settings.band, math.isfinite(change)),
                         "linear_change_db": decibels(linear / linear_reference),
                         "reason": "" if math.isfinite(change) else
                         "a cost is undefined (too few trusted bins)"})
    delay_rows = []
    for delay in DELAYS:
        for g in gains:
            if g == 0:
                continue
            reference = _linear_cost(frequency, base_iso, base_ctrl, settings, delay=delay)
            damped = _linear_cost(frequency, base_iso, dataclasses.replace(base_ctrl,
                                                                        damping_gain=g),
                                  settings, delay=delay)
            delay_rows.append({"delay": delay, "damping_gain": g,
                               "controller_rate": settings.controller_rate,
                               "linear_change_db": decibels(damped / reference)})
    return {"rows": rows, "delay_rows": delay_rows, "gains": [g for g in gains if g > 0],
            "answer": _why_answer(rows, delay_rows, moderate, kd_chosen, settings,
                                  damping_rows)}


def _pick(rows, factor, value_key, gain):
    return [(r[value_key], r["change_db"], r["linear_change_db"]) for r in rows
            if r["factor"] in (factor, "baseline") and r["damping_gain"] == gain]


def _why_answer(rows, delay_rows, moderate, chosen, settings, damping_rows=()):
    """The answer to the paper's open question, in sentences built from the numbers."""
    def base(gain):
        found = [r for r in rows if r["factor"] == "baseline" and r["damping_gain"] == gain]
        return found[0] if found else None

    ref = base(moderate)
    if ref is None or not math.isfinite(ref["change_db"]):
        return "undefined: the baseline's cost is undefined (too few trusted bins)"
    cost = "RMS" if settings.cost == "rms" else "peak"
    cv = ref["viscous_damping"]
    lines = [
        f"At the paper's operating point (Cv = {cv:g} N*s/m, {ref['velocity_highpass']:g} Hz "
        f"high-pass, the given PI gains Kp = {settings.controller.pi_kp:g} N/m, Ki = "
        f"{settings.controller.pi_ki:g} N/(m*s)) a damping gain equal to the guide's viscous "
        f"friction, Kd = {moderate:g} N*s/m, changes the {cost} transmissibility over "
        f"{settings.band[0]:g}-{settings.band[1]:g} Hz by {ref['change_db']:+.2f} dB (linear "
        f"model {ref['linear_change_db']:+.2f} dB)."]
    largest, rms = ref.get("largest_reduction_db", math.nan), ref.get("band_rms_change_db",
                                                                      math.nan)
    if math.isfinite(largest) and math.isfinite(rms):
        lines.append(
            f"By the two metrics qzs paper decides the claim with (qzs.analysis.damping): the "
            f"largest per-bin reduction is {largest:.2f} dB, the band RMS changes by "
            f"{rms:+.2f} dB" + (
                "; a few bins gain much more than the band as a whole, so the claim holds over "
                "the band and fails in its best bins" if largest >= DAMPING_CLAIM["small_db"] > -rms else "") + ".")
    sweep = sorted((r for r in rows if r["factor"] == "baseline"), key=lambda r: r["damping_gain"])
    if sweep:
        lines.append("Against the damping gain: " + ", ".join(
            f"Kd = {r['damping_gain']:g}: {r['change_db']:+.2f} dB"
            + (f" (per bin up to {r['largest_reduction_db']:.2f} dB)"
               if math.isfinite(r.get("largest_reduction_db", math.nan)) else "")
            for r in sweep if math.isfinite(r["change_db"])) + ".")
        better = [r["damping_gain"] for r in sweep if math.isfinite(r["change_db"])
                  and r["change_db"] <= -3.0]
        if better:
            lines.append(f"A 3 dB improvement takes Kd >= {better[0]:.3g} N*s/m of those tried "
                         f"({better[0] / cv:.2g} times Cv).")
    lines.append(
        "Why: the guide's viscous friction acts on the relative velocity and carries the base's "
        "motion into the payload; above the isolation onset the linear model gives "
        "T = Cv/sqrt((Cv + Kd)^2 + (m w)^2), so a skyhook gain only dilutes a transmission "
        "the friction already sets, and matters once Kd is comparable with Cv.")
    spread = {}
    texts = []
    for factor, key, unit in (("viscous friction", "viscous_damping", "N*s/m"),
                              ("high-pass", "velocity_highpass", "Hz"),
                              ("controller rate", "controller_rate", "Hz")):
        found = sorted(_pick(rows, factor, key, moderate), key=lambda x: (x[0] == 0, x[0])
                       if factor == "controller rate" else x[0])
        finite = [(v, c) for v, c, _ in found if math.isfinite(c)]
        if len(finite) > 1:
            spread[factor] = max(c for _, c in finite) - min(c for _, c in finite)
            texts.append(f"{factor}: " + ", ".join(
                (f"{v:g} {unit}" if not (factor == "controller rate" and v == 0)
                 else "continuous") + f" {c:+.2f} dB" for v, c in finite))
    delays = [r for r in delay_rows if r["damping_gain"] == moderate]
    if delays:
        spread["delay"] = (max(r["linear_change_db"] for r in delays)
                           - min(r["linear_change_db"] for r in delays))
        texts.append("delay (linear sampled model; the simulator has none): " + ", ".join(
            f"{1e3 * r['delay']:g} ms {r['linear_change_db']:+.2f} dB" for r in delays))
    if texts:
        lines.append(f"What Kd = {moderate:g} N*s/m achieves against each factor (simulated "
                     "unless stated): " + "; ".join(texts) + ".")
    if spread:
        ranked = sorted(spread.items(), key=lambda kv: -kv[1])
        lines.append("Ranked by how much they change it: " + ", ".join(
            f"{k} {v:.2f} dB" for k, v in ranked) + f". The {ranked[0][0]} matters most; "
            + ", ".join(k for k, _ in ranked[1:]) + " change the benefit by less.")
    return " ".join(lines)
