"""Each leg of the six-leg platform with its own spring law (docs/model.md §3.1, issue 41).

Six identical vertical legs under a platform of six masses, base motion in z, are six single
axes whatever the law; legs with different laws keep the energy ledger closed, each leg's
spring force and the stored energy being its own law's; a refusing table left mid-run stops
the run as the single axis's does, naming the leg.
"""
import numpy as np
import pytest
from helpers import vertical_legs

from qzs import ControllerParameters, IsolatorParameters, SimulationError, Sine, simulate
from qzs.engine.hexapod import simulate_hexapod
from qzs.model.excitation import Chirp
from qzs.model.hexapod import PlatformParameters, cubic_geometry
from qzs.model.springs import ObliqueSpringQZS, PolynomialSpring, TabulatedSpring, TanhSpring

PLANT = dict(stiction_force=4.0, coulomb_force=2.0)
SINE = Sine(amplitude=0.01, frequency=4.0)
CUBIC = PolynomialSpring(coefficients=(62.78, -300.0, 0.0, -2e5), center=-0.06)
LAWS = {"oblique-quasi-zero": ObliqueSpringQZS.quasi_zero(),
        "cubic-polynomial": CUBIC,
        "table-of-tanh-extended": TabulatedSpring.from_law(
            TanhSpring(), np.linspace(-0.12, 0.0, 121), outside="extend")}


def _six_masses(isolator):
    return PlatformParameters(mass=6 * isolator.mass, inertia=np.diag([1.0, 1.0, 1.5]))


@pytest.mark.parametrize("name", list(LAWS))
def test_six_vertical_legs_with_a_law_are_six_single_axes(name, validation):
    """Each leg is the single axis with the same law, stick-slip included: its position to
    1e-9 m (the tolerance of the tanh's legs), its spring force to 1e-6 N, the stored energy
    six times the single axis's; its locked flags and stick events exactly. The table runs
    beyond its ends (the stops' penetration), linear there as the single axis's."""
    isolator = IsolatorParameters(spring=LAWS[name], **PLANT)
    options = dict(duration=2.0, sample_rate=10000.0)
    single = simulate(SINE, isolator, ControllerParameters(), **options)
    result = simulate_hexapod(vertical_legs(), _six_masses(isolator), isolator,
                              ControllerParameters(), excitation={"z": SINE}, **options)
    assert single.run["stick_events"] >= 1
    assert not result.has_blocks  # a law alone leaves the blocks' channels out
    difference = np.max(np.abs(result["relative_position"]
                               - single["relative_position"][:, None]))
    assert difference < 1e-9
    assert np.max(np.abs(result["spring_force"] - single["spring_force"][:, None])) < 1e-6
    np.testing.assert_allclose(result["spring_energy"], 6 * single["spring_energy"], rtol=0,
                               atol=1e-8)
    assert np.all(result["locked"] == single["locked"][:, None])
    assert result.run["stick_events"] == [single.run["stick_events"]] * 6
    validation(f"Six vertical legs with the spring law {name} under a platform of six masses",
               "the single axis with the same law (qzs.simulate), stick-slip events included",
               difference, 1e-9, measure="largest leg position difference [m]")


