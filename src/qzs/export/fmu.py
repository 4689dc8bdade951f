"""``qzs.export_fmu``: the isolator as an FMI 2.0 or 3.0 co-simulation FMU.

The FMU is a zip archive with ``modelDescription.xml``, ``sources/`` (qzs's C model,
``csrc/``, its FMI interface, the generated variable table and, for FMI 3.0,
``buildDescription.xml``: an importer can build it for another platform) and
``binaries/<platform>/<model identifier>.<so|dylib|dll>``, compiled here with the system C
compiler against the FMI headers of the standard's distribution as FMPy ships them (the
``fmu`` extra). No Python inside: the binary steps the same fixed-step scheme, stick-slip
events, stops and sampled controller as :func:`qzs.simulate` (docs/fmu.md).
"""
import dataclasses
import datetime
import platform
import shutil
import sys
import tempfile
import uuid
import zipfile
from pathlib import Path

from qzs import defaults
from qzs._optional import require
from qzs.engine.prepare import prepare_run
from qzs.engine.run_spec import resolve
from qzs.engine.stability import SOLVERS
from qzs.errors import ParameterError
from qzs.export.csource import CFLAGS, compile_shared, source_folder
from qzs.export.fmu_variables import BASE_MOTIONS, MODES, fmu_variables, variables_header
from qzs.export.fmu_xml import build_description, model_description
from qzs.iotools.files import atomic_path
from qzs.iotools.paths import check_output_path
from qzs.model.controller import ControllerParameters
from qzs.model.excitation import Chirp, Sine
from qzs.model.isolator import IsolatorParameters

__all__ = ["export_fmu", "fmi_headers", "platform_folder", "FMU_SOURCES", "FMI_VERSIONS"]

FMI_VERSIONS = (2, 3)
#: The C files of the FMU's model, from ``csrc/``, and the interface of each FMI version.
FMU_SOURCES = ("qzs_controller.c", "qzs_plant.c", "qzs_model.c", "qzs_fmu.c")
FMU_HEADERS = ("qzs_controller.h", "qzs_plant.h", "qzs_model.h", "qzs_fmu.h")
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
        Plant parameters (the start values); Table 1 defaults if omitted.
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
        A literal internal integration step [s]; a communication step must be a whole
        number of it.
    tolerance, tolerance_state : float, optional
        Or the tolerance [dB] or [m] the step is chosen for, on the internal excitation, as
        :func:`qzs.simulate` chooses it (the run is resolved by :func:`qzs.resolve`, its
        output rate the communication rate).
    step : {"literal", "chosen"}
        The step given neither ``dt`` nor a tolerance, as for :func:`qzs.resolve`: the
        paper's 1e-4 s, or the default accuracy (``qzs export fmu``'s default, as
        ``qzs simulate``'s); with base-motion inputs (no excitation to probe) always literal.
    solver : {"ode3", "rk4", "euler"}
        Integrator.
    duration : float, optional
        The default experiment's stop time [s]; default the excitation's length (10 s for
        a sine or base-motion inputs).
    communication_step : float, optional
        The default experiment's communication step [s]; default 1 ms (or ``dt`` if larger).
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
        Invalid input (checked before anything is compiled); ``StabilityError`` for a ``dt``
        too large for the configuration.
    MissingDependencyError
        FMPy (the FMI headers) is not installed.
    CompilerError
        No C compiler, or it failed.
    """
    path = check_output_path(path, argument=argument, suffixes=(".fmu",))
    _check_choices(fmi_version, mode, base_motion, model_identifier)
    if base_motion == "internal":
        excitation = Chirp() if excitation is None else excitation
        if not isinstance(excitation, (Chirp, Sine)):
            raise ParameterError(
                f"`excitation` must be a Chirp or a Sine for an internal base motion, got "
                f"{type(excitation).__name__}; export with base_motion='input' (--base-motion "
                "input) and feed the record as base displacement, velocity and acceleration.")
    elif excitation is not None:
        raise ParameterError("`excitation` must be None with base_motion='input' (the base "
                             "motion comes from the FMU's inputs).")
    probe: Chirp | Sine = (excitation if excitation is not None
                           else Sine(amplitude=0.0, fade_in=0.0))
    if duration is None:
        duration = probe.duration if probe.duration is not None else 10.0
    communication = (communication_step if communication_step is not None
                     else max(1e-3, dt or 0.0))
    if controller is not None and mode == "plant":
        controller = dataclasses.replace(controller, controller_rate=0.0)
    # the run resolved as qzs.simulate resolves it: its step literal or chosen, once
    resolved = resolve(probe, isolator, controller, duration=duration, dt=dt,
                       tolerance=tolerance, tolerance_state=tolerance_state,
                       sample_rate=1.0 / communication, solver=solver,
                       step=step if base_motion == "internal" else "literal")
    dt, step = resolved.dt, communication
    run = prepare_run(**resolved.arguments())  # every check qzs.simulate makes
    headers = fmi_headers(fmi_version)
    variables = fmu_variables(isolator=run.isolator, controller=run.controller,
                              excitation_scalars=run.packed[0], dt=dt,
                              solver_code=SOLVERS[solver][0], mode=mode, base_motion=base_motion)
    token = "{" + str(uuid.uuid4()) + "}"
    sources = (*FMU_SOURCES, INTERFACE[fmi_version])
    description = (f"qzs single-axis QZS isolator, {mode}, base motion {base_motion} "
                   f"({'FMI 3.0' if fmi_version == 3 else 'FMI 2.0'} co-simulation); internal "
                   f"step {resolved.step.line()}")
    generated = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    with tempfile.TemporaryDirectory(prefix="qzs-fmu-") as folder:
        root = Path(folder)
        (root / "sources").mkdir()
        for name in (*sources, *FMU_HEADERS):
            shutil.copyfile(source_folder() / name, root / "sources" / name)
        (root / "sources" / VARIABLES_HEADER).write_text(
            variables_header(variables, mode=mode, base_motion=base_motion, token=token),
            encoding="utf-8")
        if fmi_version == 3:
            (root / "sources" / "buildDescription.xml").write_text(
                build_description(model_identifier=model_identifier, sources=sources),
                encoding="utf-8")
        (root / "modelDescription.xml").write_text(model_description(
            variables, fmi_version=fmi_version, model_identifier=model_identifier, token=token,
            description=description, dt=dt, stop_time=run.duration, step=step, sources=sources,
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
