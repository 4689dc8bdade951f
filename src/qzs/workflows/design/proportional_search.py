"""The PI search: the smallest proportional gain that keeps every case in the band.

Every case is run at each gain tried (``base`` cases in one lockstep batch,
:func:`qzs.simulate_batch`; ``step`` and ``hunting`` cases as single runs in threads), its
largest excursion measured against the spring's constant-force band; a log grid of ``Kp``
(``Ki = ratio*Kp``), then bisection between the last failing and the first passing gain
above which every grid gain passes.
"""
import math
from concurrent.futures import ThreadPoolExecutor

from qzs.engine.batch import simulate_batch
from qzs.engine.simulate import simulate
from qzs.errors import SimulationError
from qzs.workflows.design.settings import BISECTIONS, FAMILIES, KP_GRID


def _stats_row(case, z_min, z_max, contacts, failed, settings, message=""):
    z_ref = settings.controller.position_setpoint
    low, high = settings.stroke_band
    usage = max((z_max - z_ref) / (high - z_ref), (z_ref - z_min) / (z_ref - low)) \
        if not failed else math.inf
    return {"case": case.label, "family": case.family, "z_min": float(z_min),
            "z_max": float(z_max), "stop_contacts": int(contacts), "failed": bool(failed),
            "usage": float(usage), "passes": bool(not failed and contacts == 0 and usage <= 1.0),
            "message": message}


def _single(case, controller, settings):
    """Run one ``step`` or ``hunting`` case; its stroke statistics."""
    excitation, isolator, initial, duration = case.run_inputs(
        settings.isolator, controller, settings.excitation, settings.duration, settings.quick)
    try:
        result = simulate(excitation, isolator, controller, duration=duration,
                          dt=settings.stroke_dt, sample_rate=settings.sample_rate,
                          initial_state=initial)
    except SimulationError as error:
        return _stats_row(case, math.nan, math.nan, 0, True, settings, str(error))
    z = result.relative_position
    return _stats_row(case, z.min(), z.max(), result.run["stop_contacts"], False, settings)


def _run_cases(cases, gains, settings, bar=None):
    """Stroke statistics of every case at every gain: ``rows[g][c]``.

    ``gains`` are ``(Kp, Kd)`` pairs; ``base`` cases go through one lockstep batch, the others
    through threads of single runs.
    """
    controllers = [settings.controller_at(kp, kd) for kp, kd in gains]
    rows = [[None] * len(cases) for _ in gains]
    base = [(g, c) for g in range(len(gains)) for c, case in enumerate(cases)
            if case.family == "base"]
    if base:
        batch = simulate_batch([(cases[c].isolator(settings.isolator), controllers[g])
                                for g, c in base], settings.excitation,
                               duration=settings.duration, dt=settings.stroke_dt,
                               sample_rate=settings.sample_rate, channels=(),
                               workers=settings.workers)
        for i, (g, c) in enumerate(base):
            rows[g][c] = _stats_row(cases[c], batch.stats["z_min"][i], batch.stats["z_max"][i],
                                    batch.stats["stop_contacts"][i], bool(batch.status[i]),
                                    settings, batch.messages[i])
        if bar is not None:
            bar.update(len(base))
    singles = [(g, c) for g in range(len(gains)) for c, case in enumerate(cases)
               if case.family != "base"]

    def run(task):
        g, c = task
        return g, c, _single(cases[c], controllers[g], settings)

    with ThreadPoolExecutor(max_workers=settings.workers) as pool:
        for g, c, row in pool.map(run, singles):
            rows[g][c] = row
            if bar is not None:
                bar.update(1)
    return rows


def _summary(kp, kd, settings, rows):
    worst = max(rows, key=lambda r: r["usage"])
    return {"pi_kp": float(kp), "pi_ki": float(settings.ratio * kp), "damping_gain": float(kd),
            "passes": all(r["passes"] for r in rows), "usage": float(worst["usage"]),
            "worst_case": worst["case"], "z_min": float(min(r["z_min"] for r in rows)),
            "z_max": float(max(r["z_max"] for r in rows)),
            "stop_contacts": int(sum(r["stop_contacts"] for r in rows)),
            "failed_cases": int(sum(r["failed"] for r in rows))}


def _search_pi(cases, settings, kd, bar=None, below=None):
    """Grid then bisection in Kp; returns the search record.

    ``below``: ``(Kp, rows)`` of a gain known to fail at this ``kd``; the grid then starts
    above it (the repeat with the chosen damping gain, which only ever needed more).
    """
    grid = list(KP_GRID[settings.quick])
    if below is None:
        rows = _run_cases(cases, [(kp, kd) for kp in grid], settings, bar)
    else:  # upwards from the known failure, one gain at a time, to the first that passes
        above = [g for g in grid if g > below[0] * (1 + 1e-9)] or [grid[-1]]
        grid, rows = [float(below[0])], [below[1]]
        for kp in above:
            (found,) = _run_cases(cases, [(kp, kd)], settings, bar)
            grid.append(kp)
            rows.append(found)
            if all(r["passes"] for r in found):
                break
    table = [_summary(kp, kd, settings, r) for kp, r in zip(grid, rows)]
    details = {kp: r for kp, r in zip(grid, rows)}
    passes = [t["passes"] for t in table]
    record = {"grid": [float(g) for g in grid], "damping_gain": float(kd), "found": False,
              "reason": "", "pi_kp": math.nan, "pi_ki": math.nan, "failing_kp": math.nan,
              "monotone_on_grid": True, "started_above": None if below is None
              else float(below[0])}
    if not passes[-1]:
        record["reason"] = (f"no proportional gain up to {grid[-1]:g} N/m keeps every case in "
                            "the constant-force band and off the stops; widen the band, narrow "
                            "the ranges or soften the disturbance")
        record["table"] = table
        record["details"] = details
        record["family_kp"] = _family_gains(details)
        return record
    first = len(grid) - 1
    while first > 0 and passes[first - 1]:
        first -= 1
    record["monotone_on_grid"] = all(passes[first:]) and not any(passes[:first])
    if first == 0:
        record.update(found=True, pi_kp=float(grid[0]), pi_ki=float(settings.ratio * grid[0]),
                      reason=f"the lowest gain tried, {grid[0]:g} N/m, passes: the smallest gain "
                             f"lies below it (not searched)")
        record["table"] = table
        record["details"] = details
        record["family_kp"] = _family_gains(details)
        return record
    low, high = grid[first - 1], grid[first]
    for _ in range(BISECTIONS[settings.quick]):
        mid = math.sqrt(low * high)
        (mid_rows,) = _run_cases(cases, [(mid, kd)], settings, bar)
        table.append(_summary(mid, kd, settings, mid_rows))
        details[mid] = mid_rows
        if table[-1]["passes"]:
            high = mid
        else:
            low = mid
    table.sort(key=lambda t: t["pi_kp"])
    record.update(found=True, pi_kp=float(high), pi_ki=float(settings.ratio * high),
                  failing_kp=float(low), table=table, details=details)
    record["family_kp"] = _family_gains(details)
    return record


def _family_gains(details):
    """Per family, the smallest gain tried from which on every gain tried passes [N/m]."""
    out = {}
    gains = sorted(details)
    for family in FAMILIES:
        passes = [all(r["passes"] for r in details[kp] if r["family"] == family) for kp in gains]
        if not any(r["family"] == family for r in details[gains[0]]):
            continue
        value = math.nan
        for kp, ok in zip(reversed(gains), reversed(passes)):
            if not ok:
                break
            value = kp
        out[family] = float(value)
    return out
