"""Errors that carry data (qzs.errors): attributes a caller can act on, kept through pickling
(process pools, Dask), each error a subclass of the built-in its callers already catch."""
import pickle

import pytest

import qzs
from qzs import errors
from qzs.errors import CaseError, ParameterError


def test_a_failing_case_is_named_by_an_attribute_not_by_text():
    cases = [(qzs.IsolatorParameters(), qzs.ControllerParameters()),
             (qzs.IsolatorParameters(stop_stiffness=1e12), qzs.ControllerParameters())]
    with pytest.raises(CaseError) as error:
        qzs.simulate_batch(cases, qzs.Chirp(duration=1.0), sample_rate=100.0)
    assert error.value.index == 1 and "largest stable step" in error.value.reason
    assert isinstance(error.value, ParameterError)
    copy = pickle.loads(pickle.dumps(error.value))  # crosses process and Dask boundaries
    assert (copy.index, copy.reason) == (error.value.index, error.value.reason)


#: One instance of every error class that carries data, and the attributes it carries.
CARRIERS = [
    (errors.CaseError(3, "too stiff"), {"index": 3, "reason": "too stiff"}),
    (errors.SizeLimitError("duration", 1e9, 0.1, 600.0, "s"),
     {"name": "duration", "value": 1e9, "low": 0.1, "high": 600.0, "unit": "s"}),
    (errors.OutputPathError("--out", "x.txt", "has an unknown extension"),
     {"argument": "--out", "value": "x.txt", "reason": "has an unknown extension"}),
    (errors.ResumeMismatchError("seed", 4, 5, "s.zarr"),
     {"option": "seed", "stored": 4, "asked": 5, "store": "s.zarr"}),
    (errors.ResultTooLargeError(2 ** 30, 2 ** 20, 2000.0, 1000.0),
     {"needed": 2 ** 30, "available": 2 ** 20, "duration": 2000.0, "sample_rate": 1000.0}),
    (errors.RunTooLongError(steps=10 ** 15, seconds=1e7, limit=1e4, duration=100.0, dt=1e-13),
     {"steps": 10 ** 15, "limit": 1e4, "duration": 100.0, "dt": 1e-13}),
    (errors.WriteError("run.nc", "No space left on device"),
     {"reason": "No space left on device"}),
    (errors.MissingDependencyError("zarr", "cluster", "writing sweep stores"),
     {"package": "zarr", "extra": "cluster"}),
    (errors.Terminated(15), {"signum": 15, "exit_code": 143}),
    (errors.HelperProcessError("qzs-figure", -9), {"name": "qzs-figure", "exitcode": -9}),
    (errors.CompilerError("gcc", "was not found"), {"compiler": "gcc", "reason": "was not found"}),
    (errors.CModelMismatchError([("QZS_P_VREG", 21, "kernels.P_VREG = 22")]),
     {"mismatches": (("QZS_P_VREG", 21, "kernels.P_VREG = 22"),)}),
    (errors.ExcitationError("`f_low` must be below `f_high`", ("f_low", "f_high")),
     {"options": ("f_low", "f_high")}),
    (errors.UnresolvedExcitationError(frequency=4000.0, dt=1e-4, minimum=10),
     {"frequency": 4000.0, "dt": 1e-4, "minimum": 10, "name": "frequency"}),
    (errors.ControllerRateError(controller_rate=333.0, sample_rate=1000.0, step=1e-3,
                                refinement=32, suggestions=(250.0, 500.0)),
     {"controller_rate": 333.0, "sample_rate": 1000.0, "refinement": 32,
      "suggestions": (250.0, 500.0)}),
]


@pytest.mark.parametrize("error, attributes", CARRIERS, ids=lambda v: type(v).__name__)
def test_errors_keep_their_data_and_message_through_pickling(error, attributes):
    copy = pickle.loads(pickle.dumps(error))
    assert type(copy) is type(error) and str(copy) == str(error)
    for name, value in attributes.items():
        assert getattr(error, name) == value and getattr(copy, name) == value, name


def test_each_error_is_caught_by_its_built_in():
    """``except ValueError`` catches bad input, ``except RuntimeError`` a failed run,
    ``except ImportError`` a missing extra; SIGTERM is not swallowed by ``except Exception``."""
    expected = {"ParameterError": ValueError, "DataError": ValueError,
                "SimulationError": RuntimeError, "FitError": RuntimeError,
                "CompilerError": RuntimeError, "CModelMismatchError": RuntimeError,
                "HelperProcessError": ChildProcessError,
                "MissingDependencyError": ImportError, "DataWarning": UserWarning}
    for name, base in expected.items():
        assert issubclass(getattr(errors, name), base), name
    for name in errors.__all__:
        if name.endswith("Error") and name not in expected:
            assert issubclass(getattr(errors, name), (ParameterError, errors.DataError)), name
    assert not issubclass(errors.Terminated, Exception)
    assert issubclass(errors.Terminated, BaseException)


def test_an_excitation_error_names_its_options_the_callers_way():
    error = errors.ExcitationError("`f_low` (30 Hz) must be below `f_high` (10 Hz)",
                                   ("f_low", "f_high"))
    renamed = error.renamed({"f_low": "--f0", "f_high": "--f1"})
    assert str(renamed) == "`--f0` (30 Hz) must be below `--f1` (10 Hz)"
    assert renamed.options == ("--f0", "--f1") and isinstance(renamed, ParameterError)
    assert str(error.renamed({"other": "--x"})) == str(error)  # the others keep their name
