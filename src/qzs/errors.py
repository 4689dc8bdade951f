"""Every exception and warning class of qzs.

Each error subclasses a built-in so that ``except ValueError`` keeps working, as
python-control's ``exception.py`` does. Errors carry data as attributes where a
caller may act on it (:class:`CaseError`, :class:`MissingDependencyError`); the
message is for people, never for parsing.
"""

import copy
from collections.abc import Iterable, Mapping

__all__ = ["ParameterError", "ExcitationError", "StabilityError", "CaseError",
           "SimulationError", "DataError", "FitError", "MissingDependencyError",
           "OutputPathError", "ResumeMismatchError", "ResultTooLargeError", "WriteError", "ToleranceNotMetError",
           "SizeLimitError", "RunTooLongError", "UnresolvedExcitationError",
           "ControllerRateError", "CountLimitError", "InvalidCasesError",
           "SchedulerError", "AddressError", "ProblemError", "CompilerError",
           "CModelMismatchError", "Terminated",
           "HelperProcessError",
           "DataWarning", "FitWarning"]


class ParameterError(ValueError):
    """A parameter, option or input value is invalid (names it, its value and the fix).

    Parameters
    ----------
    message : str
        What is wrong, the value and the fix; each argument it is about written ```name```.
    options : tuple of str
        Those arguments (see the attribute).

    Attributes
    ----------
    options : tuple of str
        The arguments the message is about, each written ```name``` in it (empty when it
        names none in particular), so that a caller that spells them its own way (the
        command line's ``--sample-rate`` for ``sample_rate``) can say them so
        (:meth:`renamed`).
    """

    def __init__(self, message: str = "", options: Iterable[str] = ()) -> None:
        self.options = tuple(str(option) for option in options)
        super().__init__(message)

    def renamed(self, spelling: Mapping[str, str]) -> "ParameterError":
        """The same error with each of its options written as ``spelling`` says.

        Parameters
        ----------
        spelling : dict
            Option -> how the caller names it (``{"duration": "--excitation-duration"}``);
            options it leaves out keep their name.

        Returns
        -------
        ParameterError
            Of the same class, with the same attributes.
        """
        options = getattr(self, "options", ())
        if not any(option in spelling for option in options):
            return self
        message = str(self)
        for option in options:
            if option in spelling:
                message = message.replace(f"`{option}`", f"`{spelling[option]}`")
        renamed = copy.copy(self)
        renamed.args = (message,)
        renamed.options = tuple(spelling.get(o, o) for o in options)
        return renamed

    def __reduce__(self):
        return type(self), (str(self), getattr(self, "options", ()))


class ExcitationError(ParameterError):
    """An excitation definition or a displacement record is invalid.

    Parameters
    ----------
    message : str
        What is wrong, the value and the fix; each option it is about written ```name```.
    options : tuple of str
        Those options (:attr:`ParameterError.options`).
    """


class StabilityError(ParameterError):
    """The chosen time step is too large for the explicit integrator to be stable.

    Parameters
    ----------
    message : str
        The step, the stability limit and the fix.
    options : tuple of str
        The arguments it names (:attr:`ParameterError.options`).
    """


class CaseError(ParameterError):
    """One case of a batch is invalid.

    Attributes
    ----------
    index : int
        Position of the case in the batch [-], counted from 0.
    reason : str
        Why that case is invalid (the message of the underlying error).
    """

    def __init__(self, index: int, reason: str | BaseException) -> None:
        self.index = int(index)
        self.reason = str(reason)
        super().__init__(f"case {self.index}: {self.reason}")

    def __reduce__(self):  # picklable with its attributes (Dask, process pools)
        return type(self), (self.index, self.reason)


