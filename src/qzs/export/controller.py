"""The sampled controller, with its blocks, as one C file for a real-time target.

:func:`controller_source` writes ``csrc/qzs_controller.h`` and ``qzs_controller.c`` -- the very
laws the C model's closed loop and the closed-loop FMU call -- as one C99 file (no include but
its own text and the C library's ``math.h``, ``stdint.h``, ``string.h``; link with libm),
followed by the configuration it was exported from: the gains, the saturation, the sample
period (``period_steps * step_time``), the blocks packed as qzs packs them (``QZS_M_*``,
docs/model.md §5.1) and the state qzs starts a run with. On a target::

    QzsBlockController controller;
    qzs_block_controller_init(&controller, &QZS_BLOCK_CONTROLLER_EXPORTED,
                              QZS_CONTROLLER_PRELOAD, &QZS_BLOCK_CONTROLLER_STATES,
                              &QZS_BLOCK_CONTROLLER_HELD);
    every period:  F = qzs_block_controller_step(&controller, &sensors).motor;

with ``sensors`` what the rig measures (``QzsSensors``: time, encoder position and slip
velocity, the charge amplifier's high-passed payload velocity, the accelerations, and for a
friction observer the friction force the payload's balance gives). A controller without blocks
is also written for the PI + damping's own step, ``qzs_controller_step(&controller, z,
v_measured)`` (``QZS_CONTROLLER_EXPORTED``); with blocks that set is left out, so that no code
can run the PI alone by mistake. Fed the samples of a qzs run, its forces are the run's, sample
for sample (tests/export/test_controller.py, test_controller_blocks.py).

A continuous ``LinearController`` is refused: qzs integrates it with the plant, and its
zero-order-hold discretisation would be another controller than the one simulated; discretise
it at the controller's period and simulate that (the error says how).
"""
from pathlib import Path

from qzs import defaults
from qzs._version import __version__
from qzs.engine import kernels as K
from qzs.engine.prepare import prepare_run
from qzs.errors import ParameterError
from qzs.export.clayout import check_c_model
from qzs.export.csource import source_text
from qzs.iotools.files import atomic_path
from qzs.iotools.paths import check_output_path
from qzs.model.controller import ControllerParameters
from qzs.model.excitation import Sine
from qzs.model.isolator import IsolatorParameters

__all__ = ["controller_source", "export_controller", "exported_parameters", "exported_blocks"]

#: The name of the exported PI + damping parameter set in the C file (without blocks only).
PARAMETERS_NAME = "QZS_CONTROLLER_EXPORTED"
#: The PI integral qzs starts a run with [m*s].
PRELOAD_NAME = "QZS_CONTROLLER_PRELOAD"
#: The exported controller with its blocks, its blocks' initial states and held forces.
BLOCK_PARAMETERS_NAME = "QZS_BLOCK_CONTROLLER_EXPORTED"
BLOCK_STATES_NAME = "QZS_BLOCK_CONTROLLER_STATES"
BLOCK_HELD_NAME = "QZS_BLOCK_CONTROLLER_HELD"
#: The fields of ``QzsBlockOutput`` (qzs_controller.h), in order, and the state entry each
#: holds at t = 0 (``K.A_*``; the estimate is the observer's state).
HELD_FIELDS = (("pi", K.A_F_PI), ("damping", K.A_F_DAMP),
               ("compensation", K.A_F_COMPENSATION), ("dither", K.A_F_DITHER),
               ("linear", K.A_F_LINEAR), ("motor", K.A_F_MOTOR),
               ("friction_estimate", K.A_X0 + K.X_OBSERVER))


def exported_parameters(controller=None, isolator=None, *, dt=defaults.SIMULATION["dt"]):
    """The controller's C parameters and PI preload, as a qzs run at step ``dt`` has them.

    Parameters
    ----------
    controller : ControllerParameters, optional
        A sampled controller (``controller_rate > 0``); default the defaults at 1 kHz.
    isolator : IsolatorParameters, optional
        The plant (its static load sets the PI preload); default Table 1.
    dt : float
        The integration step [s] of the run the controller is checked against; the sample
        period is a whole number of it.

    Returns
    -------
    parameters : dict
        The fields of ``QzsControllerParameters`` (qzs_controller.h), in order.
    preload : float
        The PI integral at t = 0 [m*s] (docs/model.md §11).

    Raises
    ------
    ParameterError
        A continuous controller, or a rate that is not a whole number of steps.
    """
    p, state, _ = _prepared(controller, isolator, dt)
    parameters = {"position_setpoint": p[K.P_ZREF], "pi_kp": p[K.P_KP], "pi_ki": p[K.P_KI],
                  "damping_gain": p[K.P_KD], "motor_force_max": p[K.P_FMAX],
                  "period_steps": p[K.P_CONTROL_STEPS], "step_time": p[K.P_DT]}
    return parameters, float(state[K.S_INT])


