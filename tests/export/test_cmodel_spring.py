"""The C model runs every spring law as the numba kernels do, bit for bit (issue 41).

An oblique-spring QZS at its quasi-zero condition, a cubic polynomial and a table sampled from
the tanh that extends: every recorded channel of :func:`qzs.simulate` equals the C closed
loop's to the bit, with the same stick events. A table that refuses positions outside it stops
the C run where the kernel stops (status outside, the same step and last state). The C
evaluator (``qzs_spring_evaluate``) is the kernels' and
:func:`qzs.model.springs.evaluate_packed` at positions inside, outside and on a table's
breakpoints, its table packing (``qzs_spring_table``) is
:class:`~qzs.model.springs.TabulatedSpring`'s (PCHIP slopes, pieces, energies) on a measured-like
curve with extrema, flat steps and sign changes, and its stiffness peak is
:func:`qzs.engine.stability.spring_stiffness_peak`'s (what an FMU's step is checked against).
"""
import ctypes

import numpy as np
import pytest
from helpers import (EXPORT_LEAVING_SINE, EXPORT_REFUSING_TABLE, EXPORT_SETTINGS,
                     EXPORT_SPRING_LAWS, EXPORT_SPRING_SINE)

import qzs
from qzs.engine import kernels as K
from qzs.engine import lanes
from qzs.engine.channels import CHANNELS
from qzs.engine.laws import spring_energy_general, spring_general
from qzs.engine.prepare import prepare_run
from qzs.engine.stability import spring_stiffness_peak
from qzs.errors import CompilerError
from qzs.export.cmodel import simulate_c
from qzs.model.springs import (STATUS_OK, STATUS_OUTSIDE, ObliqueSpringQZS, PolynomialSpring,
                               TabulatedSpring, TanhSpring, evaluate_packed)

try:
    from qzs.export.csource import load_model
    load_model()
except CompilerError as error:  # pragma: no cover - the machines have one
    pytest.skip(f"no C compiler: {error}", allow_module_level=True)

SETTINGS = dict(EXPORT_SETTINGS, duration=1.5)
DOUBLE_P = ctypes.POINTER(ctypes.c_double)


class Values(ctypes.Structure):
    _fields_ = [("force", ctypes.c_double), ("stiffness", ctypes.c_double),
                ("energy", ctypes.c_double)]


def _library():
    library = load_model()
    library.qzs_spring_evaluate.argtypes = [DOUBLE_P, ctypes.c_double, ctypes.c_int,
                                            ctypes.POINTER(Values)]
    library.qzs_spring_evaluate.restype = ctypes.c_int
    library.qzs_spring_table.argtypes = [DOUBLE_P, ctypes.c_long, DOUBLE_P, DOUBLE_P,
                                         ctypes.c_int]
    library.qzs_spring_table.restype = None
    library.qzs_spring_stiffness_peak.argtypes = [DOUBLE_P, ctypes.c_double, ctypes.c_double]
    library.qzs_spring_stiffness_peak.restype = ctypes.c_double
    return library


def _pointer(array):
    return array.ctypes.data_as(DOUBLE_P)


