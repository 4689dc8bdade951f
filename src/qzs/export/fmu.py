"""``qzs.export_fmu``: the isolator as an FMI 2.0 or 3.0 co-simulation FMU.

The FMU is a zip archive with ``modelDescription.xml``, ``sources/`` (qzs's C model,
``csrc/``, its FMI interface, the generated variable table and, for FMI 3.0,
``buildDescription.xml``: an importer can build it for another platform) and
``binaries/<platform>/<model identifier>.<so|dylib|dll>``, compiled here with the system C
compiler against the FMI headers of the standard's distribution as FMPy ships them (the
``fmu`` extra). No Python inside: the binary steps the same fixed-step scheme, stick-slip
events, stops and sampled controller as :func:`qzs.simulate` (docs/fmu.md).
"""
import copy
import dataclasses
import datetime
import math
import platform
import shutil
import sys
import tempfile
import uuid
import zipfile
from pathlib import Path

from qzs import defaults
from qzs._optional import require
from qzs.engine import kernels as K
from qzs.engine.prepare import prepare_run
from qzs.engine.run_spec import resolve
from qzs.engine.stability import SOLVERS
from qzs.errors import (ControllerRateError, ParameterError, StabilityError,
                        UnresolvedExcitationError)
from qzs.export.clayout import check_c_model
from qzs.export.csource import CFLAGS, compile_shared, source_folder
from qzs.export.fmu_variables import BASE_MOTIONS, MODES, fmu_variables, variables_header
from qzs.export.fmu_xml import build_description, model_description
from qzs.iotools.files import atomic_path
from qzs.iotools.paths import check_output_path
from qzs.model.controller import ControllerParameters
from qzs.model.excitation import Chirp, Sine
from qzs.model.isolator import IsolatorParameters, other_spring_law

__all__ = ["export_fmu", "fmi_headers", "platform_folder", "default_stop_time", "FMU_SOURCES",
           "FMI_VERSIONS", "DEFAULT_STOP_TIME", "DEFAULT_COMMUNICATION_STEP"]

FMI_VERSIONS = (2, 3)
#: The C files of the FMU's model, from ``csrc/``, and the interface of each FMI version.
FMU_SOURCES = ("qzs_controller.c", "qzs_spring.c", "qzs_plant.c", "qzs_model.c",
               "qzs_stability.c", "qzs_fmu.c")
FMU_HEADERS = ("qzs_controller.h", "qzs_spring.h", "qzs_plant.h", "qzs_model.h",
               "qzs_stability.h", "qzs_fmu.h")
