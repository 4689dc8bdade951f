"""Spring laws as values: closed forms, energies, the PCHIP table's error bound, the packed
arrays a kernel evaluates, the equilibrium check and every bad input (docs/model.md §3.1)."""
import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.interpolate import PchipInterpolator

from qzs.errors import ParameterError
from qzs.model.isolator import IsolatorParameters, spring_energy, spring_force, spring_stiffness
from qzs.model.springs import (STATUS_OUTSIDE, ObliqueSpringQZS, PolynomialSpring, SpringLaw,
                               TabulatedSpring, TanhSpring, check_equilibrium, evaluate_packed)

#: The paper's stroke about the operating point -0.060 m [m] and the payload's weight [N].
STROKE = (-0.140, 0.020)
WEIGHT = 6.4 * 9.81
TANH = TanhSpring()


def _laws():
    """One of each law (a table that extends, so that it is defined beyond the stroke)."""
    return {
        "tanh": TANH,
        "oblique": ObliqueSpringQZS(),
        "oblique-stiff": ObliqueSpringQZS(vertical_stiffness=50.0, oblique_stiffness=300.0,
                                          free_length=0.1, horizontal_distance=0.12,
                                          center=0.01, preload=-3.0),
        "duffing": PolynomialSpring(coefficients=(62.78, -100.0, 0.0, -5e4), center=-0.06),
        "quadratic": PolynomialSpring(coefficients=(1.0, -20.0, 3e3)),
        "table": TabulatedSpring.from_law(TANH, np.linspace(-0.15, 0.03, 37), outside="extend"),
    }


LAWS = _laws()


# ------------------------------------------------------------------------------- tanh
def test_the_tanh_law_is_todays_magspring_bit_for_bit():
    params = IsolatorParameters(spring_force=55.5, spring_shape=91.0)
    law = TanhSpring(plateau=55.5, shape=91.0)
    z = np.concatenate([np.linspace(-0.3, 0.3, 2001), [0.0, -0.0, 1e-300, 3.0, -3.5]])
    for new, old in ((law.force, spring_force), (law.stiffness, spring_stiffness),
                     (law.energy, spring_energy)):
        assert np.array_equal(new(z), old(z, params))
        assert new(-0.06) == old(-0.06, params)
    default = IsolatorParameters()
    assert (TANH.plateau, TANH.shape) == (default.spring_force, default.spring_shape)


# ---------------------------------------------------------------------------- oblique
def _geometric_force(law, z):
    """The three springs' forces on the payload summed as vectors (complex-safe)."""
    u = z - law.center
    total = law.preload - law.vertical_stiffness * u
    for side in (-1.0, 1.0):     # hinge at (side*d, 0), payload at (0, u)
        dx, dz = -side * law.horizontal_distance, u
        length = np.sqrt(dx * dx + dz * dz)
        push = law.oblique_stiffness * (law.free_length - length)   # compression pushes out
        total = total + push * dz / length
    return total


@pytest.mark.parametrize("name", ["oblique", "oblique-stiff"])
def test_the_oblique_law_is_the_geometric_force_and_its_exact_derivative(name):
    law = LAWS[name]
    z = law.center + np.array([-0.08, -0.05, -0.013, -1e-4, 0.0, 2e-3, 0.031, 0.08])
    force = _geometric_force(law, z)
    np.testing.assert_allclose(law.force(z), force, rtol=1e-12, atol=1e-12 * abs(law.preload))
    # complex step: the derivative of the geometric force to round-off
    step = 1e-30
    slope = _geometric_force(law, z + 1j * step).imag / step
    scale = law.vertical_stiffness + 2.0 * law.oblique_stiffness
    np.testing.assert_allclose(law.stiffness(z), -slope, rtol=1e-12, atol=1e-12 * scale)
    # and the closed forms of docs/model.md §3.1
    u, d = z - law.center, law.horizontal_distance
    np.testing.assert_allclose(law.stiffness(z), law.vertical_stiffness + 2 * law.oblique_stiffness
                               * (1 - law.free_length * d ** 2 / (u ** 2 + d ** 2) ** 1.5),
                               rtol=1e-12, atol=1e-12 * scale)


