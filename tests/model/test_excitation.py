"""Tests of qzs.excitation: closed forms, derivative consistency, reproducibility, errors."""
import numpy as np
import pytest
from helpers import linear_controller, linear_isolator
from scipy import signal

from qzs import Chirp, DisplacementRecord, ExcitationError, ParameterError, RandomExcitation, Sine, simulate
from qzs.engine import base_motion_series
from qzs.errors import DataError
from qzs.model.excitation import build_excitation, highest_frequency, read_displacement_csv


def _record(nonuniform=False):
    rng = np.random.default_rng(7)
    if nonuniform:
        time = np.cumsum(rng.uniform(0.5e-3, 1.5e-3, 3000))
    else:
        time = np.arange(3000) * 1e-3 + 5.0  # starts at 5 s: shifted to 0
    displacement = 0.004 * np.sin(2 * np.pi * 1.3 * time) + 0.002 * np.sin(2 * np.pi * 7.1 * time + 1.0)
    return DisplacementRecord(time=time, displacement=displacement)


EXCITATIONS = {
    "linear chirp": Chirp(amplitude=0.010, f0=0.0, f1=20.0, duration=10.0),
    "down chirp": Chirp(amplitude=0.005, f0=15.0, f1=2.0, duration=10.0),
    "log chirp": Chirp(amplitude=0.010, f0=0.5, f1=20.0, duration=10.0, method="logarithmic"),
    "sine": Sine(amplitude=0.003, frequency=7.0, phase=0.4, fade_in=0.0),
    "random": RandomExcitation(amplitude=0.002, f_low=0.5, f_high=20.0, duration=10.0, seed=3),
    "record": _record(),
    "nonuniform record": _record(nonuniform=True),
}


# ------------------------------------------------------------------ derivative consistency
@pytest.mark.parametrize("name", EXCITATIONS)
def test_velocity_and_acceleration_are_derivatives_of_displacement(name):
    excitation = EXCITATIONS[name]
    time = np.linspace(0.0123, 2.4567, 997)  # off the tabulation knots (y''' jumps there)
    h = 1e-7
    y, yd, ydd = base_motion_series(excitation, time)
    y_plus, yd_plus, _ = base_motion_series(excitation, time + h)
    y_minus, yd_minus, _ = base_motion_series(excitation, time - h)
    # central differences: truncation h^2/6 * y''' for the harmonic kinds; for the splines at most
    # h/2 * (jump of y''' at a knot); rounding ~ 1e-16 * y / h; all below 1e-6 of the scale
    np.testing.assert_allclose((y_plus - y_minus) / (2 * h), yd, rtol=0, atol=1e-6 * np.abs(yd).max())
    np.testing.assert_allclose((yd_plus - yd_minus) / (2 * h), ydd, rtol=0, atol=1e-6 * np.abs(ydd).max())


# ------------------------------------------------------------------ closed forms
def test_sine_closed_form():
    excitation = EXCITATIONS["sine"]
    t = np.linspace(0, 3, 301)
    w = 2 * np.pi * 7.0
    y, yd, ydd = base_motion_series(excitation, t)
    np.testing.assert_allclose(y, 0.003 * np.sin(w * t + 0.4), rtol=0, atol=1e-15)
    np.testing.assert_allclose(yd, 0.003 * w * np.cos(w * t + 0.4), rtol=0, atol=1e-13)
    np.testing.assert_allclose(ydd, -0.003 * w**2 * np.sin(w * t + 0.4), rtol=0, atol=1e-11)
    assert excitation.duration is None and excitation.max_frequency == 7.0


def test_linear_chirp_closed_form_and_constant_displacement_envelope(validation):
    amplitude, f0, f1, duration = 0.010, 0.0, 20.0, 10.0
    t = np.linspace(0, duration, 5001)
    y, yd, _ = base_motion_series(EXCITATIONS["linear chirp"], t)
    phase = 2 * np.pi * (f0 * t + 0.5 * (f1 - f0) / duration * t**2)
    np.testing.assert_allclose(y, amplitude * np.sin(phase), rtol=0, atol=1e-13)
    omega = 2 * np.pi * (f0 + (f1 - f0) * t / duration)  # instantaneous angular frequency
    inside = omega > 0
    envelope = (y[inside] / amplitude) ** 2 + (yd[inside] / (amplitude * omega[inside])) ** 2
    np.testing.assert_allclose(envelope, 1.0, rtol=1e-12)
    validation("Linear chirp displacement", "A sin(2 pi (f0 t + (f1 - f0) t^2 / (2 T)))",
               np.abs(y - amplitude * np.sin(phase)).max(), 1e-13, measure="absolute error [m]")
    validation("Linear chirp: constant displacement amplitude", "(y/A)^2 + (y'/(A w(t)))^2 = 1",
               np.abs(envelope - 1.0).max(), 1e-12)


