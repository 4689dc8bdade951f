"""What the FMU tests share (tests/export/test_fmu*.py): an export made once per module
folder, FMPy runs with the inputs a qzs run recorded, FMI instances whose log is kept, and
the comparison of channels.

Not a test module: imported as ``export.fmu_support`` (tests/ is on the path, as for
``helpers``).
"""
import numpy as np
import pytest

import qzs
from qzs.engine.channels import CHANNELS
from qzs.errors import CompilerError
from qzs.export import fmu as export
from qzs.export.csource import find_compiler

fmpy = pytest.importorskip("fmpy")
from fmpy import extract, read_model_description  # noqa: E402
from fmpy.fmi1 import FMICallException  # noqa: E402
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE  # noqa: E402
from fmpy.fmi3 import FMU3Slave  # noqa: E402

try:  # every module that imports this one compiles FMUs
    find_compiler()
except CompilerError:  # pragma: no cover
    pytest.skip("no C compiler", allow_module_level=True)

#: The base-motion inputs of an FMU exported with ``base_motion="input"``.
BASE_INPUTS = ("base_displacement", "base_velocity", "base_acceleration")


def exported(folder, name, **kwargs):
    """``folder/name.fmu``, exported with ``kwargs`` the first time it is asked for."""
    path = folder / f"{name}.fmu"
    if not path.exists():
        export.export_fmu(path, **kwargs)
    return path


def compare(result, reference, channels=None):
    """The largest difference of each channel over its range: {channel: value}."""
    out = {}
    for name in channels or [c for c in CHANNELS if c != "time"]:
        ours = np.asarray(reference[name])
        theirs = np.asarray(result[name])
        out[name] = np.abs(theirs - ours).max() / (np.ptp(ours) or 1.0)
    return out


def recorded_inputs(reference, step, *, motor=False, base=False):
    """FMPy's input signal that replays a qzs run sampled every ``step`` [s] at its samples
    t_k: the base motion as
    recorded at t_k, and the motor force the run held over [t_k, t_k+1], recorded at t_k+1
    (docs/fmu.md §5); None if neither is asked for. The times are k*h, as FMPy computes its
    communication points (the run's own k*decimation*dt may differ in the last bit, and FMPy
    would then interpolate between two samples)."""
    time = np.arange(len(reference.time)) * step
    columns = {}
    if base:
        for name in BASE_INPUTS:
            columns[name] = np.asarray(reference[name])
    if motor:
        force = np.asarray(reference.motor_force)
        columns["motor_force"] = np.append(force[1:], force[-1])
    if not columns:
        return None
    signal = np.zeros(time.size, dtype=[("time", float)] + [(n, float) for n in columns])
    signal["time"] = time
    for name, values in columns.items():
        signal[name] = values
    return signal


def starts(path):
    """{name: ScalarVariable} of an FMU's model description."""
    return {v.name: v for v in read_model_description(str(path)).modelVariables}


class Logged:
    """An FMI 3 (``version=3``) or FMI 2 co-simulation instance whose log messages are kept:
    ``get``/``set`` by name, ``failing`` asserts an error status with a logged reason."""

    def __init__(self, path, version=3):
        description = read_model_description(str(path))
        self.refs = {v.name: v.valueReference for v in description.modelVariables}
        self.version = version
        self.messages = []
        arguments = dict(guid=description.guid, unzipDirectory=extract(str(path)),
                         modelIdentifier=description.coSimulation.modelIdentifier)
        if version == 3:
            self.fmu = FMU3Slave(**arguments)

            def log(environment, status, category, message):
                self.messages.append((status, category.decode(), message.decode()))
            self.fmu.instantiate(loggingOn=True, logMessage=log)
        else:
            self.fmu = FMU2Slave(**arguments)

            def log2(environment, name, status, category, message):
                self.messages.append((status, category.decode(), message.decode()))
            callbacks = fmi2CallbackFunctions()
            callbacks.logger = fmi2CallbackLoggerTYPE(log2)
            callbacks.allocateMemory = fmpy.fmi2.fmi2CallbackAllocateMemoryTYPE(fmpy.calloc)
            callbacks.freeMemory = fmpy.fmi2.fmi2CallbackFreeMemoryTYPE(fmpy.free)
            self._callbacks = callbacks
            self.fmu.instantiate(callbacks=callbacks, loggingOn=True)

    def enter(self, stop_time=None):
        """Enter initialisation (the experiment from t = 0, to ``stop_time`` if given)."""
        if self.version == 3:
            self.fmu.enterInitializationMode(startTime=0.0, stopTime=stop_time)
        else:
            self.fmu.setupExperiment(startTime=0.0, stopTime=stop_time)
            self.fmu.enterInitializationMode()

    def set(self, **values):
        """Set Float64 (Real) variables by name (``.`` written ``__``), in one call."""
        names = [name.replace("__", ".") for name in values]
        refs = [self.refs[name] for name in names]
        setter = self.fmu.setFloat64 if self.version == 3 else self.fmu.setReal
        setter(refs, list(values.values()))

    def get(self, *names):
        getter = self.fmu.getFloat64 if self.version == 3 else self.fmu.getReal
        return getter([self.refs[name] for name in names])

    def failing(self, call, *args):
        """Call, assert it fails with status error and a logged error; its message."""
        before = len(self.messages)
        with pytest.raises(FMICallException) as caught:
            call(*args)
        assert caught.value.status == 3
        assert len(self.messages) > before and self.messages[-1][0] == 3
        return self.messages[-1][2]

    def warnings(self):
        """The messages logged with status warning."""
        return [message for status, _, message in self.messages if status == 1]

    def free(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


#: The excitations of the matrix of FMUs (tests/export/test_fmu_matrix.py), exported with
#: defaults; None: the base motion as inputs.
EXCITATIONS = {
    "chirp-linear": qzs.Chirp(amplitude=0.01, f1=5.0, duration=4.0),
    "chirp-log": qzs.Chirp(amplitude=0.01, f0=0.5, f1=10.0, duration=4.0, method="logarithmic",
                           fade_in=1.0),
    "sine": qzs.Sine(amplitude=0.008, frequency=3.0),
    "input": None,
}


def matrix_exporter(folder):
    """``get(excitation, mode, version)``: the FMU of :data:`EXCITATIONS` ``[excitation]``
    exported with defaults into ``folder``, the first time it is asked for."""
    def get(excitation, mode="closed-loop", version=3):
        source = EXCITATIONS[excitation]
        return exported(folder, f"{excitation}-{mode}-{version}", excitation=source,
                        fmi_version=version, mode=mode,
                        base_motion="internal" if source is not None else "input")
    return get
