"""The sampled loop's margins at the design's gains, over rates and delays; the rate needed."""
from qzs.analysis import control_design as cd
from qzs.workflows.design.settings import DELAYS, RATES


def margin_steps(settings):
    """How many loop analyses :func:`_margins` makes: the units of its progress bar."""
    return 4 + len(RATES) + len({*DELAYS, settings.delay})


def _margins(settings, kp, kd, bar=None):
    """The margins at the gains ``(kp, kd)``; ``bar`` (a progress bar, optional) is advanced by
    one after each loop analysis, :func:`margin_steps` in all."""
    step = (lambda: None) if bar is None else (lambda: bar.update(1))
    controller = settings.controller_at(kp, kd)
    design = cd.loop_margins(settings.isolator, controller, settings.controller_rate,
                             settings.delay)
    step()
    continuous = cd.loop_margins(settings.isolator, controller, 0.0, 0.0)
    step()
    table = []
    for rate in RATES:
        table.append(cd.loop_margins(settings.isolator, controller, rate,
                                     settings.delay).to_dict())
        step()
    needed, reason = cd.required_controller_rate(
        settings.isolator, controller, settings.delay, gain_margin_min=settings.gain_margin_min,
        phase_margin_min=settings.phase_margin_min)
    step()
    needed0, reason0 = cd.required_controller_rate(
        settings.isolator, controller, 0.0, gain_margin_min=settings.gain_margin_min,
        phase_margin_min=settings.phase_margin_min)
    step()
    by_delay = []
    for delay in sorted({*DELAYS, settings.delay}):
        rate, why = cd.required_controller_rate(
            settings.isolator, controller, delay, gain_margin_min=settings.gain_margin_min,
            phase_margin_min=settings.phase_margin_min)
        continuous_delayed = cd.loop_margins(settings.isolator, controller, 0.0, delay)
        step()
        by_delay.append({"delay": delay, "required_rate": rate, "reason": why,
                         "continuous_gain_margin": continuous_delayed.gain_margin,
                         "continuous_phase_margin": continuous_delayed.phase_margin})
    return {"design": design.to_dict(), "continuous": continuous.to_dict(), "table": table,
            "by_delay": by_delay,
            "required_rate": needed, "required_rate_reason": reason,
            "required_rate_without_delay": needed0, "required_rate_without_delay_reason": reason0,
            "meets": design.meets(settings.gain_margin_min, settings.phase_margin_min)}