def test_logarithmic_chirp_closed_form():
    amplitude, f0, f1, duration = 0.010, 0.5, 20.0, 10.0
    t = np.linspace(0, duration, 5001)
    y, yd, _ = base_motion_series(EXCITATIONS["log chirp"], t)
    growth = np.log(f1 / f0) / duration
    phase = 2 * np.pi * f0 / growth * (np.exp(growth * t) - 1)
    np.testing.assert_allclose(y, amplitude * np.sin(phase), rtol=0, atol=1e-12)
    omega = 2 * np.pi * f0 * np.exp(growth * t)
    np.testing.assert_allclose((y / amplitude) ** 2 + (yd / (amplitude * omega)) ** 2, 1.0, rtol=1e-11)
    assert omega[-1] == pytest.approx(2 * np.pi * f1, rel=1e-12)


# ------------------------------------------------------------------ random excitation
def test_random_excitation_same_seed_same_signal_other_seed_differs():
    t = np.linspace(0, 10, 20001)
    a = base_motion_series(RandomExcitation(duration=10.0, seed=11), t)
    b = base_motion_series(RandomExcitation(duration=10.0, seed=11), t)
    c = base_motion_series(RandomExcitation(duration=10.0, seed=12), t)
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)
    correlation = np.corrcoef(a[0], c[0])[0, 1]
    assert abs(correlation) < 0.2
    assert np.max(np.abs(a[0] - c[0])) > 0.5 * 0.001


def test_same_seed_gives_identical_simulations():
    excitation = RandomExcitation(amplitude=0.003, f_low=1.0, f_high=15.0, duration=5.0, seed=5)
    first = simulate(excitation, dt=1e-4, sample_rate=500.0)
    again = simulate(RandomExcitation(amplitude=0.003, f_low=1.0, f_high=15.0, duration=5.0, seed=5),
                     dt=1e-4, sample_rate=500.0)
    other = simulate(RandomExcitation(amplitude=0.003, f_low=1.0, f_high=15.0, duration=5.0, seed=6),
                     dt=1e-4, sample_rate=500.0)
    np.testing.assert_array_equal(first.payload_acceleration, again.payload_acceleration)
    assert not np.array_equal(first.base_acceleration, other.base_acceleration)
    assert not np.array_equal(first.payload_acceleration, other.payload_acceleration)


@pytest.mark.parametrize("duration", [10.0, 10.0025])  # an even and an odd number of knots
def test_random_excitation_rms_is_its_amplitude(duration):
    excitation = RandomExcitation(amplitude=0.002, f_low=0.5, f_high=20.0, duration=duration, seed=1,
                                  fade_in=0.0)
    spacing = 1 / (20 * 20.0)
    knots = np.arange(int(np.ceil(duration / spacing)) + 1) * (duration / np.ceil(duration / spacing))
    y_knots = base_motion_series(excitation, knots)[0]
    assert np.sqrt(np.mean(y_knots**2)) == pytest.approx(0.002, rel=1e-12)
    dense = np.linspace(0, duration, 200_001)
    assert np.sqrt(np.mean(base_motion_series(excitation, dense)[0] ** 2)) == pytest.approx(0.002, rel=0.01)
    assert abs(np.mean(y_knots)) < 0.02 * 0.002  # no DC line


def test_random_excitation_spectrum_lies_in_its_band():
    f_low, f_high, fs = 2.0, 10.0, 400.0
    excitation = RandomExcitation(amplitude=0.002, f_low=f_low, f_high=f_high, duration=40.0, seed=2)
    t = np.arange(int(40.0 * fs)) / fs
    frequency, power = signal.periodogram(base_motion_series(excitation, t)[0], fs=fs, window="hann")
    band = (frequency >= f_low - 0.1) & (frequency <= f_high + 0.1)
    assert power[band].sum() > 0.999 * power.sum()
    inside = (frequency > f_low + 0.5) & (frequency < f_high - 0.5)
    # flat displacement spectrum: one tenth-octave average does not stray far from the mean
    level = power[inside].mean()
    for lo in np.arange(f_low + 0.5, f_high - 1.5, 1.0):
        chunk = power[(frequency >= lo) & (frequency < lo + 1.0)].mean()
        assert 0.5 * level < chunk < 2.0 * level


