"""The plan of the six-axis runs: where a chirp's trusted band starts."""
import pytest

from qzs.workflows.hexapod.transmissibility.plan import sweep_trusted_from


@pytest.mark.parametrize("f0, f1, duration, fft_length, rate", [
    (0.0, 20.0, 60.0, 16384, 1000.0), (2.0, 12.0, 200.0, 32768, 1000.0),
    (0.5, 5.0, 30.0, 4096, 500.0)])
def test_the_trusted_band_starts_where_the_chirp_is_a_quarter_segment_in(f0, f1, duration,
                                                                         fft_length, rate):
    """A linear chirp is at f0 + (f1 - f0) t / T after t [s]; a quarter segment is
    fft_length / (4 rate) [s]: bins below that frequency sit under the first segment's
    rising taper alone."""
    quarter = fft_length / rate / 4
    assert sweep_trusted_from(f0, f1, duration, fft_length, rate) == pytest.approx(
        f0 + (f1 - f0) * quarter / duration)


@pytest.mark.parametrize("legs", [False, True])
def test_blocks_are_refused_before_any_run(monkeypatch, legs):
    """The matrix's linear overlay models PI + damping alone: a controller with blocks (every
    leg's, or one leg's own) is refused naming it and the way out, before any chirp runs."""
    from qzs.errors import ParameterError
    from qzs.model.controller import ControllerParameters, Dither
    from qzs.workflows.hexapod.setups import hexapod_setup
    from qzs.workflows.hexapod.transmissibility import hexapod_transmissibility

    def no_run(*args, **kwargs):
        raise AssertionError("a run started")

    for name in ("_dry_run", "run_axis"):
        monkeypatch.setattr(f"qzs.workflows.hexapod.transmissibility.matrix.{name}", no_run)
    dither = ControllerParameters(pi_kp=2000.0) + Dither(amplitude=1.0, frequency=30.0)
    setup = (hexapod_setup(controller=ControllerParameters(pi_kp=2000.0), legs={3: dither})
             if legs else hexapod_setup(controller=dither))
    with pytest.raises(ParameterError, match=r"linear overlay \(hexapod_linearize\) models PI "
                       r"\+ damping alone; `controller` has blocks.*dither \(1 N at 30 Hz\).*"
                       r"qzs hexapod simulate"):
        hexapod_transmissibility(setup, axes="z", duration=20.0, workers=1, progress=False)
