"""The sampled controller as one dependency-free C file for a real-time target.

:func:`controller_source` writes ``csrc/qzs_controller.h`` and ``qzs_controller.c`` -- the very
code the C model's closed loop and the closed-loop FMU call -- as one C99 file (no include
but its own text, no libm), followed by the configuration it was exported from: the gains,
the saturation, the sample period (``period_steps * step_time``) and the PI preload qzs
starts a run with. On a target::

    QzsController controller;
    qzs_controller_init(&controller, &QZS_CONTROLLER_EXPORTED, QZS_CONTROLLER_PRELOAD);
    every period:  F = qzs_controller_step(&controller, z, v_measured).motor;

where ``v_measured`` is the charge amplifier's high-passed absolute payload velocity (a
sensor of the plant, as in docs/model.md §5). Fed the samples of a qzs run, its commands
are the run's, sample for sample (tests/export/test_controller.py).
"""
from pathlib import Path

from qzs import defaults
from qzs._version import __version__
from qzs.engine import kernels as K
from qzs.engine.prepare import prepare_run
from qzs.errors import ParameterError
from qzs.export.csource import source_text
from qzs.iotools.files import atomic_path
from qzs.iotools.paths import check_output_path
from qzs.model.controller import ControllerParameters
from qzs.model.excitation import Sine
from qzs.model.isolator import IsolatorParameters

__all__ = ["controller_source", "export_controller", "exported_parameters"]

#: The name of the exported parameter set in the C file.
PARAMETERS_NAME = "QZS_CONTROLLER_EXPORTED"
PRELOAD_NAME = "QZS_CONTROLLER_PRELOAD"


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
    if controller is None:
        controller = ControllerParameters(controller_rate=1000.0)
    if not isinstance(controller, ControllerParameters):
        raise ParameterError(f"`controller` must be a ControllerParameters, got "
                             f"{type(controller).__name__}.")
    if controller.controller_rate <= 0.0:
        raise ParameterError(
            "`controller_rate` is 0 (a continuous controller); the C controller is sampled: "
            "give its rate, e.g. `--set controller_rate=1000` (Hz).")
    at_rest = Sine(amplitude=0.0, frequency=1.0, fade_in=0.0)
    run = prepare_run(at_rest, isolator, controller, duration=dt, dt=dt, sample_rate=1.0 / dt)
    p = run.params
    parameters = {"position_setpoint": p[K.P_ZREF], "pi_kp": p[K.P_KP], "pi_ki": p[K.P_KI],
                  "damping_gain": p[K.P_KD], "motor_force_max": p[K.P_FMAX],
                  "period_steps": p[K.P_CONTROL_STEPS], "step_time": p[K.P_DT]}
    return parameters, float(run.state[K.S_INT])


def controller_source(controller=None, isolator=None, *, dt=defaults.SIMULATION["dt"]):
    """The controller as one C file: qzs_controller.h and .c, then the exported parameters.

    Parameters
    ----------
    controller : ControllerParameters, optional
        A sampled controller; default the defaults at 1 kHz.
    isolator : IsolatorParameters, optional
        The plant (for the PI preload); default Table 1.
    dt : float
        Integration step [s] of the qzs run it reproduces (:func:`exported_parameters`).

    Returns
    -------
    str
        C99 source.
    """
    parameters, preload = exported_parameters(controller, isolator, dt=dt)
    header = source_text("qzs_controller.h")
    body = source_text("qzs_controller.c").replace('#include "qzs_controller.h"\n', "")
    values = "\n".join(f"    {float(value)!r},  /* {name} */"
                       for name, value in parameters.items())
    period = float(parameters["period_steps"] * parameters["step_time"])
    return (f"/* controller.c: exported by qzs {__version__} (`qzs export controller`).\n"
            " * One file: qzs_controller.h, qzs_controller.c and the parameters of the "
            "configuration\n * it was exported from. Compile with any C99 compiler; it "
            "needs no library. */\n"
            f"{header}\n{body}\n"
            f"/* The exported configuration: sample period {period!r} s. */\n"
            f"const QzsControllerParameters {PARAMETERS_NAME} = {{\n{values}\n}};\n"
            f"/* The PI integral qzs starts a run with [m*s] (the static load's preload). */\n"
            f"const double {PRELOAD_NAME} = {preload!r};\n")


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
