"""Every exception and warning class of qzs.

Each error subclasses a built-in so that ``except ValueError`` keeps working, as
python-control's ``exception.py`` does. Errors carry data as attributes where a
caller may act on it (:class:`CaseError`, :class:`MissingDependencyError`); the
message is for people, never for parsing.
"""

__all__ = ["ParameterError", "ExcitationError", "StabilityError", "CaseError",
           "SimulationError", "DataError", "FitError", "MissingDependencyError",
           "DataWarning", "FitWarning"]


class ParameterError(ValueError):
    """A parameter, option or input value is invalid (names it, its value and the fix)."""


class ExcitationError(ParameterError):
    """An excitation definition or a displacement record is invalid."""


class StabilityError(ParameterError):
    """The chosen time step is too large for the explicit integrator to be stable."""


class CaseError(ParameterError):
    """One case of a batch is invalid.

    Attributes
    ----------
    index : int
        Position of the case in the batch [-], counted from 0.
    reason : str
        Why that case is invalid (the message of the underlying error).
    """

    def __init__(self, index, reason):
        self.index = int(index)
        self.reason = str(reason)
        super().__init__(f"case {self.index}: {self.reason}")

    def __reduce__(self):  # picklable with its attributes (Dask, process pools)
        return type(self), (self.index, self.reason)


class SimulationError(RuntimeError):
    """A simulation diverged or produced non-finite values (names the time and state)."""


class DataError(ValueError):
    """An input data file or signal is malformed (missing channel, bad time base, NaN)."""


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

    def __init__(self, package, extra, feature):
        self.package, self.extra, self.feature = package, extra, feature
        super().__init__(f"{feature} needs the optional package {package!r}, which is not "
                         f"installed; install it with: pip install \"qzs[{extra}]\"",
                         name=package)

    def __reduce__(self):
        return type(self), (self.package, self.extra, self.feature)


class DataWarning(UserWarning):
    """Input data were usable only after a repair (NaN interpolated, averages reduced...)."""


class FitWarning(UserWarning):
    """A fit converged but some parameters are poorly determined by the data."""