class InvalidCasesError(CaseError):
    """Cases of a sweep are invalid; found before any case runs, so none runs.

    A :class:`CaseError` whose ``index`` and ``reason`` are the first invalid case's.

    Attributes
    ----------
    cases : tuple of tuple
        ``(index, values, reason)`` per invalid case: its position [-] counted from 0, its
        varied parameters (a dict) and why it is invalid.
    total : int
        Cases in the sweep [-].
    """

    #: Invalid cases the message lists at most (the attribute holds them all).
    SHOWN = 3

    def __init__(self, cases, total):
        self.cases = tuple((int(i), dict(values), str(reason)) for i, values, reason in cases)
        self.total = int(total)
        shown = "; ".join(
            f"case {i} ({', '.join(f'{k} = {v!r}' for k, v in values.items())}): "
            f"{reason.rstrip('.')}" for i, values, reason in self.cases[:self.SHOWN])
        more = len(self.cases) - self.SHOWN
        self.index, self.reason = self.cases[0][0], self.cases[0][2]
        ParameterError.__init__(  # CaseError's attributes, a message of its own
            self, f"{len(self.cases)} of {self.total} cases are invalid, so none runs: {shown}"
                  + (f"; and {more} more" if more > 0 else "")
                  + "; fix or drop those values in the sweep file.")

    def __reduce__(self):
        return type(self), (self.cases, self.total)


class CountLimitError(ParameterError):
    """A request asks for more items (sweep cases, frequencies) than qzs runs in one go;
    raised before any is built, so it fails at once instead of after seconds of work.

    Attributes
    ----------
    name : str
        What sets the count (``--range``, ``grid``, ``samples``, ``frequencies``).
    count : int
        How many were asked for [-].
    limit : int
        The most qzs runs in one go [-].
    items : str
        What is counted (``cases``, ``frequencies``).
    fix : str
        What to do instead.
    """

    def __init__(self, name, count, limit, items, fix):
        self.name, self.count, self.limit = str(name), int(count), int(limit)
        self.items, self.fix = str(items), str(fix)
        super().__init__(f"`{self.name}` asks for {self.count:,} {self.items}, more than the "
                         f"{self.limit:,} qzs runs in one go; {self.fix}.")

    def __reduce__(self):
        return type(self), (self.name, self.count, self.limit, self.items, self.fix)


class ProblemError(ParameterError):
    """A design problem file is invalid; raised before any design is evaluated.

    Attributes
    ----------
    table : str
        The table (``variables``, ``objectives[0]``, ``uncertain.mass``).
    key : str
        The key or parameter in it ('' for the table as a whole).
    value : object
        The value given.
    fix : str
        What is wrong and what to do.
    source : str
        The file (or "problem definition"); '' until known.
    """

    def __init__(self, table: str, key: str, value: object, fix: str, source: str = "") -> None:
        self.table, self.key, self.value = str(table), str(key), value
        self.fix, self.source = str(fix).rstrip("."), str(source)
        table = self.table if "[" in self.table else f"[{self.table}]"  # objectives[0]
        where = table + (f" {self.key}" if self.key else "")
        value = self.value
        empty = value is None or (isinstance(value, (str, list, dict)) and not value)
        shown = "" if empty or (isinstance(value, str) and value == self.key) else f" = {value!r}"
        prefix = f"{self.source}: " if self.source else ""
        super().__init__(f"{prefix}{where}{shown}: {self.fix}.")

    def __reduce__(self):
        return type(self), (self.table, self.key, self.value, self.fix, self.source)


class SchedulerError(ParameterError):
    """No Dask scheduler answers at the address given; raised before any case runs.

    Attributes
    ----------
    address : str
        The scheduler's address as given (``tcp://host:8786``).
    reason : str
        What went wrong (refused, timed out, unknown host).
    """

    def __init__(self, address, reason):
        self.address, self.reason = str(address), str(reason)
        super().__init__(f"no Dask scheduler answers at `scheduler` {self.address!r}: "
                         f"{self.reason}; start one there (`dask scheduler`), check the "
                         "address, or leave out --scheduler to run here.")

    def __reduce__(self):
        return type(self), (self.address, self.reason)


class AddressError(ParameterError):
    """The tuning page cannot listen where asked: a busy port, or an address that is not
    this machine's; raised before the kernels warm up.

    Attributes
    ----------
    argument : str
        The option at fault: ``--host`` or ``--port``.
    host : str
        The address asked for.
    port : int or None
        The port asked for (None: any free one).
    reason : str
        What is wrong and the fix.
    """

    def __init__(self, argument, host, port, reason):
        self.argument, self.host, self.reason = str(argument), str(host), str(reason)
        self.port = None if port is None else int(port)
        value = self.host if self.argument == "--host" else self.port
        super().__init__(f"{self.argument} {value!r} {self.reason}.")

    def __reduce__(self):
        return type(self), (self.argument, self.host, self.port, self.reason)


