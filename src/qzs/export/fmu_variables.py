"""The variables of the isolator FMU: one table, read by the model description and the C.

Every registry parameter (:data:`qzs.model.registry.PARAMETERS`) is an FMI parameter with its
SI unit, description and start value (the exported configuration's); so are the run's step
and solver and, with an internal excitation, the chirp or sine of the base (units from the
registry, :func:`qzs.model.registry.unit_of`), and a spring law other than the tanh's fields
(``spring.*``: its kind and sizes fixed at export, its numbers parameters; an array one
scalar per element, ``spring.positions[1]``, an FMI 3 array variable in the model
description). The inputs are the motor force (``plant``
mode, starting at the force that holds the setpoint: :func:`holding_force`) or the base
motion (``input`` base motion); the outputs are the recorded channels
(:data:`qzs.engine.channels.CHANNELS`) and the two flags. The value reference of a variable is
its index in :func:`fmu_variables`; :func:`variables_header` writes the same table as C
(``qzs_fmu_variables.h``) for ``csrc/qzs_fmu.c``, with what the C checks the step against.
"""
import dataclasses
from dataclasses import asdict, dataclass

import numpy as np

from qzs.engine import kernels as K
from qzs.engine.channels import CHANNELS, FLAGS, run_channels
from qzs.engine.prepare import MIN_STEPS_PER_PERIOD
from qzs.model.sensors import SENSORS
from qzs.model.excitation import (E_AMPLITUDE, E_DURATION, E_F0, E_F1, E_FADE, E_KIND,
                                  E_PHASE)
from qzs.model.isolator import other_spring_law, spring_force
from qzs.model.registry import PARAMETERS, unit_of
from qzs.model.springs import OUTSIDE_RULES, TABLE, TABLE_OUTSIDE, TANH

