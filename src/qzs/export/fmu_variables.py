"""The variables of the isolator FMU: one table, read by the model description and the C.

Every registry parameter (:data:`qzs.model.registry.PARAMETERS`) is an FMI parameter with its
SI unit, description and start value (the exported configuration's); so are the run's step
and solver and, with an internal excitation, the chirp or sine of the base. The inputs are
the motor force (``plant`` mode) or the base motion (``input`` base motion); the outputs are
the recorded channels (:data:`qzs.engine.channels.CHANNELS`) and the two flags. The value
reference of a variable is its index in :func:`fmu_variables`; :func:`variables_header`
writes the same table as C (``qzs_fmu_variables.h``) for ``csrc/qzs_fmu.c``.
"""
from dataclasses import asdict, dataclass

from qzs.engine.channels import CHANNELS, FLAGS
from qzs.model.excitation import (E_AMPLITUDE, E_DURATION, E_F0, E_F1, E_FADE, E_KIND,
                                  E_PHASE)
from qzs.model.registry import PARAMETERS

__all__ = ["FmuVariable", "fmu_variables", "variables_header", "UNITS", "MODES",
           "BASE_MOTIONS", "EXCITATION_KINDS"]

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
        kind = "I" if name == "stop_model" else "F"
        rows.append(dict(name=f"{info.section}.{name}", type=kind,
                         causality="parameter", unit=info.unit if info.unit in UNITS else "",
                         description=description, start=float(starts[name])))
    rows.append(dict(name="step_size", type="F", causality="parameter", unit="s",
                     description="internal integration step dt (communication steps are whole "
                                 "numbers of it)", start=float(dt)))
    rows.append(dict(name="solver", type="I", causality="parameter", unit="",
                     description=_SOLVER_DOC, start=float(solver_code)))
    if base_motion == "internal":
        E = excitation_scalars
        kinds = ", ".join(f"{code} {name}" for code, name in EXCITATION_KINDS.items())
        for suffix, index, unit, doc in (
                ("kind", E_KIND, "", f"base excitation: {kinds}"),
                ("amplitude", E_AMPLITUDE, "m", "base displacement amplitude"),
                ("f0", E_F0, "Hz", "chirp start frequency, or the sine's frequency"),
                ("f1", E_F1, "Hz", "chirp end frequency"),
                ("duration", E_DURATION, "s", "chirp sweep time"),
                ("phase", E_PHASE, "rad", "sine phase at t = 0"),
                ("fade_in", E_FADE, "s", "fade-in of the excitation (raised-cosine slope)")):
            rows.append(dict(name=f"excitation.{suffix}", type="I" if suffix == "kind" else "F",
                             causality="parameter", unit=unit, description=doc,
                             start=float(E[index])))
    else:
        for name in _BASE_INPUTS:
            _, unit, doc = CHANNELS[name]
            rows.append(dict(name=name, type="F", causality="input", unit=unit,
                             description=doc + " (input: held as stated in docs/fmu.md)",
                             start=0.0))
    if mode == "plant":
        rows.append(dict(name="motor_force", type="F", causality="input", unit="N",
                         description="motor force on the payload (input, held over the step)",
                         start=0.0))
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


def variables_header(variables, *, mode, base_motion, token):
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

    Returns
    -------
    str
        C source.
    """
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
        f"#define QZS_FMU_N_VARIABLES {n}\n\n"
        f"enum {{\n{enum}\n}};\n\n"
        f"static const char QZS_FMU_TYPES[] = {_c_string(''.join(v.type for v in variables))};\n"
        f"static const char QZS_FMU_CAUSALITY[] = {_c_string(causality)};\n"
        f"static const double QZS_FMU_START[] = {{{starts}}};\n"
        f"static const int QZS_FMU_CHANNEL[] = {{{channels}}};\n"
        f"static const char *const QZS_FMU_NAMES[] = {{\n{names}\n}};\n\n"
        "#endif /* QZS_FMU_VARIABLES_H */\n")
