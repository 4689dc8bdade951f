"""Tests of qzs.model: force laws against their closed forms, parameter validation."""
import dataclasses
import math

import numpy as np
import pytest

import qzs
from qzs import InitialState, IsolatorParameters, ParameterError
from qzs.model import friction_force, passive_natural_frequency, spring_energy, spring_force, spring_stiffness
from qzs.model.isolator import friction_level, friction_slope

DEFAULT = IsolatorParameters()
Z_GRID = np.linspace(-0.15, 0.15, 61)


# ------------------------------------------------------------------ MagSpring (eq. 2)
def test_spring_is_restoring_odd_and_saturates_at_its_plateau():
    force = spring_force(Z_GRID, DEFAULT)
    assert np.all(np.sign(force) == -np.sign(Z_GRID))  # compressing (z < 0) pushes up
    np.testing.assert_allclose(force, -spring_force(-Z_GRID, DEFAULT), rtol=0, atol=1e-14)
    plateau = DEFAULT.spring_force
    assert np.all(np.abs(force) < plateau)
    np.testing.assert_allclose(spring_force([-1.0, 1.0], DEFAULT), [plateau, -plateau], rtol=1e-15)


@pytest.mark.parametrize("z", [-0.12, -0.060, -0.01, 0.0, 0.003, 0.05])
def test_spring_stiffness_is_minus_derivative_of_force(z):
    h = 1e-6
    central = -(spring_force(z + h, DEFAULT) - spring_force(z - h, DEFAULT)) / (2 * h)
    # central difference error ~ h^2 * a * b^3 ~ 3e-5 N/m
    np.testing.assert_allclose(spring_stiffness(z, DEFAULT), central, rtol=1e-7, atol=1e-4)


@pytest.mark.parametrize("z", [-0.12, -0.060, -0.01, 0.003, 0.05])
def test_spring_energy_derivative_is_minus_force(z):
    h = 1e-6
    central = (spring_energy(z + h, DEFAULT) - spring_energy(z - h, DEFAULT)) / (2 * h)
    np.testing.assert_allclose(central, -spring_force(z, DEFAULT), rtol=1e-7, atol=1e-7)


def test_spring_energy_is_zero_at_centre_and_the_log_cosh_closed_form(validation):
    assert spring_energy(0.0, DEFAULT) == 0.0
    a, b = DEFAULT.spring_force, DEFAULT.spring_shape
    exact = a / b * np.log(np.cosh(b * Z_GRID))
    np.testing.assert_allclose(spring_energy(Z_GRID, DEFAULT), exact, rtol=1e-12, atol=1e-15)
    inside = exact > 0
    validation("MagSpring energy", "(a/b) log cosh(b z), the integral of a tanh(b z)",
               np.abs(spring_energy(Z_GRID, DEFAULT)[inside] / exact[inside] - 1).max(), 1e-12)


def test_spring_energy_stays_finite_far_out_where_cosh_overflows():
    a, b = DEFAULT.spring_force, DEFAULT.spring_shape
    z = np.array([-20.0, 20.0])  # cosh(78.1 * 20) overflows float64
    np.testing.assert_allclose(spring_energy(z, DEFAULT), a * np.abs(z) - a / b * np.log(2), rtol=1e-14)


def test_tiny_spring_shape_gives_a_linear_spring_of_stiffness_a_times_b():
    params = IsolatorParameters(spring_force=1e5, spring_shape=1e-3)
    z = np.linspace(-0.05, 0.05, 11)
    np.testing.assert_allclose(spring_force(z, params), -100.0 * z, rtol=1e-9, atol=1e-15)


# ------------------------------------------------------------------ friction (eq. 3)
def test_friction_always_opposes_slip():
    v = np.concatenate([-np.logspace(1, -9, 50), np.logspace(-9, 1, 50)])
    power = friction_force(v, DEFAULT) * v
    assert np.all(power < 0.0)


def test_friction_limits_stiction_at_zero_and_coulomb_plus_viscous_when_fast():
    p = DEFAULT
    np.testing.assert_allclose(friction_force([1e-12, -1e-12], p), [-p.stiction_force, p.stiction_force],
                               rtol=1e-9)
    v = 1.0  # exp(-100) is negligible: Coulomb + viscous only
    np.testing.assert_allclose(friction_force(v, p), -p.coulomb_force - p.viscous_damping * v, rtol=1e-15)
    assert friction_force(0.0, p) == 0.0


