"""Exception classes of qzs.

Every error subclasses a built-in so that ``except ValueError`` keeps working,
as python-control's ``exception.py`` does.
"""


class ParameterError(ValueError):
    """A parameter, option or input value is invalid (names it, its value and the fix)."""


class ExcitationError(ParameterError):
    """An excitation definition or a displacement record is invalid."""


class StabilityError(ParameterError):
    """The chosen time step is too large for the explicit integrator to be stable."""


class SimulationError(RuntimeError):
    """A simulation diverged or produced non-finite values (names the time and state)."""


class DataError(ValueError):
    """An input data file or signal is malformed (missing channel, bad time base, NaN)."""