@pytest.mark.parametrize("geometry", [
    {}, {"oblique_stiffness": 1234.5, "free_length": 0.3, "horizontal_distance": 0.1},
    {"oblique_stiffness": 17.0, "free_length": 0.05, "horizontal_distance": 0.0499, "center": 0.3},
])
def test_the_quasi_zero_choice_zeroes_the_stiffness_at_the_centre_and_nowhere_below(geometry):
    law = ObliqueSpringQZS.quasi_zero(**geometry)
    scale = law.vertical_stiffness + 2.0 * law.oblique_stiffness
    assert abs(float(law.stiffness(law.center))) <= 1e-12 * scale
    assert law.vertical_stiffness == pytest.approx(
        2 * law.oblique_stiffness * (law.free_length / law.horizontal_distance - 1), rel=1e-15)
    z = law.center + np.linspace(-0.08, 0.08, 1601)
    assert np.all(law.stiffness(z) >= -1e-12 * scale)
    assert float(law.stiffness(law.center + 0.01)) > 0.0


def test_the_default_mechanism_is_quasi_zero_carries_the_payload_and_stays_stable():
    law = ObliqueSpringQZS()
    assert law == ObliqueSpringQZS.quasi_zero()
    assert float(law.stiffness(-0.06)) == 0.0
    assert float(law.force(-0.06)) == pytest.approx(WEIGHT, abs=0.01)
    ends = law.stiffness(np.array(STROKE))
    np.testing.assert_allclose(ends, 241.48, rtol=1e-4)               # the docstring's figures
    assert np.all(np.abs(law.force(np.linspace(*STROKE, 201)) - 62.78) <= 7.6)
    assert check_equilibrium(law, law.preload, STROKE) == pytest.approx(-0.06, abs=1e-9)


@pytest.mark.parametrize("geometry, match", [
    ({"free_length": 0.1, "horizontal_distance": 0.125},
     r"`free_length` \(0.1 m\) must exceed `horizontal_distance` \(0.125 m\).*e.g. free_length "
     r"= 0.1875 m"),
    ({"free_length": 0.125, "horizontal_distance": 0.125}, "must exceed `horizontal_distance`"),
    ({"vertical_stiffness": 3.0}, "`vertical_stiffness` is what quasi_zero chooses"),
    ({"oblique_stiffness": -1.0}, "`oblique_stiffness` must be non-negative, got -1.0"),
])
def test_the_quasi_zero_choice_refuses_what_cannot_be_quasi_zero(geometry, match):
    with pytest.raises(ParameterError, match=match):
        ObliqueSpringQZS.quasi_zero(**geometry)


# ----------------------------------------------------------------------------- energy
def _derivative(function, z, h):
    """Sixth-order central difference."""
    weights = {1: 45.0, 2: -9.0, 3: 1.0}
    return sum(w * (function(z + k * h) - function(z - k * h)) for k, w in weights.items()) \
        / (60.0 * h)


@pytest.mark.parametrize("name", list(LAWS))
def test_the_force_is_minus_the_derivative_of_the_energy_and_the_energy_its_integral(name):
    law = LAWS[name]
    z = np.linspace(-0.17, 0.05, 23)         # beyond the table's ends too (it extends)
    scale = float(np.max(np.abs(law.force(z))))
    np.testing.assert_allclose(-_derivative(law.energy, z, 2e-5), law.force(z),
                               atol=1e-7 * scale)
    reference = -0.06
    for point in z:
        work, _ = quad(lambda p: float(law.force(p)), reference, point, epsabs=1e-13,
                       epsrel=1e-13, limit=200,
                       points=getattr(law, "positions", None))
        assert float(law.energy(point) - law.energy(reference)) == pytest.approx(
            -work, abs=1e-11 * scale)