@pytest.mark.parametrize("name", list(EXPORT_SPRING_LAWS))
def test_every_channel_of_every_law_is_the_kernels(name):
    isolator = qzs.IsolatorParameters(spring=EXPORT_SPRING_LAWS[name])
    ours = qzs.simulate(EXPORT_SPRING_SINE, isolator, **SETTINGS)
    theirs = simulate_c(EXPORT_SPRING_SINE, isolator, **SETTINGS)
    assert not theirs.diverged and theirs.status == K.STATUS_OK
    assert np.ptp(np.asarray(ours.relative_position)) > 5e-3  # m: the payload moves on the law
    for channel, (column, _, _) in CHANNELS.items():
        np.testing.assert_array_equal(theirs.data[:, column], np.asarray(ours[channel]),
                                      err_msg=f"{name}: {channel}")
    np.testing.assert_array_equal(theirs.flags[:, K.O_LOCKED], np.asarray(ours.locked))
    assert theirs.run_flags[K.I_N_STICKS] == ours.run["stick_events"] >= 1
    # the law is the one run: its force and energy at the recorded positions
    law = EXPORT_SPRING_LAWS[name]
    z = theirs.data[:, CHANNELS["relative_position"][0]]
    np.testing.assert_allclose(theirs.data[:, CHANNELS["spring_force"][0]], law.force(z),
                               rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(theirs.data[:, CHANNELS["spring_energy"][0]], law.energy(z),
                               rtol=1e-13, atol=1e-12)


def test_another_law_changes_the_c_run():
    """The comparison above is not one of two runs that ignore the law."""
    tanh = simulate_c(EXPORT_SPRING_SINE, None, **SETTINGS)
    oblique = simulate_c(EXPORT_SPRING_SINE, qzs.IsolatorParameters(
        spring=EXPORT_SPRING_LAWS["oblique"]), **SETTINGS)
    column = CHANNELS["spring_force"][0]
    assert np.abs(tanh.data[:, column] - oblique.data[:, column]).max() > 0.5  # N


def test_a_refusing_table_stops_the_c_run_where_the_kernel_stops():
    run = prepare_run(EXPORT_LEAVING_SINE, qzs.IsolatorParameters(spring=EXPORT_REFUSING_TABLE),
                      **SETTINGS)
    steps = int(round(run.duration / run.dt))
    data = np.zeros((steps // run.decimation + 1, K.N_CHANNELS))
    marks = np.zeros((data.shape[0], 2), dtype=np.uint8)
    theirs = simulate_c(EXPORT_LEAVING_SINE, run.isolator, **SETTINGS)
    status, _ = lanes.single_kernel(run.model)(run.solver_code, steps, run.decimation, run.state,
                                               run.flags, run.params, run.model, *run.packed,
                                               data, marks, 0)
    assert status == theirs.status == K.STATUS_OUTSIDE
    assert theirs.diverged
    assert 0 < theirs.steps == run.flags[K.I_STEP] < steps  # stopped inside the run
    np.testing.assert_array_equal(theirs.state[:K.N_ODE], run.state[:K.N_ODE])
    first, last = EXPORT_REFUSING_TABLE.domain
    assert first <= theirs.state[K.S_Z] <= last  # the last finite state, inside the table


#: Positions [m] where the laws are evaluated: inside, on a breakpoint, outside the tables.
POSITIONS = np.concatenate([np.linspace(-0.25, 0.15, 801), [-0.2, -0.065, -0.055, 0.1]])
#: A measured-like curve: a local maximum and minimum, a flat step, uneven spacing.
MEASURED = (np.array([-0.1, -0.09, -0.075, -0.07, -0.06, -0.055, -0.04, -0.035, -0.02, 0.0]),
            np.array([70.0, 66.0, 64.0, 64.0, 61.5, 62.5, 60.0, 55.0, 57.0, 50.0]))


def _laws():
    return {**EXPORT_SPRING_LAWS, "refusing table": EXPORT_REFUSING_TABLE,
            "measured": TabulatedSpring(positions=MEASURED[0], forces=MEASURED[1],
                                        outside="extend"),
            "quintic": PolynomialSpring(coefficients=(1.0, -2.0, 3e2, -4e3, 5e4, -6e5),
                                        center=0.01),
            "stiff oblique": ObliqueSpringQZS(vertical_stiffness=50.0, preload=10.0),
            "tanh": TanhSpring(plateau=50.0, shape=60.0)}


@pytest.mark.parametrize("name", list(_laws()))
def test_the_c_evaluator_is_the_kernels_and_evaluate_packed(name):
    """Force and energy: the kernels' (qzs.engine.laws) to the bit; all three and the status:
    evaluate_packed's, to round-off where it differs in its libm (Python's own math.hypot,
    math.tanh where the kernels take qzs.engine.arithmetic.tanh)."""
    library = _library()
    packed = np.ascontiguousarray(_laws()[name].pack())
    values = Values()
    for z in POSITIONS:
        status = library.qzs_spring_evaluate(_pointer(packed), z, 7, ctypes.byref(values))
        force, stiffness, energy, expected = evaluate_packed(packed, z)
        assert status == expected
        got = np.array([values.force, values.stiffness, values.energy])
        if status == STATUS_OUTSIDE:
            assert np.all(np.isnan(got))
            assert np.isnan(spring_general(packed, 0, z))
            continue
        assert status == STATUS_OK
        np.testing.assert_allclose(got, [force, stiffness, energy], rtol=1e-13, atol=1e-13)
        assert values.force == spring_general(packed, 0, z), (name, z)
        assert values.energy == spring_energy_general(packed, 0, z), (name, z)


@pytest.mark.parametrize("outside", ["refuse", "extend"])
@pytest.mark.parametrize("points", [MEASURED, (np.array([0.0, 0.1, 0.3]),
                                               np.array([-1.0, 2.0, -0.5])),
                                    (np.linspace(-0.2, 0.1, 61),
                                     TanhSpring().force(np.linspace(-0.2, 0.1, 61)))])
def test_the_c_table_is_the_python_tables_pack(points, outside):
    """Slopes (harmonic means, zeros at extrema and flat steps, limited end slopes), pieces and
    energies: the numbers TabulatedSpring packs, bit for bit."""
    x, y = (np.ascontiguousarray(a, dtype=float) for a in points)
    expected = TabulatedSpring(positions=x, forces=y, outside=outside).pack()
    got = np.full(expected.size, np.nan)
    _library().qzs_spring_table(_pointer(got), x.size, _pointer(x), _pointer(y),
                                int(outside == "extend"))
    np.testing.assert_array_equal(got, expected)


@pytest.mark.parametrize("name", ["oblique", "cubic polynomial", "refusing table", "measured"])
def test_the_c_stiffness_peak_is_the_step_checks(name):
    law = _laws()[name]
    isolator = qzs.IsolatorParameters(spring=law)
    controller = qzs.ControllerParameters()
    center = controller.position_setpoint
    packed = np.ascontiguousarray(law.pack())
    got = _library().qzs_spring_stiffness_peak(_pointer(packed), center - isolator.stroke_half,
                                               center + isolator.stroke_half)
    assert got == pytest.approx(spring_stiffness_peak(isolator, controller), rel=1e-12)


@pytest.mark.parametrize("forces", [(0.0, 1.0, -1.0, 0.0), (0.0, 1.0, -3.0, 0.0)],
                         ids=["kept", "limited"])
def test_the_c_table_s_end_slopes_are_scipy_s_pchip_ends(forces):
    """An end whose neighbouring secant turns back (PCHIP's shape-preserving end rule, Moler's
    ``pchip``): the three-point slope is kept while within three times the end secant (25
    for secants 10 and -20: kept; 35 for 10 and -40: limited to 30). The C's end slopes and
    forces are scipy.interpolate.PchipInterpolator's, an independent implementation."""
    from scipy.interpolate import PchipInterpolator

    from qzs.model.springs import TABLE_END_SLOPE, TABLE_POSITIONS

    x = np.array([0.0, 0.1, 0.2, 0.3])
    y = np.array(forces)
    n = x.size
    library = _library()
    got = np.full(TabulatedSpring(positions=x, forces=y).pack().size, np.nan)
    library.qzs_spring_table(_pointer(got), n, _pointer(x), _pointer(y), 0)
    reference = PchipInterpolator(x, y)
    ends = reference.derivative()(x[[0, -1]])
    assert ends[0] == pytest.approx(25.0 if forces[2] == -1.0 else 30.0, rel=1e-12)
    first_piece = got[TABLE_POSITIONS + n:TABLE_POSITIONS + n + 4]
    assert first_piece[1] == pytest.approx(ends[0], rel=1e-12)
    assert got[TABLE_END_SLOPE] == pytest.approx(ends[1], rel=1e-12)
    values = Values()
    for z in np.linspace(0.0, 0.3, 31):
        library.qzs_spring_evaluate(_pointer(got), z, 7, ctypes.byref(values))
        assert values.force == pytest.approx(float(reference(z)), rel=1e-12, abs=1e-12)