__all__ = ["FmuVariable", "fmu_variables", "variables_header", "holding_force", "UNITS",
           "MODES", "BASE_MOTIONS", "EXCITATION_KINDS", "EXCITATION_VARIABLES",
           "PLANT_UNUSED", "SPRING_POSITION", "SPRING_FORCE"]

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
    "J": {"kg": 1, "m": 2, "s": -2}, "1/s": {"s": -1},
}
#: Where a block parameter goes in the C model's packed blocks (``K.M_*``): its index, or
#: one of these codes plus an index (``qzs_fmu.c``).
MODEL_TWO_PI = 1000  # the index's entry is 2*pi times the value (a frequency [Hz] as [rad/s])
MODEL_INITIAL_STATE = 2000  # a linear controller's state at t = 0
MODEL_SAMPLE_TIME = 3000  # a discrete linear controller's period [s], as whole steps
#: Where a spring law's parameter goes (``qzs_fmu.c``): its index in the packed law
#: (:meth:`qzs.model.springs.SpringLaw.pack`), or a table's point k as one of these plus k
#: (the C packs the table's pieces from its points at initialisation).
SPRING_POSITION = 1000
SPRING_FORCE = 2000
#: The unit of a linear controller's feedthrough from each sensor [N per sensor unit].
_FEEDTHROUGH_UNITS = {"position_error": "N/m", "measured_payload_velocity": "N*s/m",
                      "payload_acceleration": "kg", "base_acceleration": "kg",
                      "relative_velocity": "N*s/m"}
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
    model : int
        Where a controller block's parameter goes in the packed blocks (``K.M_*`` index,
        :data:`MODEL_TWO_PI`, :data:`MODEL_INITIAL_STATE` or :data:`MODEL_SAMPLE_TIME` plus
        an index), -1 for none.
    spring : int
        Where a spring law's parameter goes (an index in the packed law, or
        :data:`SPRING_POSITION` or :data:`SPRING_FORCE` plus a table's point), -1 for none.
    array : str
        The array an element belongs to (``spring.positions`` of ``spring.positions[2]``: one
        FMI 3 array variable), ``""`` for a scalar.
    """

    name: str
    reference: int
    type: str
    causality: str
    unit: str
    description: str
    start: float | None
    channel: int = -1
    model: int = -1
    spring: int = -1
    array: str = ""

    @property
    def macro(self):
        """Its value reference's C name (``QZS_VR_EXCITATION_F0``, ``..._A_1_2`` for
        ``a[1,2]``)."""
        name = self.name.upper().replace(".", "_").replace("[", "_").replace(",", "_")
        return "QZS_VR_" + name.replace("]", "")


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


def _block_parameters(isolator, controller, model, blocks_state):
    """The controller blocks' parameters (rows of :func:`fmu_variables`): the compensation's
    fraction, law, deadband and observer, the dither, a linear controller's matrices (the
    columns of the sensors it reads), anti-windup gain, states at t = 0 and sample time."""
    rows = []

    def add(name, unit, description, start, where):
        rows.append(dict(name=f"controller.{name}", type="F", causality="parameter",
                         unit=unit, description=description, start=float(start), model=where))

    compensation = controller.compensation
    if compensation is not None:
        add("compensation.fraction", "", "fraction of the friction law the motor cancels, in "
            "[0, 1.5]", compensation.fraction, K.M_COMP_FRACTION)
        law = compensation.law(isolator)
        for (name, unit, doc), value, index in zip(
                (("stiction_force", "N", "stiction force Fs'"),
                 ("coulomb_force", "N", "Coulomb force Fc'"),
                 ("stribeck_decay", "s/m", "Stribeck decay Cbc'"),
                 ("viscous_damping", "N*s/m", "viscous damping Cv'")),
                law, (K.M_COMP_FS, K.M_COMP_FC, K.M_COMP_CBC, K.M_COMP_CV)):
            add(f"compensation.{name}", unit, f"the compensator's {doc} (exported: the plant's "
                "where the compensation set none; it does not follow the isolator's)", value,
                index)
        add("compensation.deadband", "m/s", "velocity deadband of the compensation",
            compensation.deadband, K.M_COMP_DEADBAND)
        add("compensation.observer_bandwidth", "Hz", "friction observer bandwidth (0: none)",
            compensation.observer_bandwidth, MODEL_TWO_PI + K.M_OBSERVER_RATE)
    if controller.dither is not None:
        add("dither.amplitude", "N", "dither force amplitude", controller.dither.amplitude,
            K.M_DITHER_AMPLITUDE)
        add("dither.frequency", "Hz", "dither frequency", controller.dither.frequency,
            MODEL_TWO_PI + K.M_DITHER_OMEGA)
    linear = controller.linear
    if linear is not None:
        n = linear.states
        kind = "discrete: x <- A x + B u" if linear.discrete else "continuous: x' = A x + B u"
        for i in range(n):
            for j in range(n):
                add(f"linear.a[{i + 1},{j + 1}]", "" if linear.discrete else "1/s",
                    f"the linear controller's state matrix A ({kind})",
                    model[K.M_A + i * K.NX_MAX + j], K.M_A + i * K.NX_MAX + j)
        for sensor in linear.inputs:
            k = list(SENSORS).index(sensor)
            for i in range(n):
                add(f"linear.b_{sensor}[{i + 1}]", "", f"the linear controller's input matrix "
                    f"B, column of {sensor} (its unit: the state's per the sensor's)",
                    model[K.M_B + i * K.N_SENSORS + k], K.M_B + i * K.N_SENSORS + k)
        for i in range(n):
            add(f"linear.c[{i + 1}]", "", "the linear controller's output matrix C "
                "(force per state [N per the state's unit])", model[K.M_C + i], K.M_C + i)
        for sensor in linear.inputs:
            k = list(SENSORS).index(sensor)
            add(f"linear.d_{sensor}", _FEEDTHROUGH_UNITS[sensor], "the linear controller's "
                f"feedthrough D from {sensor}", model[K.M_D + k], K.M_D + k)
        for i in range(n):
            add(f"linear.antiwindup[{i + 1}]", "", "the back-calculation anti-windup gain L "
                "(docs/model.md §5.1; exported from tracking_time)", model[K.M_ANTIWINDUP + i],
                K.M_ANTIWINDUP + i)
        for i in range(n):
            add(f"linear.initial_state[{i + 1}]", "", "the linear controller's state at t = 0 "
                "(exported: at equilibrium with its sensors, as qzs starts it; set it with the "
                "matrices; loaded before the PI's preload, which nets its output)",
                blocks_state[i], MODEL_INITIAL_STATE + i)
        if linear.discrete:
            add("linear.sample_time", "s", "the discrete linear controller's period, a whole "
                "number of step_size", linear.sample_time, MODEL_SAMPLE_TIME)
    return rows


def _spring_parameters(law):
    """A spring law's parameters (rows of :func:`fmu_variables`): its fields with their units
    and descriptions (qzs.model.springs), an array's elements one row each."""
    if law.code == TABLE:
        rows = [dict(name="spring.outside", type="I", causality="parameter", unit="",
                     description="outside the table: 0 refuse (the run stops with an error), 1 "
                                 "extend (linear with the end slope)",
                     start=float(OUTSIDE_RULES.index(law.outside)), spring=TABLE_OUTSIDE)]
        for field, where, doc in (("positions", SPRING_POSITION, "relative positions of the "
                                   "table, strictly increasing (PCHIP, docs/model.md §3.1)"),
                                  ("forces", SPRING_FORCE, "forces on the payload at the "
                                   "positions, upward positive")):
            unit = "m" if field == "positions" else "N"
            rows += [dict(name=f"spring.{field}[{k + 1}]", type="F", causality="parameter",
                          unit=unit, description=doc, start=float(value), spring=where + k,
                          array=f"spring.{field}")
                     for k, value in enumerate(getattr(law, field))]
        return rows
    packed = law.pack()
    if law.kind == "polynomial":
        rows = [dict(name="spring.center", type="F", causality="parameter", unit="m",
                     description="position the powers are taken about", start=float(packed[1]),
                     spring=1)]
        return rows + [dict(name=f"spring.coefficients[{k + 1}]", type="F",
                            causality="parameter", unit="",
                            description="coefficient c_k of (z - center)^k, ascending from c_0 "
                                        "[N], c_1 [N/m], ... (c_k in N/m^k)",
                            start=float(value), spring=3 + k, array="spring.coefficients")
                       for k, value in enumerate(law.coefficients)]
    return [dict(name=f"spring.{f.name}", type="F", causality="parameter",
                 unit=f.metadata["unit"], description=f.metadata["doc"] + " (the "
                 f"{law.kind} spring law, docs/model.md §3.1)", start=float(packed[1 + i]),
                 spring=1 + i)
            for i, f in enumerate(dataclasses.fields(law))]