@pytest.mark.parametrize("law, reference", [
    (TANH, 0.0), (ObliqueSpringQZS(), -0.06), (LAWS["duffing"], -0.06),
    (LAWS["quadratic"], 0.0), (LAWS["table"], -0.15)])
def test_the_energy_is_zero_at_the_stated_reference(law, reference):
    assert float(law.energy(reference)) == 0.0


# ------------------------------------------------------------------------------ table
def test_the_table_is_scipys_pchip_with_its_exact_integral():
    x = np.sort(np.random.default_rng(4).uniform(-0.14, 0.02, 60))
    y = np.random.default_rng(5).normal(50.0, 10.0, x.size)          # not monotone
    law = TabulatedSpring(positions=x, forces=y)
    reference = PchipInterpolator(x, y)
    z = np.linspace(x[0], x[-1], 5001)
    np.testing.assert_allclose(law.force(z), reference(z), rtol=1e-12, atol=1e-12 * 80)
    slope_scale = np.abs(reference(z, 1)).max()
    np.testing.assert_allclose(-law.stiffness(z), reference(z, 1), atol=1e-12 * slope_scale)
    integral = reference.antiderivative()
    np.testing.assert_allclose(law.energy(z), -(integral(z) - integral(x[0])),
                               atol=1e-12 * 80 * np.ptp(x))


def _tanh_derivatives(z):
    """|F^(k)| of the default tanh law, k = 1..4."""
    a, b = TANH.plateau, TANH.shape
    t = np.tanh(b * z)
    s = 1.0 - t * t
    return (a * b * s, np.abs(2 * a * b ** 2 * s * t), np.abs(2 * a * b ** 3 * s * (1 - 3 * t * t)),
            np.abs(8 * a * b ** 4 * s * t * (3 * t * t - 2)))


def _pchip_bound(x):
    """docs/model.md §3.1's bound on |F - P| on each piece of a uniform table of a monotone F:
    h^4 M4/384 + (h/4) max(delta_i, delta_(i+1)); slope errors delta = h^2 (M3/6 + M2^2/(4 mu))
    inside, h^2 M3/3 at the ends; M_k = max |F^(k)|, mu = min |F'| over the breakpoint's two
    pieces (M4 over the piece itself); maxima sampled at 200 points a piece."""
    h = x[1] - x[0]
    fine = np.linspace(0.0, 1.0, 201)
    pieces = [x[i] + h * fine for i in range(x.size - 1)]
    d1, d2, d3, d4 = zip(*(_tanh_derivatives(p) for p in pieces))
    delta = np.empty(x.size)
    for k in range(1, x.size - 1):
        m2 = max(d2[k - 1].max(), d2[k].max())
        m3 = max(d3[k - 1].max(), d3[k].max())
        mu = min(d1[k - 1].min(), d1[k].min())
        delta[k] = h * h * (m3 / 6 + m2 * m2 / (4 * mu))
    delta[0], delta[-1] = h * h * d3[0].max() / 3, h * h * d3[-1].max() / 3
    m4 = np.array([d.max() for d in d4])
    return h ** 4 * m4 / 384 + h / 4 * np.maximum(delta[:-1], delta[1:])