def test_a_leg_with_its_own_law_is_its_law_and_the_ledger_closes(validation):
    """Leg 3 a cubic polynomial, leg 5 the oblique-spring QZS, the others the tanh, on the
    cubic platform under a chirp in z with stick-slip: the platform moves otherwise than on six
    tanh legs; each leg's spring force and the stored energy are its own law's at its
    position (numpy's evaluation of the law, an independent reference); the energy ledger
    closes as the tanh legs' does (< 1e-7 of the largest base work); the file's attributes
    name each leg's law."""
    geometry = cubic_geometry(cube_edge=0.3, cube_center_height=0.3)
    platform = PlatformParameters(mass=22.17, inertia=np.diag([0.3, 0.3, 0.5]))
    controller = ControllerParameters(pi_kp=2000.0, pi_ki=800.0, damping_gain=20.0)
    tanh = IsolatorParameters(**PLANT)
    legs = [tanh, tanh, IsolatorParameters(spring=CUBIC, **PLANT), tanh,
            IsolatorParameters(spring=ObliqueSpringQZS(), **PLANT), tanh]
    laws = [leg.spring_law for leg in legs]
    options = dict(excitation={"z": Chirp(duration=20.0)}, duration=2.0)
    result = simulate_hexapod(geometry, platform, legs, controller, **options)
    reference = simulate_hexapod(geometry, platform, tanh, controller, **options)
    assert result["locked"].any() and not result["locked"].all()
    moved = np.max(np.abs(result["platform_pose"] - reference["platform_pose"]))
    assert moved > 1e-5  # m or rad: the laws act
    z = result["relative_position"]
    forces = np.column_stack([law.force(z[:, i]) for i, law in enumerate(laws)])
    np.testing.assert_allclose(result["spring_force"], forces, rtol=1e-12, atol=1e-9)
    energy = sum(law.energy(z[:, i]) for i, law in enumerate(laws))
    np.testing.assert_allclose(result["spring_energy"], energy, rtol=1e-12, atol=1e-12)
    residual = np.max(np.abs(result.energy_residual())) / np.max(np.abs(result["base_work"]))
    assert residual < 1e-7
    meta = result.metadata()
    assert meta["isolator.leg3.spring.law"][0] == "polynomial"
    assert meta["isolator.leg5.spring.law"][0] == "oblique"
    assert "isolator.leg1.spring.law" not in meta  # the tanh of the fields
    validation("Hexapod with a polynomial and an oblique-spring leg: energy ledger",
               "energy balance: base + motor work = mechanical energy change + dissipation",
               residual, 1e-7, measure="largest residual / largest |base work|")


def test_a_refusing_table_left_mid_run_stops_naming_the_leg_and_the_range():
    """A table over [-0.14, 0.021] m refusing positions outside it, the stops at [-0.14, 0.02]
    m; a 0.1 m base motion throws the legs into their stops and past the table's end: the run
    stops with the single axis's message, the leg named, the position it reached just beyond
    the end it passed, the velocity carrying it there."""
    table = TabulatedSpring.from_law(ObliqueSpringQZS(), np.linspace(-0.14, 0.021, 162))
    isolator = IsolatorParameters(spring=table)
    with pytest.raises(SimulationError, match=r"leg \d left the spring table \[-0\.14, 0\.021\] "
                                              r"m past its end at ") as error:
        simulate_hexapod(vertical_legs(), _six_masses(isolator), isolator,
                         excitation={"z": Sine(amplitude=0.1, frequency=2.0, fade_in=0.0)},
                         duration=1.0)
    text = str(error.value)
    assert "outside='extend'" in text
    end = float(text.split("past its end at ")[1].split(" m")[0])
    z = float(text.split("reached z = ")[1].split(" m")[0])
    v = float(text.split("moving at v = ")[1].split(" m/s")[0])
    assert end in (-0.14, 0.021)
    assert 0 < (z - end) * np.sign(v) < 1e-3  # just past the end, moving outwards


def test_the_leg_that_leaves_its_refusing_table_is_the_one_named():
    """Leg 4 alone refuses positions outside its table, the other five extend the same table
    beyond its ends: the legs move alike, only leg 4 leaves a table, and the run's error names
    leg 4 (legs are numbered from 1)."""
    positions = np.linspace(-0.14, 0.021, 162)
    refusing = IsolatorParameters(spring=TabulatedSpring.from_law(ObliqueSpringQZS(), positions))
    extending = IsolatorParameters(spring=TabulatedSpring.from_law(ObliqueSpringQZS(), positions,
                                                                   outside="extend"))
    legs = [extending] * 3 + [refusing] + [extending] * 2
    with pytest.raises(SimulationError, match=r"leg 4 left the spring table \[-0\.14, 0\.021\] "
                                              r"m past its end at "):
        simulate_hexapod(vertical_legs(), _six_masses(refusing), legs,
                         excitation={"z": Sine(amplitude=0.1, frequency=2.0, fade_in=0.0)},
                         duration=1.0)
