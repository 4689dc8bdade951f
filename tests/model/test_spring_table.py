"""PCHIP pieces, their exact integrals and the force-curve reader, against scipy and by hand."""
import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

from qzs.errors import DataError, ParameterError
from qzs.model.spring_table import hermite_pieces, pchip_slopes, piece_energies, read_force_curve

RNG = np.random.default_rng(41)


def _tables():
    """Monotone, non-monotone (extrema, sign changes), flat stretches, uneven spacing."""
    x = np.cumsum(RNG.uniform(0.2, 3.0, 30)) * 1e-3
    yield x, -np.tanh(40.0 * (x - x.mean())) * 60.0
    yield x, RNG.normal(0.0, 5.0, x.size)
    yield x, np.where(np.arange(x.size) % 7 < 3, 1.0, RNG.normal(0.0, 1.0, x.size))
    yield np.array([0.0, 1.0, 2.0]), np.array([10.0, 0.0, 1.0])      # end slope limited to 3 m0
    yield np.array([0.0, 0.1, 0.2, 0.3]), np.array([0.0, 1.0, 10.0, 11.0])  # end slope clamped


@pytest.mark.parametrize("x, y", list(_tables()))
def test_the_pieces_are_scipys_pchip(x, y):
    reference = PchipInterpolator(x, y)
    slopes = pchip_slopes(x, y)
    np.testing.assert_allclose(slopes, reference(x, 1), rtol=1e-12, atol=1e-12 * np.ptp(y) / np.ptp(x))
    pieces = hermite_pieces(x, y, slopes)
    # scipy's PPoly holds the same pieces, highest power first
    for power in range(4):
        expected = reference.c[3 - power]
        np.testing.assert_allclose(pieces[:, power], expected, rtol=1e-11,
                                   atol=1e-12 * np.abs(expected).max())


@pytest.mark.parametrize("x, y", list(_tables()))
def test_the_breakpoint_energies_are_minus_the_integral_of_the_pieces(x, y):
    reference = PchipInterpolator(x, y)
    energies = piece_energies(x, hermite_pieces(x, y, pchip_slopes(x, y)))
    integral = reference.antiderivative()
    expected = -(integral(x) - integral(x[0]))
    assert energies[0] == 0.0
    np.testing.assert_allclose(energies, expected, rtol=1e-12,
                               atol=1e-13 * np.abs(y).max() * np.ptp(x))


def test_an_end_slope_of_the_wrong_sign_is_zero_and_one_too_steep_is_three_secants():
    # left end: (3*10 - 90)/2 < 0 against a rising secant -> 0
    assert pchip_slopes(np.array([0.0, 1.0, 2.0]), np.array([0.0, 10.0, 100.0]))[0] == 0.0
    # right end of (10, 0, 1): end secant 1 after -10; the estimate (3*1 + 10)/2 = 6.5 is more
    # than three end secants where the secants change sign -> 3
    slopes = pchip_slopes(np.array([0.0, 1.0, 2.0]), np.array([10.0, 0.0, 1.0]))
    assert slopes[-1] == 3.0


def _write(path, text):
    path.write_text(text)
    return path


def test_a_curve_in_millimetres_and_kilonewtons_comes_back_in_si(tmp_path):
    path = _write(tmp_path / "curve.csv",
                  "# a comment\nforce [kN],position [mm]\n0.06,-140\n0.0,0\n-0.05,20\n")
    positions, forces = read_force_curve(path)
    np.testing.assert_allclose(positions, [-0.14, 0.0, 0.02], rtol=1e-15)
    np.testing.assert_allclose(forces, [60.0, 0.0, -50.0], rtol=1e-15)
    # the units may be given instead of written, and both if they agree
    plain = _write(tmp_path / "plain.csv", "position,force\n-140,60\n0,0\n20,-50\n")
    positions, forces = read_force_curve(plain, position_unit="mm", force_unit="N")
    np.testing.assert_allclose(positions, [-0.14, 0.0, 0.02], rtol=1e-15)
    assert read_force_curve(path, position_unit="mm", force_unit="kN")[1][0] == 60.0


@pytest.mark.parametrize("text, options, error, match", [
    ("position [mm],force [N]\n0,1\n", {"position_unit": "m"}, ParameterError,
     r"`position_unit` is 'm' but the header .* says \[mm\]: mismatched units"),
    ("position,force [N]\n0,1\n", {}, ParameterError,
     r"`position_unit` is not given and the header .* names no unit"),
    ("position,force\n0,1\n", {"position_unit": "cm", "force_unit": "N"}, ParameterError,
     r"`position_unit` must be one of 'm', 'mm', got 'cm'"),
    ("position [inch],force [N]\n0,1\n", {}, DataError,
     r"the header of column 'position' .* says \[inch\]; write it as one of 'm', 'mm'"),
    ("z,force [N]\n0,1\n", {"position_unit": "m"}, DataError,
     r"no column 'position' .* columns found: \['z', 'force \[N\]'\]"),
    ("position [m],force [N]\n0,nan\n1,2\n", {}, DataError, "1 non-finite samples"),
    ("position [m],force [N]\n0,abc\n", {}, DataError, "non-numeric"),
    ("", {}, DataError, "is empty"),
])
def test_a_bad_force_curve_file_is_refused_naming_the_fix(tmp_path, text, options, error, match):
    path = _write(tmp_path / "bad.csv", text)
    with pytest.raises(error, match=match):
        read_force_curve(path, **options)


def test_a_missing_file_or_a_folder_is_a_data_error(tmp_path):
    with pytest.raises(DataError, match="force curve not found"):
        read_force_curve(tmp_path / "none.csv")
    with pytest.raises(DataError, match="is a folder; pass the CSV file"):
        read_force_curve(tmp_path)