class SizeLimitError(ParameterError):
    """A request asks for more than a bound allows (the tuning page's :data:`qzs.app.compute.LIMITS`
    and ``MAX_STEPS``: one request must not exhaust the machine).

    Attributes
    ----------
    name : str
        The setting (``excitation.duration``, ``frequency_count``, ``steps``, ...).
    value : float
        The value asked for, in ``unit``.
    low, high : float
        The bounds, in ``unit`` [1, s, Hz].
    unit : str
        SI unit of the setting (``1`` for a count).
    """

    def __init__(self, name: str, value: float, low: float, high: float, unit: str) -> None:
        self.name, self.value = str(name), value
        self.low, self.high, self.unit = low, high, str(unit)
        shown = "" if self.unit == "1" else f" {self.unit}"
        super().__init__(f"`{self.name}` must lie in [{self.low:g}, {self.high:g}]{shown} on "
                         f"the page, got {self.value:g}{shown}; choose a value inside it, or "
                         "run it with `qzs simulate` / `qzs response`, which have no such bound.")

    def __reduce__(self):
        return type(self), (self.name, self.value, self.low, self.high, self.unit)


class ToleranceNotMetError(ParameterError):
    """No step tried meets an accuracy tolerance (:func:`qzs.engine.accuracy.choose_step`).

    The response then depends on the step at every step tried: stop contacts or a
    stick-slip pattern that each refinement redraws.

    Attributes
    ----------
    tolerance : float
        The tolerance asked for, in ``unit``.
    unit : str
        ``"dB"`` (transmissibility) or ``"m"`` (state).
    smallest_step : float
        The finest step whose error was estimated [s] (compared with two finer ones).
    smallest_error : float
        The smallest error estimated over the steps tried, in ``unit`` (inf: none).
    safety : float
        The factor [-] the estimate had to stay below the tolerance by.
    """

    def __init__(self, tolerance: float, unit: str, smallest_step: float, smallest_error: float,
                 safety: float) -> None:
        self.tolerance = float(tolerance)
        self.unit = str(unit)
        self.smallest_step = float(smallest_step)
        self.smallest_error = float(smallest_error)
        self.safety = float(safety)
        super().__init__(
            f"no step down to {self.smallest_step:.3g} s meets the tolerance "
            f"{self.tolerance:g} {self.unit} with safety {self.safety:g} on the probe (smallest "
            f"estimated error {self.smallest_error:.3g} {self.unit}); loosen the tolerance or "
            "raise `max_halvings`.")

    def __reduce__(self):
        return type(self), (self.tolerance, self.unit, self.smallest_step, self.smallest_error,
                            self.safety)


class OutputPathError(ParameterError):
    """An output path cannot be written (extension, folder, permissions, free space).

    Raised by :func:`qzs.iotools.paths.check_output_path` before any long work starts.

    Attributes
    ----------
    argument : str
        The option or parameter that named the path (``"--out"``, ``"out"``).
    value : str
        The path as given.
    reason : str
        What is wrong and the fix.
    """

    def __init__(self, argument: str, value: object, reason: str) -> None:
        self.argument, self.value, self.reason = str(argument), str(value), str(reason)
        super().__init__(f"{self.argument} {self.value!r} {self.reason}.")

    def __reduce__(self):
        return type(self), (self.argument, self.value, self.reason)


class ResumeMismatchError(ParameterError):
    """A search resumed with another setting than its store was started with.

    The optimiser would ask for other designs than the stored ones (another seed draws
    another first generation, another population another size); raised before any design
    is evaluated.

    Attributes
    ----------
    option : str
        The setting (``seed``, ``population``); on the command line ``--<option>``.
    stored : object
        The value the store was started with.
    asked : object
        The value asked for now.
    store : str
        The store's path.
    """

    def __init__(self, option: str, stored: object, asked: object, store: object) -> None:
        self.option, self.stored, self.asked, self.store = str(option), stored, asked, str(store)
        super().__init__(
            f"`{self.option}` (--{self.option}) = {asked!r} is not the {stored!r} the store "
            f"{self.store!r} was started with, so the search would ask for other designs than "
            f"it holds; resume with --{self.option} {stored!r}, or start again with "
            f"--overwrite.")

    def __reduce__(self):
        return type(self), (self.option, self.stored, self.asked, self.store)


