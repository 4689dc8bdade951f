"""The variables of the isolator FMU: one table, read by the model description and the C.

Every registry parameter (:data:`qzs.model.registry.PARAMETERS`) is an FMI parameter with its
SI unit, description and start value (the exported configuration's); so are the run's step
and solver and, with an internal excitation, the chirp or sine of the base (units from the
registry, :func:`qzs.model.registry.unit_of`). The inputs are the motor force (``plant``
mode, starting at the force that holds the setpoint: :func:`holding_force`) or the base
motion (``input`` base motion); the outputs are the recorded channels
(:data:`qzs.engine.channels.CHANNELS`) and the two flags. The value reference of a variable is
its index in :func:`fmu_variables`; :func:`variables_header` writes the same table as C
(``qzs_fmu_variables.h``) for ``csrc/qzs_fmu.c``, with what the C checks the step against.
"""
from dataclasses import asdict, dataclass

import numpy as np

from qzs.engine.channels import CHANNELS, FLAGS
from qzs.engine.prepare import MIN_STEPS_PER_PERIOD
from qzs.model.excitation import (E_AMPLITUDE, E_DURATION, E_F0, E_F1, E_FADE, E_KIND,
                                  E_PHASE)
from qzs.model.isolator import spring_force
from qzs.model.registry import PARAMETERS, unit_of

__all__ = ["FmuVariable", "fmu_variables", "variables_header", "holding_force", "UNITS",
           "MODES", "BASE_MOTIONS", "EXCITATION_KINDS", "EXCITATION_VARIABLES",
           "PLANT_UNUSED"]

#: How the motor force is made: by the PI + damping inside, or given as an input.
MODES = ("closed-loop", "plant")
#: How the base moves: an excitation inside (chirp, sine), or displacement, velocity and
#: acceleration as inputs.
BASE_MOTIONS = ("internal", "input")
#: The internal excitations, by their ``excitation.kind`` code (qzs.model.excitation kinds).
EXCITATION_KINDS = {0: "linear chirp", 1: "logarithmic chirp", 2: "sine"}
#: Every unit of the variables, by its name, as SI base-unit exponents (FMI ``BaseUnit``).
UNITS = {
    "s": {"s": 1}, "m": {"m": 1}, "kg": {"kg": 1}, "rad": {"rad": 1}, "Hz": {"s": -1},
    "m/s": {"m": 1, "s": -1}, "m/s^2": {"m": 1, "s": -2}, "N": {"kg": 1, "m": 1, "s": -2},
    "1/m": {"m": -1}, "s/m": {"s": 1, "m": -1}, "N*s/m": {"kg": 1, "s": -1},
    "N/m": {"kg": 1, "s": -2}, "N/(m*s)": {"kg": 1, "s": -3},
    "J": {"kg": 1, "m": 2, "s": -2},
}
_STOP_MODELS = {"compliant": 0, "plastic": 1}
#: Codes of the ``solver`` parameter (qzs.engine.kernels.SOLVER_*).
_SOLVER_DOC = "integrator: 0 euler, 1 ode3 (Bogacki-Shampine), 2 rk4"
#: The inputs of the base motion, by channel.
_BASE_INPUTS = ("base_displacement", "base_velocity", "base_acceleration")
#: The internal excitation's variables: suffix -> (index in the packed scalars, the registry's
#: ``(kind, option)`` whose unit it has, None for the kind code).
EXCITATION_VARIABLES = {
    "kind": (E_KIND, None),
    "amplitude": (E_AMPLITUDE, ("chirp", "amplitude")),
    "f0": (E_F0, ("chirp", "f0")),
    "f1": (E_F1, ("chirp", "f1")),
    "duration": (E_DURATION, ("chirp", "duration")),
    "phase": (E_PHASE, ("sine", "phase")),
    "fade_in": (E_FADE, ("chirp", "fade_in")),
}
_EXCITATION_DOCS = {
    "kind": "base excitation: " + ", ".join(f"{code} {name}"
                                            for code, name in EXCITATION_KINDS.items()),
    "amplitude": "base displacement amplitude",
    "f0": "chirp start frequency, or the sine's frequency (positive for a sine)",
    "f1": "chirp end frequency (chirps only: a sine does not use it)",
    "duration": "chirp sweep time; the FMU runs no chirp past it (chirps only: a sine does not "
                "use it)",
    "phase": "sine phase at t = 0 (sine only: a chirp does not use it)",
    "fade_in": "fade-in of the excitation (raised-cosine slope)",
}
#: The registry parameters a plant-mode FMU does not use: the controller is the importer's.
PLANT_UNUSED = ("pi_kp", "pi_ki", "damping_gain", "controller_rate", "motor_force_max")