def exported_blocks(controller=None, isolator=None, *, dt=defaults.SIMULATION["dt"]):
    """The controller's blocks as the C file has them, and their state at t = 0.

    Parameters
    ----------
    controller : ControllerParameters, optional
        A sampled controller (``controller_rate > 0``); a linear controller among its blocks
        must be discrete with the controller's sample period. Default the defaults at 1 kHz.
    isolator : IsolatorParameters, optional
        The plant (the compensator's law where it sets none, the friction sign's
        regularisation); default Table 1.
    dt : float
        The integration step [s] of the run the controller is checked against.

    Returns
    -------
    velocity_regularisation : float
        ``v_reg`` [m/s] of the compensator's friction sign (0: the exact sign).
    model : ndarray, shape (K.N_MODEL,)
        The blocks packed (``K.M_*``, qzs.engine.prepare.pack_model; zeros without blocks).
    states : ndarray, shape (K.N_X,)
        The blocks' states at t = 0 (a linear controller's, the observer's estimate [N]).
    held : dict
        The forces held at t = 0 [N] (``QzsBlockOutput``'s fields, in order).

    Raises
    ------
    ParameterError
        As :func:`exported_parameters`; a continuous linear controller, or a discrete one
        whose period is not the controller's.
    """
    p, state, model = _prepared(controller, isolator, dt)
    held = {name: float(state[index]) for name, index in HELD_FIELDS}
    return float(p[K.P_VREG]), model, state[K.A_X0:K.A_X0 + K.N_X].copy(), held


def _prepared(controller, isolator, dt):
    """The packed parameters, initial state and blocks of ``controller`` at rest, checked."""
    if controller is None:
        controller = ControllerParameters(controller_rate=1000.0)
    if not isinstance(controller, ControllerParameters):
        raise ParameterError(f"`controller` must be a ControllerParameters, got "
                             f"{type(controller).__name__}.", ("controller",))
    if controller.controller_rate <= 0.0:
        raise ParameterError(
            "`controller_rate` is 0 (a continuous controller); the C controller is sampled: "
            "give its rate, e.g. `--set controller_rate=1000` (Hz).", ("controller_rate",))
    linear = controller.linear
    if linear is not None and not linear.discrete:
        period = 1.0 / controller.controller_rate
        raise ParameterError(
            "`linear` is a continuous LinearController (sample_time = 0): qzs integrates it "
            "with the plant, and its zero-order-hold discretisation would be another "
            "controller than the one simulated, so it is not exported. Discretise it at the "
            f"controller's period and simulate that: LinearController.from_system("
            f"control.c2d(linear.to_system(), {period!r}, 'zoh'), inputs=linear.inputs).",
            ("linear",))
    at_rest = Sine(amplitude=0.0, frequency=1.0, fade_in=0.0)
    run = prepare_run(at_rest, isolator, controller, duration=dt, dt=dt, sample_rate=1.0 / dt)
    p, m = run.params, run.model
    if linear is not None and m[K.M_LINEAR_STEPS] != p[K.P_CONTROL_STEPS]:
        period = float(p[K.P_CONTROL_STEPS] * p[K.P_DT])
        raise ParameterError(
            f"`sample_time` of the LinearController ({linear.sample_time!r} s) must be the "
            f"controller's sample period ({period!r} s, controller_rate = "
            f"{controller.controller_rate!r} Hz): the exported step samples every block at "
            f"once. Give it sample_time={period!r}, or set controller_rate="
            f"{1.0 / linear.sample_time!r}.", ("sample_time",))
    return p, run.state, m