def test_a_table_of_the_tanh_law_meets_the_bound_and_converges_at_third_and_fourth_order():
    force_errors, energy_errors, spacings = [], [], []
    for intervals in (40, 80, 160, 320, 640):
        x = np.linspace(*STROKE, intervals + 1)
        law = TabulatedSpring.from_law(TANH, x)
        bound = _pchip_bound(x)
        z = x[:-1, None] + (x[1] - x[0]) * np.linspace(0.0, 1.0, 41)[None, :]
        force_error = np.abs(law.force(z) - TANH.force(z))
        # plus round-off: 1e-14 of the plateau force, and of the work over the stroke
        assert np.all(force_error.max(axis=1) <= bound + 1e-14 * TANH.plateau), intervals
        energy_error = np.abs(law.energy(z) - (TANH.energy(z) - TANH.energy(x[0])))
        # |E - E_P| <= integral of |F - P| <= the bounds of the pieces below, summed
        below = np.concatenate([[0.0], np.cumsum(bound * (x[1] - x[0]))])
        roundoff = 1e-14 * TANH.plateau * (STROKE[1] - STROKE[0])
        assert np.all(energy_error.max(axis=1) <= below[1:] + roundoff), intervals
        force_errors.append(force_error.max())
        energy_errors.append(energy_error.max())
        spacings.append(x[1] - x[0])
    force_order = np.polyfit(np.log(spacings), np.log(force_errors), 1)[0]
    energy_order = np.polyfit(np.log(spacings), np.log(energy_errors), 1)[0]
    assert 2.9 < force_order < 3.15, force_order      # PCHIP: third order in the force
    assert 3.8 < energy_order < 4.15, energy_order    # its integral: fourth


def test_outside_the_table_it_refuses_or_continues_with_the_end_slope():
    x = np.linspace(-0.1, 0.0, 11)
    refusing = TabulatedSpring.from_law(TANH, x)
    with pytest.raises(ParameterError, match=r"`z` = 0.01 m is outside the table .*outside="
                                             r"'extend'"):
        refusing.force(np.array([-0.05, 0.01]))
    with pytest.raises(ParameterError, match="outside the table"):
        refusing.energy(-0.2)
    extending = TabulatedSpring.from_law(TANH, x, outside="extend")
    for end, beyond in ((x[0], x[0] - 0.03), (x[-1], x[-1] + 0.02)):
        slope = -float(extending.stiffness(end))
        assert float(extending.force(beyond)) == pytest.approx(
            float(extending.force(end)) + slope * (beyond - end), rel=1e-14)
        assert float(extending.stiffness(beyond)) == float(extending.stiffness(end))
        # C1 at the end: the piece's slope meets the line's
        inner = end + (1e-9 if end == x[0] else -1e-9)
        assert float(extending.stiffness(inner)) == pytest.approx(-slope, rel=1e-6, abs=1e-5)


# ------------------------------------------------------------------------------- pack
@pytest.mark.parametrize("name", list(LAWS))
def test_the_packed_law_evaluates_to_the_same_force_stiffness_and_energy(name):
    law = LAWS[name]
    packed = law.pack()
    assert packed.dtype == np.float64 and packed.ndim == 1 and packed[0] == law.code
    z = np.concatenate([np.linspace(-0.2, 0.06, 301), getattr(law, "positions", [])])
    values = np.array([evaluate_packed(packed, float(p)) for p in z])
    assert np.all(values[:, 3] == 0)
    for column, method in enumerate((law.force, law.stiffness, law.energy)):
        expected = method(z)
        np.testing.assert_allclose(values[:, column], expected, rtol=1e-14,
                                   atol=1e-14 * np.abs(expected).max())


def test_a_packed_refusing_table_reports_outside_with_a_status():
    packed = TabulatedSpring.from_law(TANH, np.linspace(-0.1, 0.0, 5)).pack()
    force, stiffness, energy, status = evaluate_packed(packed, 0.001)
    assert status == STATUS_OUTSIDE and all(math.isnan(v) for v in (force, stiffness, energy))


# ------------------------------------------------------------------------ as values
@pytest.mark.parametrize("name", list(LAWS))
def test_a_law_goes_to_a_dict_and_back(name):
    law = LAWS[name]
    data = law.to_dict()
    assert data["law"] == law.kind
    again = SpringLaw.from_dict(data)
    assert type(again) is type(law) and again == law and hash(again) == hash(law)
    assert type(law).from_dict(data) == law
    assert law != TabulatedSpring.from_law(TANH, [0.0, 0.1, 0.2])
    line = law.describe()
    assert "\n" not in line and (" N" in line or "[N" in line)