class ResultTooLargeError(ParameterError):
    """A run's result would not fit in memory; raised before the run starts.

    Attributes
    ----------
    needed : int
        Memory the result would take [bytes].
    available : int
        Memory available now [bytes].
    duration : float
        The run's simulated time [s].
    sample_rate : float
        The run's output rate [Hz].
    remedy : str
        What to do instead, the message's end (default: stream the run to a file).
    """

    #: The advice of a single run's message.
    STREAM = ("stream it to a file instead (`--out FILE.nc` on the command line, "
              "`qzs.simulate_to_file` in Python), or lower the `sample_rate` or the `duration`")

    def __init__(self, needed: int, available: int, duration: float, sample_rate: float,
                 remedy: str | None = None) -> None:
        self.needed, self.available = int(needed), int(available)
        self.duration, self.sample_rate = float(duration), float(sample_rate)
        self.remedy = str(remedy) if remedy is not None else self.STREAM
        gib = 1024 ** 3
        super().__init__(
            f"a {self.duration:g} s run at {self.sample_rate:g} Hz keeps "
            f"{self.needed / gib:.2f} GiB of samples, more than half the {self.available / gib:.2f} "
            f"GiB of memory available; {self.remedy}.")

    def __reduce__(self):
        return type(self), (self.needed, self.available, self.duration, self.sample_rate,
                            self.remedy)


class RunTooLongError(ParameterError):
    """A run would take absurdly long (more than a day at best); raised before it starts.

    Attributes
    ----------
    steps : int
        Integration steps the run would take [-].
    seconds : float
        Wall time it would take at the kernel's best speed [s] (a lower bound).
    limit : float
        The longest run qzs starts [s].
    duration : float
        The run's simulated time [s].
    dt : float
        Its integration step [s].
    cases : int
        Cases stepped together [-].
    """

    def __init__(self, *, steps, seconds, limit, duration, dt, cases=1):
        self.steps, self.seconds, self.limit = int(steps), float(seconds), float(limit)
        self.duration, self.dt, self.cases = float(duration), float(dt), int(cases)
        of = f" of {self.cases} cases" if self.cases > 1 else ""
        super().__init__(
            f"`dt` = {self.dt:g} s over `duration` = {self.duration:g} s is {self.steps:.3g} "
            f"integration steps{of}: at least {_span(self.seconds)} of computing even at the "
            f"kernel's best speed, and qzs starts no run of more than {_span(self.limit)}; use "
            "a larger `dt` (the paper's is 1e-4 s; qzs.largest_stable_step gives the largest "
            "stable one) or a shorter `duration`.", ("dt", "duration"))

    def __reduce__(self):
        return _rebuild_keywords, (type(self), dict(
            steps=self.steps, seconds=self.seconds, limit=self.limit, duration=self.duration,
            dt=self.dt, cases=self.cases))


class UnresolvedExcitationError(ParameterError):
    """The integration step is too coarse for the excitation's frequency; raised before the run.

    A fixed-step integrator needs several steps per period of the base motion to follow it:
    at 2.5 steps per period of a 4000 Hz sine (dt = 1e-4 s) the energy ledger is 15 % off,
    and a 1e9 Hz sine diverges.

    Attributes
    ----------
    frequency : float
        The excitation's highest frequency within the run [Hz].
    dt : float
        The integration step [s].
    minimum : int
        The fewest steps per period a run is started with [-].
    name : str
        The excitation's option that sets the frequency (``frequency``, ``f1``, ...).
    """

    def __init__(self, *, frequency, dt, minimum, name="frequency"):
        self.frequency, self.dt = float(frequency), float(dt)
        self.minimum, self.name = int(minimum), str(name)
        finest = 1.0 / (self.minimum * self.frequency)
        super().__init__(
            f"the excitation reaches {self.frequency:g} Hz (`{self.name}`), where `dt` = "
            f"{self.dt:g} s gives {1.0 / (self.frequency * self.dt):.3g} integration steps per "
            f"period, fewer than the {self.minimum} a run needs to follow it; lower `{self.name}` "
            f"to at most {1.0 / (self.minimum * self.dt):.3g} Hz, or reduce `dt` to at most "
            f"{finest:.3g} s.")

    def __reduce__(self):
        return _rebuild_keywords, (type(self), dict(
            frequency=self.frequency, dt=self.dt, minimum=self.minimum, name=self.name))