def controller_source(controller=None, isolator=None, *, dt=defaults.SIMULATION["dt"]):
    """The controller as one C file: qzs_controller.h and .c, then the exported parameters.

    Parameters
    ----------
    controller : ControllerParameters, optional
        A sampled controller, with or without blocks (:func:`exported_blocks` says which
        it refuses); default the defaults at 1 kHz.
    isolator : IsolatorParameters, optional
        The plant (for the PI preload and the compensator's law); default Table 1.
    dt : float
        Integration step [s] of the qzs run it reproduces (:func:`exported_parameters`).

    Returns
    -------
    str
        C99 source (links with libm).

    Raises
    ------
    CModelMismatchError
        The shipped C model's indices or checks are not the Python side's
        (:func:`qzs.export.clayout.check_c_model`).
    """
    check_c_model()  # qzs_controller.h's block indices are the kernels' M_*
    parameters, preload = exported_parameters(controller, isolator, dt=dt)
    regularisation, model, states, held = exported_blocks(controller, isolator, dt=dt)
    header = source_text("qzs_controller.h")
    body = source_text("qzs_controller.c").replace('#include "qzs_controller.h"\n', "")
    control = _initialiser(parameters.items(), "    ")
    period = float(parameters["period_steps"] * parameters["step_time"])
    with_blocks = bool(model[K.M_BLOCKS])
    pi_alone = "" if with_blocks else (
        "/* PI + damping alone (the controller has no blocks): qzs_controller_init/step. */\n"
        f"const QzsControllerParameters {PARAMETERS_NAME} = {{\n{control}\n}};\n")
    blocks = _initialiser(zip(_model_names(), model), "        ")
    return (f"/* controller.c: exported by qzs {__version__} (`qzs export controller`).\n"
            " * One file: qzs_controller.h, qzs_controller.c and the parameters of the "
            "configuration\n * it was exported from. Compile with any C99 compiler and link "
            "libm (-lm). */\n"
            f"{header}\n{body}\n"
            f"/* The exported configuration: sample period {period!r} s"
            f"{'' if with_blocks else ', no blocks'}. */\n{pi_alone}"
            f"/* The PI integral qzs starts a run with [m*s] (the static load's preload). */\n"
            f"const double {PRELOAD_NAME} = {preload!r};\n"
            "/* The controller with its blocks: qzs_block_controller_init/step. */\n"
            f"const QzsBlockParameters {BLOCK_PARAMETERS_NAME} = {{\n"
            f"    {{\n{_initialiser(parameters.items(), '        ')}\n    }},\n"
            f"    {regularisation!r},  /* velocity_regularisation [m/s] */\n"
            f"    {{\n{blocks}\n    }}\n}};\n"
            "/* The blocks' states at t = 0 (a linear controller's, the observer's [N]). */\n"
            f"const QzsBlocks {BLOCK_STATES_NAME} = {{{{"
            f"{', '.join(repr(float(x)) for x in states)}}}}};\n"
            "/* The forces held at t = 0 [N]. */\n"
            f"const QzsBlockOutput {BLOCK_HELD_NAME} = {{\n{_initialiser(held.items(), '    ')}"
            "\n};\n")


def _initialiser(items, indent):
    """``name, value`` pairs as the lines of a C initialiser, each value commented."""
    return "\n".join(f"{indent}{float(value)!r},  /* {name} */" for name, value in items)


def _model_names():
    """The names of the packed blocks' entries (``K.M_*``), in order, for the C file."""
    from qzs.model.sensors import SENSORS

    scalars = sorted((index, name[2:].lower()) for name, index in vars(K).items()
                     if name.startswith("M_") and isinstance(index, int) and index < K.M_A)
    names = [name for _, name in scalars]
    names += [f"A[{i}][{j}]" for i in range(K.NX_MAX) for j in range(K.NX_MAX)]
    names += [f"B[{i}][{sensor}]" for i in range(K.NX_MAX) for sensor in SENSORS]
    names += [f"C[{i}]" for i in range(K.NX_MAX)]
    names += [f"D[{sensor}]" for sensor in SENSORS]
    names += [f"antiwindup L[{i}]" for i in range(K.NX_MAX)]
    return names


def export_controller(path: str | Path, controller: ControllerParameters | None = None,
                      isolator: IsolatorParameters | None = None, *,
                      dt: float = defaults.SIMULATION["dt"], argument: str = "path") -> Path:
    """Write :func:`controller_source` to ``path`` (atomically).

    Parameters
    ----------
    path : str or Path
        The ``.c`` file to write.
    controller : ControllerParameters, optional
        A sampled controller; default the defaults at 1 kHz.
    isolator : IsolatorParameters, optional
        The plant (for the PI preload).
    dt : float
        Integration step [s] of the qzs run it reproduces.
    argument : str
        How the caller names ``path`` in messages (``--out`` on the command line).

    Returns
    -------
    Path
        The file written.
    """
    path = check_output_path(path, argument=argument, suffixes=(".c",))
    text = controller_source(controller, isolator, dt=dt)
    with atomic_path(path) as partial:
        partial.write_text(text, encoding="utf-8")
    return path