@dataclass(frozen=True, kw_only=True)
class FmuVariable:
    """One variable of the FMU.

    Attributes
    ----------
    name : str
        FMI name (structured: ``excitation.f0``).
    reference : int
        Value reference [-] (its index).
    type : {"F", "I", "B"}
        Float64 (FMI 2 Real), Int32 (FMI 2 Integer) or Boolean.
    causality : {"independent", "parameter", "input", "output"}
        FMI causality.
    unit : str
        Unit name (a key of :data:`UNITS`), or ``""``.
    description : str
        One line.
    start : float or None
        Start value (parameters and inputs), None for outputs and time.
    channel : int
        The recorded channel an output shows (``K.C_*``), 100 + flag for a flag, -1 for none.
    """

    name: str
    reference: int
    type: str
    causality: str
    unit: str
    description: str
    start: float | None
    channel: int = -1

    @property
    def macro(self):
        """Its value reference's C name (``QZS_VR_EXCITATION_F0``)."""
        return "QZS_VR_" + self.name.upper().replace(".", "_")


def _parameter_starts(isolator, controller):
    """The registry parameters' start values: the configuration's, resolved for the C."""
    values = {**asdict(isolator), **asdict(controller)}
    if values["stop_center"] is None:
        values["stop_center"] = controller.position_setpoint
    values["stop_model"] = _STOP_MODELS[values["stop_model"]]
    return values


def holding_force(isolator, controller):
    """The motor force [N] that holds the payload at rest at the setpoint, the base at rest.

    ``m*g`` less the spring's force at ``position_setpoint`` (docs/model.md §2), within the
    motor's saturation ``motor_force_max``: the plant-mode FMU's ``motor_force`` starts here,
    so an importer that has not yet connected the input sees the payload held, not sinking.

    Parameters
    ----------
    isolator : IsolatorParameters
        Plant parameters.
    controller : ControllerParameters
        Supplies the setpoint.

    Returns
    -------
    float
    """
    force = (isolator.mass * isolator.gravity
             - float(spring_force(controller.position_setpoint, isolator)))
    return float(np.clip(force, -isolator.motor_force_max, isolator.motor_force_max))


def fmu_variables(*, isolator, controller, excitation_scalars, dt, solver_code, mode,
                  base_motion):
    """The FMU's variables in value-reference order.

    Parameters
    ----------
    isolator : IsolatorParameters
        The exported plant parameters (start values).
    controller : ControllerParameters
        The exported controller parameters.
    excitation_scalars : ndarray or None
        The internal excitation's packed scalars (``pack()[0]``); None with base-motion inputs.
    dt : float
        Internal step [s].
    solver_code : int
        Integrator code (``K.SOLVER_*``).
    mode : {"closed-loop", "plant"}
        Motor force inside or as input.
    base_motion : {"internal", "input"}
        Base excitation inside or as inputs.

    Returns
    -------
    tuple of FmuVariable
    """
    rows = [dict(name="time", type="F", causality="independent", unit="s",
                 description="simulation time", start=None)]
    starts = _parameter_starts(isolator, controller)
    for name, info in PARAMETERS.items():
        description = info.doc
        if name == "stop_model":
            description += " (0 compliant, 1 plastic)"
        if name == "stop_center":
            description = "centre of the stops in z (exported: the setpoint if none was set)"
        if mode == "plant" and name in PLANT_UNUSED:
            description += " (not used in plant mode: the motor force is the input)"
        kind = "I" if name == "stop_model" else "F"
        rows.append(dict(name=f"{info.section}.{name}", type=kind,
                         causality="parameter", unit=info.unit if info.unit in UNITS else "",
                         description=description, start=float(starts[name])))
    rows.append(dict(name="step_size", type="F", causality="parameter", unit="s",
                     description="internal integration step dt, on a grid from t = 0; any "
                                 "communication step is taken: a grid step that a "
                                 "communication point falls inside is split there",
                     start=float(dt)))
    rows.append(dict(name="solver", type="I", causality="parameter", unit="",
                     description=_SOLVER_DOC, start=float(solver_code)))
    if base_motion == "internal":
        for suffix, (index, registry) in EXCITATION_VARIABLES.items():
            rows.append(dict(name=f"excitation.{suffix}", type="I" if registry is None else "F",
                             causality="parameter",
                             unit="" if registry is None else unit_of(
                                 f"excitation.{registry[1]}", registry[0]),
                             description=_EXCITATION_DOCS[suffix],
                             start=float(excitation_scalars[index])))
    else:
        for name in _BASE_INPUTS:
            _, unit, doc = CHANNELS[name]
            rows.append(dict(name=name, type="F", causality="input", unit=unit,
                             description=doc + " (input: held as stated in docs/fmu.md)",
                             start=0.0))
    if mode == "plant":
        hold = holding_force(isolator, controller)
        rows.append(dict(name="motor_force", type="F", causality="input", unit="N",
                         description="motor force on the payload (input, held over each "
                                     "communication step); starts at the force that holds the "
                                     "setpoint statically, m*g - spring force at the setpoint "
                                     f"within motor_force_max ({hold:.6g} N as exported)",
                         start=hold))
    skipped = {"time", "pi_force", "damping_force", "motor_force"} if mode == "plant" else {"time"}
    if base_motion == "input":
        skipped |= set(_BASE_INPUTS)
    for name, (column, unit, doc) in CHANNELS.items():
        if name not in skipped:
            rows.append(dict(name=name, type="F", causality="output", unit=unit,
                             description=doc, start=None, channel=column))
    for name, (flag, doc) in FLAGS.items():
        rows.append(dict(name=name, type="B", causality="output", unit="", description=doc,
                         start=None, channel=100 + flag))
    return tuple(FmuVariable(reference=i, **row) for i, row in enumerate(rows))


