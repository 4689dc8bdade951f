"""The integration steps of the design's runs: accuracy-driven, and coarser for the PI search."""
import dataclasses

from qzs import defaults
from qzs.engine.accuracy import choose_step
from qzs.errors import ToleranceNotMetError
from qzs.workflows.design.settings import KP_GRID, STROKE_STEP_MAX


def _divides(rate, dt):
    ratio = 1.0 / (rate * dt)
    return rate * dt <= 1 + 1e-12 and abs(ratio - round(ratio)) < 1e-6 * ratio


def _stroke_step(settings):
    """The step [s] of the PI search's runs: the coarsest stable one up to STROKE_STEP_MAX.

    Their statistic, the largest excursion, is far less sensitive to the step than the
    transmissibility: measured on the quick design's 16 cases at three gain sets, the band's
    use agreed within 0.9 % of the band between 0.625 ms and 2.5 ms (docs/design.md).
    """
    from qzs.engine.stability import stability_test

    stiffest = settings.controller_at(max(KP_GRID[settings.quick]),
                                      max(settings.damping_gain_max,
                                          settings.controller.damping_gain))
    light = dataclasses.replace(settings.isolator, mass=settings.mass_range[0],
                                stiction_force=settings.stiction_range[1])
    stable = stability_test(light, stiffest, defaults.SIMULATION["solver"])
    for k in range(1, 10_000):
        step = 1.0 / (settings.sample_rate * k)
        if step > STROKE_STEP_MAX or not stable(step):
            continue
        if settings.controller_rate > 0 and not _divides(settings.controller_rate, step):
            continue
        return max(step, settings.dt)
    return settings.dt


def _choose_dt(settings, kp_probe):
    """The accuracy-driven step, chosen on the extreme controllers (docs/model.md decision 26)."""
    probes = [(dataclasses.replace(settings.isolator, stiction_force=settings.stiction_range[1]),
               settings.controller_at(kp_probe, 0.0)),
              (settings.isolator, settings.controller_at(kp_probe, settings.damping_gain_max))]
    steps, notes = [], []
    for isolator, controller in probes:
        try:
            choice = choose_step(settings.excitation, isolator, controller,
                                 tolerance_db=defaults.ACCURACY["tolerance_db"],
                                 sample_rate=settings.sample_rate, band=settings.band)
        except ToleranceNotMetError as error:
            notes.append(f"Kd = {controller.damping_gain:g} N*s/m: {error}")
            continue
        steps.append(choice.dt)
        notes.append(f"Kd = {controller.damping_gain:g} N*s/m, Fs = {isolator.stiction_force:g} "
                     f"N: {choice.dt:.3g} s (estimated error {choice.error:.2g} dB)")
    if not steps:
        return defaults.SIMULATION["dt"], ("no probed case meets the tolerance; the paper's "
                                           "step: " + "; ".join(notes))
    return min(steps), ("accuracy-driven step (tolerance "
                        f"{defaults.ACCURACY['tolerance_db']:g} dB over the band), the smallest "
                        "of: " + "; ".join(notes))