@pytest.mark.parametrize("data, match", [
    ({"law": "magnet"}, r"`law` must be one of 'tanh', 'oblique', 'polynomial', 'table'"),
    ({"law": "tanh", "force": 3.0}, r"unknown key\(s\) \['force'\] in a 'tanh' spring law"),
    ([1, 2], "`data` must be a dict"),
])
def test_bad_law_data_is_refused(data, match):
    with pytest.raises(ParameterError, match=match):
        SpringLaw.from_dict(data)


def test_a_subclass_refuses_another_laws_data():
    with pytest.raises(ParameterError, match="`law` must be one of 'tanh'"):
        TanhSpring.from_dict({"law": "oblique"})


# -------------------------------------------------------------------------- bad input
@pytest.mark.parametrize("make, match", [
    (lambda: TabulatedSpring(positions=[0.0, 0.2, 0.1, 0.3], forces=[1, 2, 3, 4]),
     r"`positions` must be strictly increasing, but it is decreasing at index 2 .*sort"),
    (lambda: TabulatedSpring(positions=[0.0, 0.1, 0.1, 0.3], forces=[1, 2, 3, 4]),
     r"it is repeated at index 2 \(0.1 m after 0.1 m; 1 such steps\).*average"),
    (lambda: TabulatedSpring(positions=[0.3, 0.2, 0.1], forces=[1, 2, 3]),
     r"decreasing at index 1 .*reverse the table"),
    (lambda: TabulatedSpring(positions=[0.0, np.nan, 0.3], forces=[1, 2, 3]),
     r"`positions` must be finite, but 1 of its 3 values are NaN or inf \(the first at index 1"),
    (lambda: TabulatedSpring(positions=[0.0, 0.1, 0.3], forces=[1, np.inf, 3]),
     r"`forces` must be finite"),
    (lambda: TabulatedSpring(positions=[0.0, 0.1], forces=[1, 2]),
     r"at least 3 points for the PCHIP interpolant.*PolynomialSpring"),
    (lambda: TabulatedSpring(positions=[0.0, 0.1, 0.2], forces=[1, 2]),
     r"same length, got 3 and 2"),
    (lambda: TabulatedSpring(positions=[[0.0, 0.1, 0.2]], forces=[1, 2, 3]),
     r"`positions` must be a 1-D sequence of numbers, got shape \(1, 3\)"),
    (lambda: TabulatedSpring(positions=["a", "b", "c"], forces=[1, 2, 3]),
     r"`positions` must be a sequence of numbers"),
    (lambda: TabulatedSpring(positions=[0.0, 0.1, 0.2], forces=[1, 2, 3], outside="clip"),
     r"`outside` must be one of 'refuse', 'extend', got 'clip'"),
    (lambda: TanhSpring(plateau=-1.0), r"`plateau` must be non-negative, got -1.0"),
    (lambda: TanhSpring(shape=0.0), r"`shape` must be positive, got 0.0"),
    (lambda: ObliqueSpringQZS(vertical_stiffness=-5.0),
     r"`vertical_stiffness` must be non-negative, got -5.0"),
    (lambda: ObliqueSpringQZS(horizontal_distance=0.0), r"`horizontal_distance` must be positive"),
    (lambda: ObliqueSpringQZS(free_length=math.nan), r"`free_length` must be finite, got nan"),
    (lambda: PolynomialSpring(coefficients=[]), r"`coefficients` must hold at least one number"),
    (lambda: PolynomialSpring(coefficients=[1.0, math.inf]), r"`coefficients` must be finite"),
    (lambda: TabulatedSpring.from_law(lambda z: z, [0.0, 0.1, 0.2]), r"`law` must be a spring law"),
])
def test_bad_parameters_are_refused_naming_the_argument_and_the_fix(make, match):
    with pytest.raises(ParameterError, match=match):
        make()