def test_friction_stribeck_decay_is_exponential_in_speed(validation):
    p = IsolatorParameters(viscous_damping=0.0)
    v = np.array([0.001, 0.01, 0.03])
    excess = -friction_force(v, p) - p.coulomb_force
    exact = (p.stiction_force - p.coulomb_force) * np.exp(-p.stribeck_decay * v)
    np.testing.assert_allclose(excess, exact, rtol=1e-13)
    validation("Stribeck decay of the friction law", "(Fs - Fc) exp(-Cbc |v|) (paper eq. 3)",
               np.abs(excess / exact - 1).max(), 1e-13)


@pytest.mark.parametrize("regularisation", [0.0, 2e-3])
def test_friction_slope_is_the_derivative_of_the_friction_force(regularisation):
    p = IsolatorParameters(stiction_force=12.0, coulomb_force=2.5, stribeck_decay=40.0,
                           viscous_damping=80.0, friction_regularisation=regularisation)
    speeds = np.logspace(-5, 0.5, 60)
    v = np.concatenate([-speeds[::-1], speeds])
    if regularisation:  # smooth through 0: the steep tanh is resolved by a small step
        v = np.concatenate([v, np.linspace(-5 * regularisation, 5 * regularisation, 41)])
        h = np.full(v.shape, 1e-6 * regularisation)  # |v| v at 0: an error of order h
    else:  # the exact law jumps at 0: differences on one side only
        h = 1e-4 * np.abs(v)
    central = (friction_force(v + h, p) - friction_force(v - h, p)) / (2 * h)
    slope = friction_slope(v, p)
    np.testing.assert_allclose(slope, central, rtol=1e-6, atol=1e-8 * np.abs(slope).max())
    # the Stribeck level is the force's size without direction and viscous part
    direction = np.tanh(v / regularisation) if regularisation else np.sign(v)
    np.testing.assert_allclose(friction_force(v, p),
                               -friction_level(v, p) * direction - p.viscous_damping * v,
                               rtol=1e-15, atol=1e-15)
    assert friction_level(0.0, p) == p.stiction_force
    assert friction_level(-1e3, p) == pytest.approx(p.coulomb_force, rel=1e-15)
    # at rest: the viscous slope alone (exact law, its jump left out), or steep (regularised)
    expected = -p.viscous_damping - (p.stiction_force / regularisation if regularisation else 0)
    assert friction_slope(0.0, p) == pytest.approx(expected, rel=1e-15)


# ------------------------------------------------------------------ operating point
def test_default_passive_natural_frequency_is_the_papers_0_08_hz(validation):
    frequency = passive_natural_frequency(DEFAULT, -0.060)
    assert frequency == pytest.approx(0.08, abs=0.003)
    a, b, m = DEFAULT.spring_force, DEFAULT.spring_shape, DEFAULT.mass
    closed_form = math.sqrt(a * b / math.cosh(b * 0.060) ** 2 / m) / (2 * math.pi)
    assert frequency == pytest.approx(closed_form, rel=1e-12)
    validation("Passive natural frequency at the setpoint (Table 1 values)",
               "paper, Section 3.1: resonance at approximately 0.08 Hz", abs(frequency - 0.08), 0.003,
               measure=f"absolute error [Hz], {frequency:.4f} Hz")
    validation("Passive natural frequency at the setpoint", "sqrt(a b / cosh^2(b z) / m) / 2 pi",
               abs(frequency / closed_form - 1), 1e-12)
    assert qzs.passive_natural_frequency is passive_natural_frequency


def test_passive_natural_frequency_is_highest_at_the_spring_centre():
    assert passive_natural_frequency(DEFAULT, 0.0) == pytest.approx(
        math.sqrt(DEFAULT.spring_force * DEFAULT.spring_shape / DEFAULT.mass) / (2 * math.pi), rel=1e-12)
    assert passive_natural_frequency(DEFAULT, -0.06) < passive_natural_frequency(DEFAULT, -0.03)


def test_paper_values_leave_a_weight_deficit_that_validation_accepts():
    """docs/model.md §5 (gravity): m*g = 62.78 N exceeds the spring plateau of 60.84 N."""
    assert DEFAULT.weight_deficit == pytest.approx(6.4 * 9.81 - 60.84, rel=1e-12)
    assert DEFAULT.weight_deficit > 0
    assert IsolatorParameters(gravity=0.0).weight_deficit < 0


# ------------------------------------------------------------------ parameters
TABLE_1 = dict(mass=6.4, gravity=9.81, spring_force=60.84, spring_shape=78.10, stiction_force=10.0,
               coulomb_force=1.0, stribeck_decay=100.0, viscous_damping=100.0,
               friction_regularisation=0.0, stroke_half=0.080,
               stop_center=None, stop_stiffness=1e6, stop_damping=1e3, stop_model="compliant",
               motor_force_max=44.0, spring=None)  # None: the tanh of spring_force, spring_shape