def fmu_variables(*, isolator, controller, excitation_scalars, dt, solver_code, mode,
                  base_motion, model=None, blocks_state=None):
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
    model : ndarray, optional
        The controller's blocks packed for the kernels (``K.M_*``,
        :func:`qzs.engine.prepare.pack_model`); needed when it has blocks (closed loop).
    blocks_state : ndarray, optional
        The blocks' states at t = 0 (``K.X_*``, as the run starts them).

    Returns
    -------
    tuple of FmuVariable
    """
    rows = [dict(name="time", type="F", causality="independent", unit="s",
                 description="simulation time", start=None)]
    starts = _parameter_starts(isolator, controller)
    law = other_spring_law(isolator)
    for name, info in PARAMETERS.items():
        description = info.doc
        if name == "stop_model":
            description += " (0 compliant, 1 plastic)"
        if name == "stop_center":
            description = "centre of the stops in z (exported: the setpoint if none was set)"
        if mode == "plant" and name in PLANT_UNUSED:
            description += " (not used in plant mode: the motor force is the input)"
        if law is not None and name in ("spring_force", "spring_shape"):
            description += f" (not used: the spring is the exported {law.kind} law, spring.*)"
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
    if law is not None:
        rows += _spring_parameters(law)
    blocks = mode == "closed-loop" and controller.has_blocks
    if blocks:
        rows += _block_parameters(isolator, controller, model, blocks_state)
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
    for name, (column, unit, doc) in (run_channels(controller) if blocks else CHANNELS).items():
        if name not in skipped:
            rows.append(dict(name=name, type="F", causality="output", unit=unit,
                             description=doc, start=None, channel=column))
    for name, (flag, doc) in FLAGS.items():
        rows.append(dict(name=name, type="B", causality="output", unit="", description=doc,
                         start=None, channel=100 + flag))
    return tuple(FmuVariable(reference=i, **row) for i, row in enumerate(rows))


def _c_string(text):
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _sizes(variables, fmi_version):
    """How many values each value reference holds: an FMI 3 array's length at its first
    element and 0 (no variable) at the others; 1 for every other variable."""
    sizes = []
    for i, v in enumerate(variables):
        if fmi_version == 3 and v.array:
            first = i == 0 or variables[i - 1].array != v.array
            sizes.append(sum(1 for w in variables if w.array == v.array) if first else 0)
        else:
            sizes.append(1)
    return sizes


def variables_header(variables, *, mode, base_motion, token, step=None, model=None,
                     spring=None, fmi_version=2):
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
    model : ndarray, optional
        The exported controller's blocks packed (``K.M_*``): the C model's blocks, which the
        block parameters overwrite at initialisation; None or all zeros for none.
    spring : ndarray, optional
        A spring law other than the tanh, packed (:meth:`qzs.model.springs.SpringLaw.pack`):
        its kind and size, which the spring parameters fill at initialisation; None for the
        tanh of ``isolator.spring_force`` and ``isolator.spring_shape``.
    fmi_version : {2, 3}
        FMI version: FMI 3 addresses an array by its first element's value reference.

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
    blocks = model is not None and model[K.M_BLOCKS] != 0.0
    base = ", ".join(repr(float(value)) for value in (model if blocks else [0.0]))
    where = ", ".join(str(v.model) for v in variables)
    law = np.array([float(TANH), 0.0, 0.0]) if spring is None else np.asarray(spring)
    points = int(law[2]) if law[0] == TABLE else 0
    spring_where = ", ".join(str(v.spring) for v in variables)
    base_law = ", ".join(repr(float(x)) for x in law)
    sizes = ", ".join(str(n) for n in _sizes(variables, fmi_version))
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
        f"#define QZS_FMU_MIN_STEPS_PER_PERIOD {MIN_STEPS_PER_PERIOD}\n"
        f"#define QZS_FMU_BLOCKS {int(blocks)}\n"
        f"#define QZS_FMU_MODEL_TWO_PI {MODEL_TWO_PI}\n"
        f"#define QZS_FMU_MODEL_INITIAL_STATE {MODEL_INITIAL_STATE}\n"
        f"#define QZS_FMU_MODEL_SAMPLE_TIME {MODEL_SAMPLE_TIME}\n"
        f"#define QZS_FMU_SPRING_LAW {int(law[0])}\n"
        f"#define QZS_FMU_SPRING_SIZE {law.size}\n"
        f"#define QZS_FMU_SPRING_POINTS {points}\n"
        f"#define QZS_FMU_SPRING_POSITION {SPRING_POSITION}\n"
        f"#define QZS_FMU_SPRING_FORCE {SPRING_FORCE}\n\n"
        f"enum {{\n{enum}\n}};\n\n"
        f"static const char QZS_FMU_TYPES[] = {_c_string(''.join(v.type for v in variables))};\n"
        f"static const char QZS_FMU_CAUSALITY[] = {_c_string(causality)};\n"
        f"static const double QZS_FMU_START[] = {{{starts}}};\n"
        f"static const int QZS_FMU_CHANNEL[] = {{{channels}}};\n"
        "/* the controller's blocks as exported (QZS_M_*; unused without blocks), and where\n"
        " * each block parameter goes in them (-1: none) */\n"
        f"static const double QZS_FMU_MODEL_BASE[] = {{{base}}};\n"
        f"static const int QZS_FMU_MODEL[] = {{{where}}};\n"
        "/* the spring law as exported (QZS_FMU_SPRING_LAW 0: the tanh of the isolator's\n"
        " * parameters), where each spring parameter goes in it (-1: none), and how many values\n"
        " * each value reference holds (an FMI 3 array's elements follow its first) */\n"
        f"static const double QZS_FMU_SPRING_BASE[] = {{{base_law}}};\n"
        f"static const int QZS_FMU_SPRING[] = {{{spring_where}}};\n"
        f"static const int QZS_FMU_SIZE[] = {{{sizes}}};\n"
        f"static const char *const QZS_FMU_NAMES[] = {{\n{names}\n}};\n\n"
        "#endif /* QZS_FMU_VARIABLES_H */\n")
