"""A sweep's cases: their varied values, parameters and excitations, checked before any run.

:func:`case_settings` turns the sampled columns (:func:`~qzs.workflows.sweeps.definition.
sample_cases`) into one dict per case; :func:`build_model` and :func:`build_case` give a
case's parameters and excitation; :func:`check_cases` refuses a sweep with invalid cases,
naming every one of them, before any runs.
"""
import numpy as np

from qzs.engine.channels import BLOCK_CHANNELS, unrecorded
from qzs.errors import InvalidCasesError, ParameterError
from qzs.model.controller import ControllerParameters
from qzs.model.isolator import IsolatorParameters
from qzs.model.registry import update_parameters
from qzs.workflows.sweeps.definition import case_excitation

__all__ = ["case_settings", "case_duration", "build_model", "build_case", "check_cases",
           "needs_estimates", "batch_channels", "ESTIMATE_CHANNELS"]

#: The channels a case's transmissibility estimate reads.
ESTIMATE_CHANNELS = ("base_acceleration", "payload_acceleration")


def case_settings(definition, columns):
    """One dict of plain Python values per case: the varied parameters.

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    columns : dict of str to ndarray
        One array per varied parameter over the cases
        (:func:`~qzs.workflows.sweeps.definition.sample_cases`).

    Returns
    -------
    list of dict
        Per case, varied parameter name -> value (no ``sample`` index).
    """
    names = list(definition.varied)
    rows = zip(*(np.asarray(columns[n]).tolist() for n in names)) if names else []
    return [dict(zip(names, row)) for row in rows]


def case_duration(definition, settings):
    """Simulated time of a case [s].

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    settings : dict
        The case's varied parameters (an entry of :func:`case_settings`).

    Returns
    -------
    float
        The case's ``excitation.duration`` if it varies it, else the excitation's
        ``duration``, else the analysis's [s].
    """
    if "excitation.duration" in settings:
        return float(settings["excitation.duration"])
    return float(definition.excitation.get("duration", definition.analysis["duration"]))


def build_model(definition, case):
    """A case's model parameters: the sweep's fixed ones with the case's varied ones.

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    case : dict
        The case's varied parameters (``excitation.<name>`` entries are left out).

    Returns
    -------
    isolator : IsolatorParameters
    controller : ControllerParameters

    Raises
    ------
    ParameterError
        Invalid parameter values.
    """
    model = {k: v for k, v in case.items() if not k.startswith("excitation.")}
    return update_parameters(IsolatorParameters(spring=definition.spring),
                             ControllerParameters(), {**definition.parameters, **model})


def build_case(definition, case):
    """A case's parameters and excitation.

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    case : dict
        The case's varied parameters (an entry of :func:`case_settings`).

    Returns
    -------
    isolator : IsolatorParameters
    controller : ControllerParameters
    excitation : tuple
        ``(excitation, duration [s])`` of
        :func:`~qzs.workflows.sweeps.definition.case_excitation`.
    key : tuple
        Equal for cases that share their excitation.

    Raises
    ------
    ParameterError
        Invalid parameter values.
    """
    excitation = {**definition.excitation,
                  **{k.split(".", 1)[1]: v for k, v in case.items()
                     if k.startswith("excitation.")}}
    isolator, controller = build_model(definition, case)
    built = case_excitation(definition.excitation_kind, excitation, definition.analysis)
    return isolator, controller, built, tuple(sorted(excitation.items()))


def check_cases(definition, settings):
    """Refuse a sweep with invalid cases before any runs, naming every one of them.

    Each case's parameters are built (:func:`qzs.model.registry.update_parameters`: a
    negative stiction, a NaN gain, a Coulomb force above the stiction), and each distinct
    excitation once. A step too coarse or a model too stiff for it is found per batch
    instead (the case is then recorded ``invalid`` with its reason).

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.
    settings : list of dict
        The varied parameters of each case (:func:`case_settings`).

    Raises
    ------
    InvalidCasesError
        Some cases are invalid (a :class:`~qzs.errors.CaseError`): their indices, values
        and reasons.
    """
    invalid, excitations = [], {}
    for i, case in enumerate(settings):
        varied = {k.split(".", 1)[1]: v for k, v in case.items() if k.startswith("excitation.")}
        try:
            _check_block_channels(definition, *build_model(definition, case))
            key = tuple(sorted(varied.items()))
            if key not in excitations:
                try:
                    case_excitation(definition.excitation_kind,
                                    {**definition.excitation, **varied}, definition.analysis)
                    excitations[key] = None
                except (ParameterError, TypeError) as error:
                    excitations[key] = error
            if excitations[key] is not None:
                raise excitations[key]
        except (ParameterError, TypeError) as error:
            invalid.append((i, case, str(error)))
    if invalid:
        raise InvalidCasesError(invalid, len(settings))


def _check_block_channels(definition, isolator, controller):
    """Refuse a block's time series (``compensation_force``, ...) the case does not record."""
    missing = unrecorded(definition.outputs["time_series"], controller)
    if missing:
        blocks = sorted({BLOCK_CHANNELS[name][3] for name in missing})
        raise ParameterError(
            f"`outputs.time_series` holds {missing}, which only a controller with the "
            f"{', '.join(blocks)} block records, and this case has none; give the block in "
            f"[parameters] or [grid] (e.g. `compensation.fraction`, "
            f"`compensation.observer_bandwidth` > 0 for `friction_estimate`, "
            f"`dither.amplitude`), or keep them out of `time_series`.",
            options=("outputs.time_series",))


def needs_estimates(definition):
    """Does the sweep keep anything of its cases' transmissibility estimates?

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.

    Returns
    -------
    bool
        True if it stores the transmissibility, the coherence, metrics or band values.
    """
    out = definition.outputs
    return bool(out["transmissibility"] or out["coherence"] or out["metrics"] or out["bands"]
                or out["rms_bands"])


def batch_channels(definition):
    """The channels a batch of the sweep keeps of its runs (every sample at the output rate).

    Parameters
    ----------
    definition : SweepDefinition
        The sweep.

    Returns
    -------
    tuple of str
        :data:`ESTIMATE_CHANNELS` if :func:`needs_estimates`, then the time series it
        stores (each once).
    """
    estimates = ESTIMATE_CHANNELS if needs_estimates(definition) else ()
    return estimates + tuple(c for c in definition.outputs["time_series"]
                             if c not in estimates)