def test_a_table_from_a_csv_file_with_units(tmp_path):
    path = tmp_path / "magspring.csv"
    x = np.linspace(-140.0, 20.0, 33)
    rows = "\n".join(f"{float(p)!r},{float(f)!r}" for p, f in zip(x, TANH.force(x * 1e-3) / 1e3))
    path.write_text("position [mm],force [kN]\n" + rows + "\n")
    law = TabulatedSpring.read_csv(path, outside="extend")
    np.testing.assert_allclose(law.positions, x * 1e-3, rtol=1e-15)
    np.testing.assert_allclose(law.forces, TANH.force(x * 1e-3), rtol=1e-14, atol=1e-14)
    assert law.outside == "extend"
    with pytest.raises(ParameterError, match="mismatched units"):
        TabulatedSpring.read_csv(path, position_unit="m")


# ------------------------------------------------------------------------ equilibrium
def test_the_magspring_alone_cannot_carry_the_payload_but_with_the_motors_hold_it_can():
    with pytest.raises(ParameterError) as info:
        check_equilibrium(TANH, WEIGHT, STROKE)
    message = str(info.value)
    assert "no stable equilibrium inside `stroke` [-0.14, 0.02] m" in message
    assert "1.944 N short of the load" in message and "`hold` >= 1.944 N" in message
    assert set(info.value.options) >= {"law", "weight", "hold"}
    position = check_equilibrium(TANH, WEIGHT, STROKE, hold=1.95)
    assert float(TANH.force(position)) == pytest.approx(WEIGHT - 1.95, abs=1e-9)
    assert float(TANH.stiffness(position)) > 0.0


def test_a_law_that_pushes_too_hard_or_only_unstably_is_refused_with_its_fix():
    with pytest.raises(ParameterError, match=r"at least .* N more than the load .*upper stop"):
        check_equilibrium(PolynomialSpring(coefficients=(100.0, -10.0)), WEIGHT, STROKE)
    # no vertical spring: the oblique springs' negative stiffness alone about the centre
    bistable = ObliqueSpringQZS(vertical_stiffness=0.0)
    with pytest.raises(ParameterError, match=r"only where it rises with z \(negative stiffness, "
                                             r"near z = -0.06 m\).*quasi_zero"):
        check_equilibrium(bistable, bistable.preload, STROKE)


def test_the_equilibrium_is_where_the_force_falls_through_the_load_and_nearest_the_middle():
    # a Duffing spring softened into two wells: stable at u = +-sqrt(k1/k3), unstable at 0
    law = PolynomialSpring(coefficients=(10.0, 200.0, 0.0, -2e5), center=-0.06)
    wells = np.sqrt(200.0 / 2e5)
    position = check_equilibrium(law, 10.0, STROKE)
    assert abs(abs(position + 0.06) - wells) < 1e-12
    assert float(law.stiffness(position)) > 0.0
    # an equilibrium sitting exactly on a sample counts too
    line = PolynomialSpring(coefficients=(0.0, -100.0), center=-0.06)
    assert check_equilibrium(line, 0.0, STROKE) == pytest.approx(-0.06, abs=1e-15)


@pytest.mark.parametrize("arguments, match", [
    ({"stroke": (0.02, -0.14)}, r"`stroke` must be \(low, high\) with low < high"),
    ({"stroke": 0.1}, r"`stroke` must be two positions"),
    ({"weight": -1.0}, r"`weight` must be non-negative"),
    ({"law": 3.0}, r"`law` must be a spring law"),
    ({"law": TabulatedSpring.from_law(TANH, np.linspace(-0.1, 0.0, 9))},
     r"`stroke` \(-0.14, 0.02\) m reaches beyond the table .*outside='extend'"),
])
def test_bad_equilibrium_arguments_are_refused(arguments, match):
    call = {"law": TANH, "weight": WEIGHT, "stroke": STROKE, **arguments}
    with pytest.raises(ParameterError, match=match):
        check_equilibrium(call.pop("law"), call.pop("weight"), call.pop("stroke"))