def test_defaults_are_table_1_of_model_md():
    assert {f.name: getattr(DEFAULT, f.name) for f in dataclasses.fields(DEFAULT)} == TABLE_1


def test_every_field_documents_its_unit():
    for field in dataclasses.fields(IsolatorParameters):
        assert field.metadata.get("unit"), field.name


def test_parameters_are_frozen_keyword_only_and_round_trip_through_dict():
    with pytest.raises(dataclasses.FrozenInstanceError):
        DEFAULT.mass = 1.0
    with pytest.raises(TypeError):
        IsolatorParameters(6.4)
    params = IsolatorParameters(mass=3, stop_center=0.01)
    assert isinstance(params.mass, float)
    assert IsolatorParameters(**params.to_dict()) == params
    assert "stop_center" not in DEFAULT.to_dict()  # None is omitted


@pytest.mark.parametrize("name, value, match", [
    ("mass", -1.0, "must be positive, got -1.0"),
    ("mass", 0.0, "must be positive, got 0.0"),
    ("mass", "2.0", "must be a number, got '2.0'"),  # text was taken as 2.0
    ("mass", float("nan"), "must be finite, got nan"),
    ("gravity", float("inf"), "must be finite, got inf"),
    ("viscous_damping", -0.5, "must be non-negative, got -0.5"),
    ("stiction_force", True, "must be a number, got the boolean True"),
    ("spring_force", "heavy", "must be a number, got 'heavy'"),
    ("spring_shape", None, "must be a number, got None"),
    ("stroke_half", [0.08], r"must be a number, got \[0.08\]"),
    ("stop_center", float("nan"), "must be finite, got nan"),
    ("stop_model", "elastic", "must be one of 'compliant', 'plastic', got 'elastic'"),
    ("friction_regularisation", -1e-3, "must be non-negative, got -0.001"),
    ("friction_regularisation", float("inf"), "must be finite, got inf"),
])
def test_invalid_parameter_is_named_with_its_value(name, value, match):
    with pytest.raises(ParameterError, match=match) as info:
        IsolatorParameters(**{name: value})
    assert f"`{name}`" in str(info.value)
    assert isinstance(info.value, ValueError)


def test_numpy_boolean_is_rejected_like_a_python_boolean():
    with pytest.raises(ParameterError, match="`mass` must be a number, got the boolean"):
        IsolatorParameters(mass=np.True_)


def test_stiction_below_coulomb_is_rejected_with_both_values():
    with pytest.raises(ParameterError, match="stiction_force") as info:
        IsolatorParameters(stiction_force=0.5, coulomb_force=1.0)
    assert "0.5" in str(info.value) and "1.0" in str(info.value)
    IsolatorParameters(stiction_force=1.0, coulomb_force=1.0)  # equal is allowed
    IsolatorParameters(stiction_force=0.0, coulomb_force=0.0)  # frictionless guide


def test_unknown_keyword_is_a_type_error():
    with pytest.raises(TypeError, match="masss"):
        IsolatorParameters(masss=6.4)
    with pytest.raises(TypeError, match="velocity"):
        InitialState(velocity=0.0)


@pytest.mark.parametrize("kwargs, match", [
    (dict(locked=True, relative_velocity=0.1), "`relative_velocity` must be 0 when `locked` is True"),
    (dict(locked="yes"), "`locked` must be True, False or None, got 'yes'"),
    (dict(relative_position=float("nan")), "`relative_position` must be finite, got nan"),
    (dict(relative_velocity=None), "`relative_velocity` must be a number, got None"),
    (dict(pi_integral=float("inf")), "`pi_integral` must be finite, got inf"),
])
def test_invalid_initial_state(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        InitialState(**kwargs)


def test_worker_count_defaults_to_the_cores_and_respects_its_limit():
    import os

    import numpy as np

    from qzs._validation import worker_count

    cores = os.cpu_count() or 1
    assert worker_count(None) == cores
    assert worker_count(None, limit=1) == 1
    assert worker_count(np.int64(3)) == 3 and type(worker_count(np.int64(3))) is int
    assert worker_count(5, limit=2) == 2
    assert worker_count(5, limit=0) == 1  # nothing to share out: one worker
    for bad in (0, -1, 1.0, True, np.bool_(True), "2"):
        with pytest.raises(ParameterError, match="`workers` must be an integer >= 1"):
            worker_count(bad)
