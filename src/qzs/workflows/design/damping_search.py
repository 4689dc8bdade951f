"""The damping gain: the least transmissibility cost within the stability bound and margins.

The bound is the smaller of the linear stability limit (Routh-Hurwitz with the high-pass)
and the largest gain that keeps the sampled loop's margins; the cost is simulated on a
coarse log grid of gains, then refined about the best.
"""
import math

import numpy as np

from qzs.analysis import control_design as cd
from qzs.workflows.design.settings import DAMPING_POINTS
from qzs.workflows.design.cost import _band_grid, _costs, _damping_metrics, _linear_cost


def _damping_bound(settings, kp):
    """Largest damping gain [N*s/m] inside the linear bound and the sampled loop's margins."""
    controller = settings.controller_at(kp, 0.0)
    routh = cd.damping_gain_limits(settings.isolator, controller)
    cap = settings.damping_gain_max
    notes = []
    high = cap
    if math.isfinite(routh[1]):
        notes.append(f"linear stability (Routh-Hurwitz with the {controller.velocity_highpass:g} "
                     f"Hz high-pass): Kd < {routh[1]:.4g} N*s/m")
        high = min(high, routh[1])
    elif math.isnan(routh[1]):
        return 0.0, ["no damping gain is linearly stable at these PI gains"], routh

    def ok(kd):
        return cd.loop_margins(settings.isolator, settings.controller_at(kp, kd),
                               settings.controller_rate, settings.delay).meets(
            settings.gain_margin_min, settings.phase_margin_min)

    if ok(high):
        bound = high
    else:
        low = 0.0
        if not ok(low):
            return 0.0, notes + ["even Kd = 0 misses the margins"], routh
        for _ in range(40):
            mid = 0.5 * (low + high)
            low, high = (mid, high) if ok(mid) else (low, mid)
            if high - low < 1e-3 * high:
                break
        bound = low
        rate = (f"{settings.controller_rate:g} Hz" if settings.controller_rate > 0
                else "continuous")
        notes.append(f"margins ({settings.gain_margin_min:g} dB, {settings.phase_margin_min:g} "
                     f"deg; {rate}, delay {settings.delay:g} s): Kd <= {bound:.4g} N*s/m")
    if bound >= cap:
        notes.append(f"the search's cap: Kd <= {cap:g} N*s/m (`damping_gain_max`)")
    return float(bound), notes, routh


def _search_damping(settings, kp, bar=None):
    bound, notes, routh = _damping_bound(settings, kp)
    coarse, fine = DAMPING_POINTS[settings.quick]
    record = {"bound": bound, "bound_notes": notes, "routh_limits": list(routh), "rows": [],
              "chosen": 0.0, "at_bound": False, "reason": ""}
    if bound <= 0:
        record["reason"] = "no admissible damping gain above 0: " + "; ".join(notes)
        return record, {}
    gains = [0.0] + list(np.geomspace(max(1.0, bound / 100), bound, coarse))
    curves = {}

    def evaluate(values):
        pairs = [(settings.isolator, settings.controller_at(kp, kd)) for kd in values]
        frequency = _band_grid(settings.band)
        for kd, (value, share, estimate, reason, motor) in zip(values,
                                                                _costs(pairs, settings)):
            linear = _linear_cost(frequency, settings.isolator, settings.controller_at(kp, kd),
                                  settings)
            record["rows"].append({"damping_gain": float(kd), "cost": value,
                                   "trusted_share": share, "linear_cost": linear,
                                   "motor_force_rms": motor, "reason": reason})
            if estimate is not None:
                curves[float(kd)] = estimate
            if bar is not None:
                bar.update(1)

    evaluate(gains)
    rows = sorted(record["rows"], key=lambda r: r["damping_gain"])
    finite = [r for r in rows if math.isfinite(r["cost"])]
    if not finite:
        record["reason"] = "no damping gain has a defined cost (too few trusted bins)"
        return record, curves
    best = min(range(len(rows)), key=lambda i: rows[i]["cost"] if math.isfinite(rows[i]["cost"])
               else math.inf)
    left = rows[max(best - 1, 0)]["damping_gain"]
    right = rows[min(best + 1, len(rows) - 1)]["damping_gain"]
    if right > left:
        if left > 0:
            refine = list(np.geomspace(left, right, fine + 2)[1:-1])
        else:
            refine = list(np.linspace(left, right, fine + 2)[1:-1])
        refine = [kd for kd in refine if all(abs(kd - r["damping_gain"]) > 1e-9 * max(kd, 1)
                                             for r in rows)]
        if refine:
            evaluate(refine)
    rows = sorted(record["rows"], key=lambda r: r["damping_gain"])
    reference = rows[0] if rows and rows[0]["damping_gain"] == 0 else None
    for row in rows:  # both damping metrics against Kd = 0 (qzs.analysis.damping)
        defined = (reference is not None and math.isfinite(reference["cost"])
                   and math.isfinite(row["cost"]))
        row.update(_damping_metrics(curves.get(0.0), curves.get(row["damping_gain"]),
                                    settings.band, defined))
    record["rows"] = rows
    best_row = min((r for r in rows if math.isfinite(r["cost"])), key=lambda r: r["cost"])
    record["chosen"] = best_row["damping_gain"]
    record["at_bound"] = bool(best_row["damping_gain"] >= 0.999 * bound)
    if record["at_bound"]:
        record["reason"] = ("the cost still falls at the bound: the gain is set by the bound "
                            "(" + "; ".join(notes) + "), not by the cost")
    return record, curves