class ControllerRateError(ParameterError):
    """A sampled controller's rate shares a step with the output rate only at a far finer step.

    Every step must divide both the output period and the controller's: 333 Hz against a
    1000 Hz output needs 1/333000 s, a run hundreds of times longer than at the stable
    step. Raised before any run, by :func:`qzs.engine.accuracy.admissible_step`.

    Attributes
    ----------
    controller_rate : float
        The controller's rate [Hz].
    sample_rate : float
        The output rate [Hz].
    step : float
        The largest step stability and the output rate allow [s].
    refinement : int
        How much finer than ``step`` the search went [-].
    suggestions : tuple of float
        Rates [Hz] near ``controller_rate`` that divide the output rate or are whole
        multiples of it.
    """

    def __init__(self, *, controller_rate, sample_rate, step, refinement, suggestions=()):
        self.controller_rate, self.sample_rate = float(controller_rate), float(sample_rate)
        self.step, self.refinement = float(step), int(refinement)
        self.suggestions = tuple(float(f) for f in suggestions)
        near = " or ".join(f"{f:g}" for f in self.suggestions)
        super().__init__(
            f"`controller_rate` ({self.controller_rate:g} Hz) and the output rate "
            f"`sample_rate` ({self.sample_rate:g} Hz) share no integration step down to "
            f"{self.refinement} times finer than the stable {self.step:.3g} s: every run would "
            f"take that much longer or more; choose a controller rate that divides the output "
            f"rate or is a whole multiple of it" + (f" (e.g. {near} Hz)" if near else "")
            + ", or 0 for a continuous controller.")

    def __reduce__(self):
        return _rebuild_keywords, (type(self), dict(
            controller_rate=self.controller_rate, sample_rate=self.sample_rate, step=self.step,
            refinement=self.refinement, suggestions=self.suggestions))


def _rebuild_keywords(kind, keywords):
    return kind(**keywords)


def _span(seconds):
    """A wall time in the largest unit that keeps it at least 1 (s, min, h, days, years)."""
    for unit, size in (("year", 365.25 * 86400), ("day", 86400), ("h", 3600), ("min", 60)):
        if seconds >= size:
            value = seconds / size
            plural = "s" if unit in ("year", "day") and f"{value:.3g}" != "1" else ""
            return f"{value:.3g} {unit}{plural}"
    return f"{seconds:.3g} s"


class SimulationError(RuntimeError):
    """A simulation diverged or produced non-finite values (names the time and state)."""


class DataError(ValueError):
    """An input data file or signal is malformed (missing channel, bad time base, NaN)."""


class WriteError(DataError):
    """A file could not be written (disk full, permissions, read-only file system).

    Nothing is left behind: the temporary file is removed and the target untouched.

    Attributes
    ----------
    path : Path
        The file being written.
    reason : str
        What went wrong (``"the disk is full"``, ``"permission denied"``, ...).
    message : str, optional
        The message for people; default ``cannot write <path>: <reason>.``
    """

    def __init__(self, path, reason, message=None):
        from pathlib import Path

        self.path, self.reason = Path(path), str(reason)
        super().__init__(message or f"cannot write {str(self.path)!r}: {self.reason}.")

    def __reduce__(self):
        return type(self), (self.path, self.reason, str(self))


class FitError(RuntimeError):
    """A least-squares fit did not converge, or its inputs cannot determine the parameters."""


class MissingDependencyError(ImportError):
    """An optional dependency is not installed.

    Attributes
    ----------
    package : str
        The missing distribution (``pip install`` name).
    extra : str
        The qzs extra that installs it: ``pip install "qzs[<extra>]"``.
    feature : str
        What needs it (e.g. "reading MF4 logs").
    """

    def __init__(self, package: str, extra: str, feature: str) -> None:
        self.package, self.extra, self.feature = package, extra, feature
        super().__init__(f"{feature} needs the optional package {package!r}, which is not "
                         f"installed; install it with: pip install \"qzs[{extra}]\"",
                         name=package)

    def __reduce__(self):
        return type(self), (self.package, self.extra, self.feature)


