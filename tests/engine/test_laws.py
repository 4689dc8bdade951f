"""One force law: the numba laws every kernel calls, against the numpy laws and closed forms."""
import ast
from pathlib import Path

import numpy as np
import pytest

from qzs import IsolatorParameters
from qzs.engine import laws
from qzs.model.isolator import friction_force, spring_energy, spring_force

SOURCE = Path(__file__).resolve().parents[2] / "src" / "qzs"
ENGINE = SOURCE / "engine"
HARMONIC_BALANCE = SOURCE / "analysis" / "harmonic_balance"
P = IsolatorParameters(stiction_force=12.0, coulomb_force=2.5, stribeck_decay=40.0,
                       viscous_damping=80.0)


def _vectorised(law, *arrays):
    return np.array([law(*values) for values in zip(*arrays)])


def test_spring_law_equals_the_numpy_law_and_its_energy():
    z = np.concatenate([np.linspace(-0.2, 0.2, 801), [0.0, 1e-12, -1e-12, 0.35, -0.35]])
    a, b = P.spring_force, P.spring_shape
    numba_force = _vectorised(lambda zz: laws.spring_law(a, b, zz), z)
    np.testing.assert_allclose(numba_force, spring_force(z, P), rtol=1e-15, atol=1e-15 * a)
    numba_energy = _vectorised(lambda zz: laws.spring_energy_law(a, b, zz), z)
    np.testing.assert_allclose(numba_energy, spring_energy(z, P), rtol=1e-15, atol=1e-15 * a / b)
    # the energy's derivative is minus the force (central differences)
    h = 1e-7
    slope = (_vectorised(lambda zz: laws.spring_energy_law(a, b, zz), z + h)
             - _vectorised(lambda zz: laws.spring_energy_law(a, b, zz), z - h)) / (2 * h)
    np.testing.assert_allclose(slope, -numba_force, atol=1e-6 * a)


def test_sliding_friction_law_equals_the_numpy_law_and_opposes_the_slip():
    v = np.concatenate([-np.logspace(-9, 1, 300), np.logspace(-9, 1, 300)])
    numba = _vectorised(lambda vv: laws.sliding_friction_law(
        vv, np.sign(vv), P.stiction_force, P.coulomb_force, P.stribeck_decay,
        P.viscous_damping, 0.0), v)
    np.testing.assert_allclose(numba, friction_force(v, P), rtol=2e-15, atol=1e-14)
    assert np.all(numba * v < 0)
    # the breakaway force is Fs, and far from it Coulomb plus viscous
    assert laws.sliding_friction_law(0.0, 1.0, 12.0, 2.5, 40.0, 80.0, 0.0) == -12.0
    assert laws.sliding_friction_law(1.0, 1.0, 12.0, 2.5, 40.0, 80.0, 0.0) == pytest.approx(
        -(2.5 + 9.5 * np.exp(-40.0) + 80.0), rel=1e-15)


@pytest.mark.parametrize("z, v, expected", [
    (0.0, 0.0, (0.0, 0.0)),                     # between the stops
    (-0.11, 0.0, (1e6 * 0.01, 1e6 * 0.01)),     # pressed on the lower stop
    (-0.11, -0.2, (1e4 + 200.0, 1e4)),          # moving into it: the damper adds
    (-0.11, 20.0, (0.0, 1e4)),                  # leaving fast: it pushes, never pulls
    (0.13, 0.0, (-3e4, -3e4)),                  # the upper stop pushes down
    (0.13, -40.0, (0.0, -3e4)),
])
def test_compliant_stop_law_only_pushes(z, v, expected):
    force, elastic = laws.compliant_stop_law(z, v, -0.1, 0.1, 1e6, 1e3)
    assert force == pytest.approx(expected[0], rel=1e-12, abs=1e-9)
    assert elastic == pytest.approx(expected[1], rel=1e-12, abs=1e-9)


def test_controller_law_saturates_and_stops_integrating_into_saturation():
    # inside the limits: PI plus damping, the integral follows the error
    f_pi, f_damp, f_motor, rate = laws.controller_law(-0.06, 50.0, 20.0, 30.0, 44.0,
                                                      -0.07, 0.1, 0.05)
    assert f_pi == pytest.approx(50.0 * 0.01 + 20.0 * 0.05)
    assert f_damp == pytest.approx(-3.0)
    assert f_motor == pytest.approx(f_pi + f_damp) and rate == pytest.approx(0.01)
    # saturated high with an error pushing higher: clipped, integral frozen
    _, _, f_motor, rate = laws.controller_law(0.0, 1e4, 20.0, 0.0, 44.0, -0.01, 0.0, 0.0)
    assert f_motor == 44.0 and rate == 0.0
    # saturated high but the error pulls back: it integrates again
    _, _, f_motor, rate = laws.controller_law(0.0, 1e4, 20.0, 0.0, 44.0, 0.001, 0.0, 10.0)
    assert f_motor == 44.0 and rate == pytest.approx(-0.001)
    # saturated low, error pushing lower: frozen
    _, _, f_motor, rate = laws.controller_law(0.0, 1e4, 20.0, 0.0, 44.0, 0.01, 0.0, 0.0)
    assert f_motor == -44.0 and rate == 0.0


def called_names(path):
    """Names of everything a source file calls (``f(...)`` and ``module.f(...)``)."""
    tree = ast.parse(Path(path).read_text(encoding="utf-8"))
    return {node.func.attr if isinstance(node.func, ast.Attribute) else
            getattr(node.func, "id", None)
            for node in ast.walk(tree) if isinstance(node, ast.Call)}


def test_drivers_write_no_force_law_of_their_own():
    """tanh and exp (the spring and the Stribeck curve) appear only in laws and arithmetic."""
    for name in ("kernels.py", "lanes.py", "base_motion.py"):
        called = called_names(ENGINE / name)
        assert not called & {"tanh", "_tanh", "cosh"}, name
        assert "spring_law" in called or name != "kernels.py"
        assert "sliding_friction_law" in called or name != "kernels.py"
        assert "compliant_stop_law" in called or name != "kernels.py"
        assert "controller_law" in called or name != "kernels.py"


def test_the_six_leg_engine_writes_no_force_law_of_its_own():
    """The six-axis kernels and their packing call the same laws (engine.laws in the kernels,
    the model's numpy laws in the preload): no tanh, cosh or exp of their own."""
    modules = sorted((ENGINE / "hexapod").glob("*.py"))
    assert len(modules) > 3
    for path in modules:
        assert not called_names(path) & {"tanh", "_tanh", "cosh", "exp"}, path.name
    assert "spring_force" in called_names(ENGINE / "hexapod" / "prepare.py")


def test_the_harmonic_balance_writes_no_force_law_of_its_own():
    """The smooth model's spring and friction are the model's numpy laws (qzs.model.isolator),
    which tests/model/test_isolator.py and the test above hold equal to the kernels' laws: no tanh,
    cosh, exp or sign anywhere in the harmonic balance, and the smooth model calls the laws
    and their slopes."""
    modules = sorted(HARMONIC_BALANCE.glob("*.py"))
    assert len(modules) > 1
    for path in modules:
        called = called_names(path)
        assert not called & {"tanh", "cosh", "exp", "sign"}, path.name
    assert {"spring_force", "spring_stiffness", "friction_force", "friction_slope"} <= (
        called_names(HARMONIC_BALANCE / "smooth_model.py"))