# ------------------------------------------------------------------ displacement record
def test_record_passes_through_its_samples_and_starts_at_zero():
    time = np.arange(3000) * 1e-3 + 5.0
    displacement = 0.004 * np.sin(2 * np.pi * 1.3 * time)
    record = DisplacementRecord(time=time, displacement=displacement, fade_in=0.0)
    assert record.time[0] == 0.0
    assert record.duration == pytest.approx(2.999, rel=1e-12)
    assert record.max_frequency == pytest.approx(500.0, rel=1e-9)
    np.testing.assert_allclose(base_motion_series(record, record.time)[0], displacement, rtol=0, atol=1e-15)


def test_record_of_a_sine_drives_the_simulator_like_the_sine():
    """The tabulated path (spline) and the analytic path give the same run (the same fade-in)."""
    sine = Sine(amplitude=0.005, frequency=2.0, fade_in=1.0)
    time = np.arange(0, 5.0 + 1e-9, 1e-3)
    record = DisplacementRecord(time=time, displacement=0.005 * np.sin(2 * np.pi * 2.0 * time),
                                fade_in=1.0)
    plant = linear_isolator(stiffness=100.0)
    controller = linear_controller(pi_kp=200.0, pi_ki=100.0)
    from_sine = simulate(sine, plant, controller, duration=4.0, sample_rate=100.0)
    from_record = simulate(record, plant, controller, duration=4.0, sample_rate=100.0)
    # a cubic spline's second derivative is accurate to ~ (w*h)^2/12 = 1.3e-5 of w^2*A
    np.testing.assert_allclose(from_record.base_displacement, from_sine.base_displacement, rtol=0,
                               atol=1e-12 * 0.005)
    np.testing.assert_allclose(from_record.base_acceleration, from_sine.base_acceleration, rtol=0,
                               atol=3e-5 * 0.005 * (4 * np.pi) ** 2)
    np.testing.assert_allclose(from_record.payload_displacement, from_sine.payload_displacement, rtol=0,
                               atol=1e-5 * 0.005)


# ------------------------------------------------------------------ errors
@pytest.mark.parametrize("factory, match", [
    (lambda: Chirp(f0=0.0, method="logarithmic"), r"logarithmic chirp needs `f0` > 0.*`f0` = 0.0"),
    (lambda: Chirp(method="exponential"), r"`method` must be one of 'linear', 'logarithmic', got 'exponential'"),
    (lambda: Chirp(amplitude=-0.01), r"`amplitude` must be non-negative, got -0.01"),
    (lambda: Chirp(duration=0.0), r"`duration` must be positive, got 0.0"),
    (lambda: Chirp(f1=float("nan")), r"`f1` must be finite, got nan"),
    (lambda: Sine(frequency=-1.0), r"`frequency` must be non-negative, got -1.0"),
    (lambda: Sine(phase=True), r"`phase` must be a number, got the boolean True"),
    (lambda: RandomExcitation(f_low=5.0, f_high=5.0), r"`f_low` \(5.0 Hz\) must be below `f_high`"),
    (lambda: RandomExcitation(f_low=8.0, f_high=2.0), r"`f_low` \(8.0 Hz\) must be below `f_high`"),
    (lambda: RandomExcitation(seed=1.5), r"`seed` must be an integer in \[0, .*\], got 1.5"),
    (lambda: RandomExcitation(seed=True), r"`seed` must be an integer in \[0, .*\], got the boolean True"),
    (lambda: DisplacementRecord(time=[0, 1, 2], displacement=[0, 1, 2]), "at least 4 samples, got 3"),
    (lambda: DisplacementRecord(time=[0, 1, 1, 2], displacement=[0, 0, 0, 0]),
     r"`time` must be strictly increasing, but it is duplicated at sample 2 \("),
    (lambda: DisplacementRecord(time=[0, 2, 1, 3], displacement=[0, 0, 0, 0]), "strictly increasing"),
    (lambda: DisplacementRecord(time=[0, 1, 2, 3], displacement=[0, np.nan, 0, 0]),
     "`displacement` has 1 non-finite samples"),
    (lambda: DisplacementRecord(time=[0, 1, np.inf, 3], displacement=[0, 0, 0, 0]),
     "`time` has 1 non-finite samples"),
    (lambda: DisplacementRecord(time=[0, 1, 2, 3], displacement=[0, 0, 0]), r"same length.*\(4,\) and \(3,\)"),
])
def test_bad_excitation_is_rejected_with_a_clear_message(factory, match):
    with pytest.raises(ExcitationError, match=match) as info:
        factory()
    assert isinstance(info.value, ParameterError)