def _c_string(text):
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def variables_header(variables, *, mode, base_motion, token, step=None):
    """``qzs_fmu_variables.h``: the variable table as C, for ``csrc/qzs_fmu.c``.

    Parameters
    ----------
    variables : tuple of FmuVariable
        :func:`fmu_variables`.
    mode : {"closed-loop", "plant"}
        Motor force inside or as input.
    base_motion : {"internal", "input"}
        Base excitation inside or as inputs.
    token : str
        The instantiation token (FMI 3) / GUID (FMI 2) the FMU checks.
    step : StepChoice, optional
        How the exported ``step_size`` was chosen (:attr:`qzs.ResolvedRun.step`): the FMU
        warns of a larger step at initialisation, as one above the step chosen for accuracy
        or above the one given. Default: given (literal), ``step_size``'s start.

    Returns
    -------
    str
        C source.
    """
    exported = next(v.start for v in variables if v.name == "step_size")
    chosen = bool(step is not None and step.chosen)
    how = step.line() if chosen else "given"
    n = len(variables)
    enum = ",\n".join(f"    {v.macro} = {v.reference}" for v in variables)
    starts = ", ".join(repr(float(v.start)) if v.start is not None else "0.0" for v in variables)
    channels = ", ".join(str(v.channel) for v in variables)
    names = ",\n".join(f"    {_c_string(v.name)}" for v in variables)
    causality = "".join("t" if v.causality == "independent" else v.causality[0]
                        for v in variables)
    return (
        "/* qzs_fmu_variables.h: written by qzs at export; the FMU's variables by value\n"
        " * reference (types F Float64, I Int32, B Boolean; causality t time, p parameter,\n"
        " * i input, o output; the recorded channel an output shows, 100 + flag, or -1). */\n"
        "#ifndef QZS_FMU_VARIABLES_H\n#define QZS_FMU_VARIABLES_H\n\n"
        f"#define QZS_FMU_PLANT_MODE {1 if mode == 'plant' else 0}\n"
        f"#define QZS_FMU_BASE_INPUT {1 if base_motion == 'input' else 0}\n"
        f"#define QZS_FMU_TOKEN {_c_string(token)}\n"
        f"#define QZS_FMU_N_VARIABLES {n}\n"
        f"#define QZS_FMU_EXPORTED_STEP {float(exported)!r}\n"
        f"#define QZS_FMU_STEP_CHOSEN {int(chosen)}\n"
        f"#define QZS_FMU_STEP_HOW {_c_string(how)}\n"
        f"#define QZS_FMU_MIN_STEPS_PER_PERIOD {MIN_STEPS_PER_PERIOD}\n\n"
        f"enum {{\n{enum}\n}};\n\n"
        f"static const char QZS_FMU_TYPES[] = {_c_string(''.join(v.type for v in variables))};\n"
        f"static const char QZS_FMU_CAUSALITY[] = {_c_string(causality)};\n"
        f"static const double QZS_FMU_START[] = {{{starts}}};\n"
        f"static const int QZS_FMU_CHANNEL[] = {{{channels}}};\n"
        f"static const char *const QZS_FMU_NAMES[] = {{\n{names}\n}};\n\n"
        "#endif /* QZS_FMU_VARIABLES_H */\n")
