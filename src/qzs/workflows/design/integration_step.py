"""The integration steps of the design's runs: accuracy-driven, and coarser for the PI search."""
import dataclasses

from qzs import defaults
from qzs.engine.step_search import MAX_HALVINGS
from qzs.workflows.design.settings import KP_GRID, STROKE_STEP_MAX


def _stroke_step(settings):
    """The step [s] of the PI search's runs: the coarsest stable one up to STROKE_STEP_MAX.

    Their statistic, the largest excursion, is far less sensitive to the step than the
    transmissibility: measured on the quick design's 16 cases at three gain sets, the band's
    use agreed within 0.9 % of the band between 0.625 ms and 2.5 ms (docs/design.md). So no
    halving: the step is the admissible start of the step search
    (:func:`~qzs.engine.step_choice.admissible_step`, the one search's first candidate) on the
    stiffest, lightest case, with STROKE_STEP_MAX as its resolving step; never finer than the
    accuracy-driven ``settings.dt`` (that step too where no such start exists).
    """
    from qzs.engine.stability import stability_test
    from qzs.engine.step_choice import admissible_step
    from qzs.errors import ParameterError

    stiffest = settings.controller_at(max(KP_GRID[settings.quick]),
                                      max(settings.damping_gain_max,
                                          settings.controller.damping_gain))
    light = dataclasses.replace(settings.isolator, mass=settings.mass_range[0],
                                stiction_force=settings.stiction_range[1])
    stable = stability_test(light, stiffest, defaults.SIMULATION["solver"])
    try:
        step, _ = admissible_step(settings.sample_rate, settings.controller_rate,
                                  lambda dt: dt <= STROKE_STEP_MAX and stable(dt))
    except ParameterError:  # no stable step, or none a sampled controller's period divides
        return settings.dt
    return max(step, settings.dt)


def choose_dt(settings, kp_probe):
    """The accuracy-driven step, chosen on the extreme controllers (docs/model.md decision 26).

    The one call (:func:`qzs.engine.step_choice.choose`, the default tolerance) on a batch
    probe of the two extreme cases (the most stiction without damping, the most damping):
    the finest of their steps, with the one fallback where neither meets the tolerance.

    Parameters
    ----------
    settings : DesignSettings
        The design's settings.
    kp_probe : float
        The proportional gain of the probed controllers [N/m].

    Returns
    -------
    dt : float
        The step [s].
    note : str
        How it was chosen.
    """
    from qzs.engine.accuracy_batch import BatchProbe
    from qzs.engine.step_choice import StepRequest, choose

    probes = [(dataclasses.replace(settings.isolator, stiction_force=settings.stiction_range[1]),
               settings.controller_at(kp_probe, 0.0)),
              (settings.isolator, settings.controller_at(kp_probe, settings.damping_gain_max))]
    labels = [f"Kd = {controller.damping_gain:g} N*s/m, Fs = {isolator.stiction_force:g} N"
              for isolator, controller in probes]
    choice = choose(StepRequest(), BatchProbe(cases=probes, excitation=settings.excitation,
                                              sample_rate=settings.sample_rate,
                                              band=settings.band, max_halvings=MAX_HALVINGS,
                                              labels=labels),
                    fallback=True, cache=True)
    if not choice.met:
        return choice.dt, f"no probed case meets the tolerance: {choice.unmet_note}"
    return choice.dt, (f"accuracy-driven step (tolerance {choice.tolerance:g} dB over the "
                       "band), the smallest of: " + "; ".join(
                           f"{label}: {step:.3g} s (estimated error {error:.2g} dB)"
                           for label, step, error in zip(labels, choice.case_steps,
                                                         choice.case_errors)))