class CompilerError(RuntimeError):
    """The system C compiler is missing, or failed to build qzs's C sources.

    Parameters
    ----------
    compiler : str
        The compiler asked for (``$CC``, else ``cc``/``gcc``).
    reason : str
        Why: not found on ``PATH``, or the compiler's own messages.
    fix : str, optional
        What to do; default: install a compiler or name it in ``CC``.

    Attributes
    ----------
    compiler, reason, fix : str
        As given.
    """

    def __init__(self, compiler: str, reason: str, fix: str | None = None) -> None:
        if fix is None:
            fix = ("install one (gcc or clang: e.g. `apt install gcc`, Xcode's command line "
                   "tools) or name it in the CC environment variable")
        self.compiler, self.reason, self.fix = compiler, reason, fix
        super().__init__(f"the C compiler {compiler!r} {reason}; {fix}.")

    def __reduce__(self):
        return type(self), (self.compiler, self.reason, self.fix)


class CModelMismatchError(RuntimeError):
    """qzs's C model (``qzs/export/csrc``) is not the numba side it copies: a packed index
    (``QZS_P_*``, ``QZS_S_*``, ...) with another value or on one side only, or a registry
    parameter that ``qzs_fmu.c`` does not read or checks with another bound. Raised before
    anything is exported (:func:`qzs.export.clayout.check_c_model`).

    Parameters
    ----------
    mismatches : tuple of (str, object, object)
        Each difference: the index or parameter (``QZS_P_VREG``, ``isolator.mass``), the C
        side (its value; None where C has none) and the Python side (None where it has none).

    Attributes
    ----------
    mismatches : tuple of (str, object, object)
        As given.
    """

    def __init__(self, mismatches) -> None:
        self.mismatches = tuple(tuple(m) for m in mismatches)
        shown = "; ".join(f"{name}: C {'has none' if c is None else repr(c)}, Python "
                          f"{'has none' if py is None else py}"
                          for name, c, py in self.mismatches)
        super().__init__(f"qzs's C model does not match the Python side it copies ({shown}); "
                         "make src/qzs/export/csrc (its headers' indices, qzs_fmu.c's packing "
                         "and REQUIRE checks) say what the Python side says, then run "
                         "tests/export.")

    def __reduce__(self):
        return type(self), (self.mismatches,)


class Terminated(BaseException):
    """The process received a termination signal (SIGTERM) and unwinds to exit.

    A ``BaseException``, like ``KeyboardInterrupt``, so that ``except Exception``
    does not swallow it while ``finally`` blocks and context managers still run
    (atomic writers remove their temporary files). :func:`qzs.cli.main` raises it
    from its SIGTERM handler and exits with :attr:`exit_code`.

    Attributes
    ----------
    signum : int
        The signal's number (15 for SIGTERM).
    """

    def __init__(self, signum=15):
        self.signum = int(signum)
        super().__init__(f"terminated by signal {self.signum}")

    @property
    def exit_code(self):
        """The shell's convention for a death by signal: 128 + the signal's number [-]."""
        return 128 + self.signum

    def __reduce__(self):
        return type(self), (self.signum,)


class HelperProcessError(ChildProcessError):
    """A helper process (:mod:`qzs.workflows.forked`) ended without sending its job's
    outcome (killed, or never told the job); the caller does the job itself.

    Attributes
    ----------
    name : str
        The helper's process name.
    exitcode : int or None
        Its exit code (negative: the signal that ended it), None if not known.
    """

    def __init__(self, name, exitcode=None):
        self.name = str(name)
        self.exitcode = exitcode
        super().__init__(f"the helper process {self.name!r} ended without an answer (exit "
                         f"code {exitcode}); the job is to be done in this process instead.")

    def __reduce__(self):
        return type(self), (self.name, self.exitcode)


class DataWarning(UserWarning):
    """Input data were usable only after a repair (NaN interpolated, averages reduced...)."""


class FitWarning(UserWarning):
    """A fit converged but some parameters are poorly determined by the data."""