#: The default experiment's stop time [s] of an FMU whose excitation has no length of its own
#: (a sine, base-motion inputs), as ``qzs simulate`` runs a sine.
DEFAULT_STOP_TIME = 10.0
#: The default experiment's communication step [s] (or the internal step, if larger).
DEFAULT_COMMUNICATION_STEP = 1e-3
INTERFACE = {2: "fmi2_api.c", 3: "fmi3_api.c"}
#: The FMI headers each version's interface is compiled against (FMPy's ``c-code``).
HEADERS = {2: ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h"),
           3: ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h")}
VARIABLES_HEADER = "qzs_fmu_variables.h"


def fmi_headers(fmi_version):
    """The folder of the FMI headers of ``fmi_version``, from the installed FMPy.

    Parameters
    ----------
    fmi_version : {2, 3}
        FMI version.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    MissingDependencyError
        FMPy is not installed (``pip install "qzs[fmu]"``).
    """
    fmpy = require("fmpy", "exporting an FMU (the FMI headers of the standard)")
    folder = Path(fmpy.__file__).parent / "c-code"
    missing = [name for name in HEADERS[fmi_version] if not (folder / name).is_file()]
    if missing:
        raise ParameterError(f"the installed FMPy ({folder}) has no {', '.join(missing)}; "
                             "update it: pip install -U fmpy")
    return folder


def platform_folder(fmi_version):
    """The ``binaries/`` subfolder of this platform: FMI 3 ``x86_64-linux``, FMI 2 ``linux64``.

    Parameters
    ----------
    fmi_version : {2, 3}
        FMI version.

    Returns
    -------
    str
    """
    machine = platform.machine().lower()
    machine = {"amd64": "x86_64", "arm64": "aarch64"}.get(machine, machine)
    system = {"win32": "windows", "darwin": "darwin"}.get(sys.platform, "linux")
    if fmi_version == 3:
        return f"{machine}-{system}"
    bits = "64" if sys.maxsize > 2 ** 32 else "32"
    return {"windows": "win", "darwin": "darwin", "linux": "linux"}[system] + bits


def _library_suffix():
    return {"win32": ".dll", "darwin": ".dylib"}.get(sys.platform, ".so")


def default_stop_time(excitation):
    """The default experiment's stop time [s]: the excitation's length, else
    :data:`DEFAULT_STOP_TIME` (a sine, base-motion inputs: ``excitation`` None).

    Parameters
    ----------
    excitation : Chirp, Sine or None
        The internal excitation.

    Returns
    -------
    float
    """
    if excitation is None or excitation.duration is None:
        return DEFAULT_STOP_TIME
    return float(excitation.duration)


def _communication_step(communication_step, dt, duration):
    """The default experiment's communication step [s], checked: positive, finite, within the
    stop time (any such step: the FMU splits a grid step at a communication point)."""
    if communication_step is None:
        return max(DEFAULT_COMMUNICATION_STEP, dt if isinstance(dt, (int, float)) else 0.0)
    if not (isinstance(communication_step, (int, float)) and not isinstance(
            communication_step, bool) and 0.0 < communication_step < math.inf):
        raise ParameterError(
            f"`communication_step` must be a positive number of seconds, got "
            f"{communication_step!r}; e.g. {DEFAULT_COMMUNICATION_STEP:g} (the default).",
            ("communication_step",))
    if isinstance(duration, (int, float)) and 0.0 < duration < communication_step:
        raise ParameterError(
            f"`communication_step` ({communication_step!r} s) must not exceed `duration` "
            f"({duration!r} s), the default experiment's stop time; shorten the step or "
            "lengthen the experiment.", ("communication_step", "duration"))
    return float(communication_step)


def _check_excitation(excitation, base_motion):
    """The internal excitation: a Chirp or a Sine that moves the base; None with inputs."""
    if base_motion == "input":
        if excitation is not None:
            raise ParameterError("`excitation` must be None with base_motion='input' (the base "
                                 "motion comes from the FMU's inputs).", ("excitation",))
        return None
    excitation = Chirp() if excitation is None else excitation
    if not isinstance(excitation, (Chirp, Sine)):
        raise ParameterError(
            f"`excitation` must be a Chirp or a Sine for an internal base motion, got "
            f"{type(excitation).__name__}; export with base_motion='input' (--base-motion "
            "input) and feed the record as base displacement, velocity and acceleration.",
            ("excitation",))
    if isinstance(excitation, Sine) and not excitation.frequency > 0.0:
        raise ParameterError(
            f"`frequency` of the FMU's sine must be positive, got {excitation.frequency!r} Hz: "
            "a sine of 0 Hz does not move the base; give its frequency in Hz (e.g. 3), or "
            "amplitude 0 for a base at rest.", ("frequency",))
    return excitation


def _named(error):
    """``error`` renamed for the export (the output rate is the communication step's
    reciprocal), with the arguments it names as its options where it names them in its text
    only (a step unstable or too coarse, a controller rate), so that the command line can
    spell them as its flags (:meth:`ParameterError.renamed`)."""
    if not error.options:
        named = {StabilityError: ("dt",), ControllerRateError: ("controller_rate", "sample_rate"),
                 UnresolvedExcitationError: (getattr(error, "name", ""), "dt")}
        for kind, options in named.items():
            if isinstance(error, kind):
                error = copy.copy(error)
                error.options = tuple(option for option in options if option)
                break
    return error.renamed({"sample_rate": "1/communication_step"})


def _check_choices(fmi_version, mode, base_motion, model_identifier):
    if fmi_version not in FMI_VERSIONS:
        raise ParameterError(f"`fmi_version` must be 2 or 3, got {fmi_version!r}.")
    if mode not in MODES:
        raise ParameterError(f"`mode` must be one of {', '.join(MODES)}, got {mode!r}.")
    if base_motion not in BASE_MOTIONS:
        raise ParameterError(f"`base_motion` must be one of {', '.join(BASE_MOTIONS)}, got "
                             f"{base_motion!r}.")
    if not (model_identifier.isidentifier() and model_identifier.isascii()):
        raise ParameterError(f"`model_identifier` must be a C identifier, got "
                             f"{model_identifier!r}.")


def export_fmu(path: str | Path, excitation: Chirp | Sine | None = None,
               isolator: IsolatorParameters | None = None,
               controller: ControllerParameters | None = None, *, fmi_version: int = 3,
               mode: str = "closed-loop",
               base_motion: str = "internal", dt: float | None = None,
               tolerance: float | None = None, tolerance_state: float | None = None,
               step: str = "literal",
               solver: str = defaults.SIMULATION["solver"], duration: float | None = None,
               communication_step: float | None = None, model_identifier: str = "isolator",
               argument: str = "path") -> Path:
    """Write the isolator as an FMI co-simulation FMU, compiled for this platform.

    Parameters
    ----------
    path : str or Path
        The ``.fmu`` file to write (atomically).
    excitation : Chirp or Sine, optional
        The internal base excitation (its parameters become the FMU's ``excitation.*``);
        default the paper's chirp. Not used with ``base_motion="input"``.
    isolator : IsolatorParameters, optional
        Plant parameters (the start values); Table 1 defaults if omitted. A spring law other
        than the tanh (``spring``) is the FMU's, its kind fixed and its numbers parameters
        (``spring.*``, docs/fmu.md).
    controller : ControllerParameters, optional
        PI and damping loops; defaults if omitted (in ``plant`` mode only the setpoint and
        the charge amplifier's high-pass are used).
    fmi_version : {3, 2}
        FMI version.
    mode : {"closed-loop", "plant"}
        The PI + damping inside, or the motor force as an input.
    base_motion : {"internal", "input"}
        The excitation inside, or base displacement, velocity and acceleration as inputs.
    dt : float, optional
        A literal internal integration step [s] (the FMU takes any communication step on its
        grid: docs/fmu.md §4).
    tolerance, tolerance_state : float, optional
        Or the tolerance [dB] or [m] the step is chosen for, on the internal excitation, as
        :func:`qzs.simulate` chooses it (the run is resolved by :func:`qzs.resolve`, its
        output rate the communication rate).
    step : {"literal", "chosen"}
        The step given neither ``dt`` nor a tolerance, as for :func:`qzs.resolve`: the
        paper's 1e-4 s (the Python functions' rule: a script's numbers never depend on a
        search), or the default accuracy (``qzs export fmu``'s default, as ``qzs simulate``'s);
        with base-motion inputs (no excitation to probe) always literal. The FMU warns when
        an importer sets ``step_size`` above it (docs/fmu.md §7).
    solver : {"ode3", "rk4", "euler"}
        Integrator.
    duration : float, optional
        The default experiment's stop time [s]; default the excitation's length
        (:data:`DEFAULT_STOP_TIME`, 10 s, for a sine or base-motion inputs).
    communication_step : float, optional
        The default experiment's communication step [s], any positive one up to
        ``duration``; default 1 ms (or ``dt`` if larger).
    model_identifier : str
        Name of the binary (a C identifier).
    argument : str
        How the caller names ``path`` in messages.

    Returns
    -------
    Path
        The FMU written.

    Raises
    ------
    ParameterError
        Invalid input (checked before anything is compiled), named as the argument; a sine
        of 0 Hz; ``StabilityError`` for a ``dt`` too large for the configuration.
    MissingDependencyError
        FMPy (the FMI headers) is not installed.
    CompilerError
        No C compiler, or it failed.
    CModelMismatchError
        The shipped C model's indices or checks are not the Python side's
        (:func:`qzs.export.clayout.check_c_model`).
    """
    path = check_output_path(path, argument=argument, suffixes=(".fmu",))
    _check_choices(fmi_version, mode, base_motion, model_identifier)
    check_c_model()  # the C sources copied below are the Python side's, index for index
    excitation = _check_excitation(excitation, base_motion)
    probe: Chirp | Sine = (excitation if excitation is not None
                           else Sine(amplitude=0.0, fade_in=0.0))
    if duration is None:
        duration = default_stop_time(excitation)
    communication = _communication_step(communication_step, dt, duration)
    if controller is not None and mode == "plant":  # the importer's controller makes the force
        controller = dataclasses.replace(controller, controller_rate=0.0, compensation=None,
                                         dither=None, linear=None)
    # the run resolved as qzs.simulate resolves it: its step literal or chosen, once, with the
    # communication rate as the output rate
    try:
        resolved = resolve(probe, isolator, controller, duration=duration, dt=dt,
                           tolerance=tolerance, tolerance_state=tolerance_state,
                           sample_rate=1.0 / communication, solver=solver,
                           step=step if base_motion == "internal" else "literal")
        dt = resolved.dt
        # every check qzs.simulate makes, at an output every step: any communication step
        run = prepare_run(**{**resolved.arguments(), "sample_rate": 1.0 / dt})
    except ParameterError as error:
        raise _named(error) from None
    headers = fmi_headers(fmi_version)
    law = other_spring_law(run.isolator)
    variables = fmu_variables(isolator=run.isolator, controller=run.controller,
                              excitation_scalars=run.packed[0], dt=dt,
                              solver_code=SOLVERS[solver][0], mode=mode, base_motion=base_motion,
                              model=run.model, blocks_state=run.state[K.A_X0:K.A_X0 + K.N_X])
    token = "{" + str(uuid.uuid4()) + "}"
    sources = (*FMU_SOURCES, INTERFACE[fmi_version])
    description = (f"qzs single-axis QZS isolator, {mode}, base motion {base_motion} "
                   f"({'FMI 3.0' if fmi_version == 3 else 'FMI 2.0'} co-simulation); internal "
                   f"step {resolved.step.line()}; any communication step is taken (a grid step "
                   "that a communication point falls inside is split there: a step of whole "
                   "internal steps reproduces qzs simulate)")
    generated = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    with tempfile.TemporaryDirectory(prefix="qzs-fmu-") as folder:
        root = Path(folder)
        (root / "sources").mkdir()
        for name in (*sources, *FMU_HEADERS):
            shutil.copyfile(source_folder() / name, root / "sources" / name)
        (root / "sources" / VARIABLES_HEADER).write_text(
            variables_header(variables, mode=mode, base_motion=base_motion, token=token,
                             step=resolved.step, model=run.model if mode == "closed-loop" else None,
                             spring=None if law is None else law.pack(), fmi_version=fmi_version),
            encoding="utf-8")
        if fmi_version == 3:
            (root / "sources" / "buildDescription.xml").write_text(
                build_description(model_identifier=model_identifier, sources=sources),
                encoding="utf-8")
        (root / "modelDescription.xml").write_text(model_description(
            variables, fmi_version=fmi_version, model_identifier=model_identifier, token=token,
            description=description, dt=dt, stop_time=run.duration, step=communication,
            sources=sources,
            generated=generated), encoding="utf-8")
        binaries = root / "binaries" / platform_folder(fmi_version)
        binaries.mkdir(parents=True)
        compile_shared([root / "sources" / name for name in sources],
                       binaries / f"{model_identifier}{_library_suffix()}",
                       flags=(*CFLAGS, "-fvisibility=hidden"),
                       include=[root / "sources", headers])
        with atomic_path(path) as partial:
            with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as archive:
                for file in sorted(root.rglob("*")):
                    if file.is_file():
                        archive.write(file, file.relative_to(root).as_posix())
    return path