def test_non_monotonic_time_message_shows_plain_numbers():
    with pytest.raises(ExcitationError) as info:
        DisplacementRecord(time=np.array([0.0, 1.0, 1.0, 2.0]), displacement=np.zeros(4))
    assert "at sample 2 (t = 1.0 s after t = 1.0 s; 1 such steps)" in str(info.value)
    assert "np.float64" not in str(info.value)


def test_band_without_a_frequency_line_is_rejected_when_packed():
    excitation = RandomExcitation(f_low=0.01, f_high=0.02, duration=10.0)  # lines every 0.1 Hz
    with pytest.raises(ExcitationError, match="lengthen `duration` or widen the band"):
        excitation.pack()


def test_excitations_reject_unknown_keywords():
    with pytest.raises(TypeError):
        Chirp(frequency=1.0)
    with pytest.raises(TypeError):
        Sine(duration=3.0)


# ---------------------------------------------------------------- names in the messages
@pytest.mark.parametrize("kind, options, names, message", [
    ("random", {"f0": 30.0, "f1": 10.0}, {"f0": "--f0", "f1": "--f1"},
     r"`--f0` \(30.0 Hz\) must be below `--f1` \(10.0 Hz\)"),
    ("random", {"f0": 30.0, "f1": 10.0}, None, r"`f0` \(30.0 Hz\) must be below `f1`"),
    ("chirp", {"duration": 0.0}, {"duration": "--excitation-duration"},
     r"`--excitation-duration` must be positive, got 0.0"),
    ("sine", {"fade_in": -1.0}, {"fade_in": "[excitation] fade_in"},
     r"`\[excitation\] fade_in` must be non-negative"),
])
def test_build_excitation_names_the_options_as_the_caller_does(kind, options, names, message):
    """A random band's fields are f_low/f_high, its options f0/f1: a message names what the
    caller wrote (the command line's flags), never a field the caller has not seen."""
    with pytest.raises(ExcitationError, match=message):
        build_excitation(kind, options, names=names)


@pytest.mark.parametrize("make, message", [
    (lambda folder: folder, "is a folder; pass the CSV file"),
    (lambda folder: _write(folder / "junk.csv", bytes(range(256))), "is not UTF-8 text"),
])
def test_a_record_that_is_a_folder_or_binary_is_a_data_error(tmp_path, make, message):
    path = make(tmp_path)
    with pytest.raises(DataError, match=message):
        read_displacement_csv(path)
    with pytest.raises(DataError, match=f"^--record: .*{message}"):
        build_excitation("file", {"record": str(path)}, names={"record": "--record"})


def _write(path, content):
    path.write_bytes(content)
    return path


def test_highest_frequency_within_the_run():
    assert highest_frequency(Chirp(f0=0.0, f1=20.0, duration=100.0), 50.0) == pytest.approx(10.0)
    assert highest_frequency(Chirp(f0=20.0, f1=0.0, duration=100.0), 50.0) == 20.0
    assert highest_frequency(Chirp(f0=0.0, f1=20.0, duration=100.0)) == 20.0
    assert highest_frequency(Sine(frequency=3.0)) == 3.0
    assert highest_frequency(RandomExcitation(f_low=1.0, f_high=15.0)) == 15.0


@pytest.mark.parametrize("make, frequency", [
    (lambda a: Chirp(amplitude=a, f0=0.0, f1=20.0, duration=10.0), 20.0),
    (lambda a: Sine(amplitude=a, frequency=20.0), 20.0),
    (lambda a: RandomExcitation(amplitude=a, f_low=1.0, f_high=20.0, duration=10.0), 20.0)])
def test_an_amplitude_that_overflows_the_base_acceleration_is_refused(make, frequency):
    """(2 pi f)^2 A beyond float64 (with room for the forces) is bad input naming
    `amplitude`; an amplitude a factor 100 inside the bound is taken."""
    crest = 4.0 if isinstance(make(1.0), RandomExcitation) else 1.0
    bound = np.finfo(float).max / ((2 * np.pi * frequency) ** 2 * 1e3 * crest)
    with pytest.raises(ExcitationError, match="`amplitude`") as error:
        make(bound * 1.01)
    assert error.value.options[0] == "amplitude"  # the command line names its flag
    make(bound / 100)
