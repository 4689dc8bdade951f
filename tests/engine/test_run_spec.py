"""A run resolved once (qzs.engine.run_spec): the same inputs give the same step and the same
bits from the API, the command line and the page; the duration reaches the step search.

Properties that fail if the resolution is wrong:

* ``qzs.simulate(..., tolerance=0.01)``, ``qzs simulate --tolerance 0.01 --out`` and the page
  integrate at one step and give bit-identical series;
* the step of a run shorter than its chirp is chosen over the band the run covers (a chirp
  of the same sweep law ended at the frequency the run reaches), not the whole sweep's;
* a stationary excitation (a sine, a random one) is never probed longer than its run: every
  probe run of a 2 s sine run integrates 2 s, not the sine's own 15.3 s probe;
* a literal step is a record too (nothing chosen, no estimate), and asking for a step two
  ways, or for more samples than can be counted, is refused before any run.
"""
import json
import math

import numpy as np
import pytest

import qzs
from qzs import Chirp, ControllerParameters, IsolatorParameters, Sine
from qzs.engine.accuracy import excitation_over
from qzs.errors import ParameterError

CHIRP = Chirp(duration=30.0, f1=5.0)


def test_api_command_line_and_page_give_the_same_step_and_bits(tmp_path, capsys):
    from qzs.app.compute import resolve_page_run
    from qzs.cli import main

    isolator, controller = IsolatorParameters(), ControllerParameters()
    api = qzs.simulate(CHIRP, isolator, controller, tolerance=0.01)
    assert api.step.chosen and api.step.met and api.run["dt"] == api.step.dt
    out = tmp_path / "run.nc"
    assert main(["simulate", "--excitation-duration", "30", "--f1", "5", "--tolerance", "0.01",
                 "--out", str(out), "--plot", "none", "--json"]) == 0
    record = json.loads(capsys.readouterr().out)
    assert record["step"]["dt"] == api.step.dt and record["step"]["error"] == api.step.error
    page = resolve_page_run(CHIRP, isolator, controller, 1000.0).simulate()
    assert page.step.dt == api.step.dt
    import xarray as xr

    with xr.open_dataset(out) as data:
        for name in ("relative_position", "payload_acceleration", "friction_force",
                     "motor_force"):
            np.testing.assert_array_equal(data[name].values, api[name])
            np.testing.assert_array_equal(page[name], api[name])
    # the command line's default accuracy is the API's tolerance=0.01 (one decision)
    default = qzs.resolve(CHIRP, step="chosen")
    assert default.step.tolerance == qzs.defaults.ACCURACY["tolerance_db"]
    assert default.dt == api.step.dt


def test_a_run_shorter_than_its_chirp_chooses_its_step_over_the_band_it_covers():
    """The paper's 2000 s chirp cut at 60 s covers 0-0.6 Hz: the probe sweeps that band."""
    covered = excitation_over(Chirp(), 60.0)
    assert covered.duration == 60.0 and math.isclose(covered.f1, 0.6)
    t = np.linspace(0.0, 60.0, 601)
    np.testing.assert_allclose(covered.frequency_at(t), Chirp().frequency_at(t), rtol=1e-12)
    assert excitation_over(Chirp(), 2000.0) == Chirp()
    assert excitation_over(Sine(frequency=2.0), 5.0) == Sine(frequency=2.0)
    run = qzs.resolve(Chirp(), duration=60.0, step="chosen")
    assert run.step.band[1] == pytest.approx(0.6)  # not the whole sweep's 20 Hz
    assert run.step.probe.f1 < 1.0 and run.step.probe_duration <= 60.0
    whole = qzs.resolve(Chirp(duration=200.0, f1=20.0), step="chosen")
    assert whole.step.band[1] == 20.0


@pytest.mark.parametrize("excitation, own_probe", [
    (Sine(amplitude=0.008, frequency=3.0, fade_in=2.0), 2.0 + 40 / 3.0),  # fade-in, 40 periods
    (qzs.RandomExcitation(duration=200.0, f_high=10.0), 60.0)], ids=["sine", "random"])
def test_a_stationary_excitation_is_never_probed_longer_than_its_run(monkeypatch, excitation,
                                                                     own_probe):
    """A 2 s run of a 3 Hz sine: its own probe would be the fade-in and 40 periods (15.3 s),
    more than seven times the run. Every probe run integrates the run's 2 s, no more, and the
    record says so; a run longer than the probe keeps the probe's own length (a random
    excitation's: 60 s)."""
    from qzs.engine import single

    integrated = []
    original = single.integrate

    def recording(*args, **kwargs):
        integrated.append((kwargs["duration"], kwargs["dt"]))
        return original(*args, **kwargs)

    monkeypatch.setattr(single, "integrate", recording)
    run = qzs.resolve(excitation, duration=2.0, step="chosen", cache=False)
    assert len(integrated) >= 3  # the search compared at least three steps
    assert {duration for duration, _ in integrated} == {2.0}
    assert run.step.probe_duration == 2.0 and run.duration == 2.0
    integrated.clear()
    longer = qzs.resolve(excitation, duration=100.0, step="chosen", cache=False)
    probed = {duration for duration, _ in integrated}
    # a whole number of output periods (1 ms) of the probe's own length
    assert probed == {longer.step.probe_duration}
    assert longer.step.probe_duration == pytest.approx(own_probe, abs=1e-3)


def test_a_literal_step_is_a_record_and_the_python_default_is_the_papers_step():
    run = qzs.resolve(CHIRP)
    assert run.dt == qzs.defaults.SIMULATION["dt"] and not run.step.chosen
    assert run.step.attributes() == {"step": "given"}
    assert run.step.to_dict() == {"dt": 1e-4, "chosen": False}
    result = qzs.simulate(Sine(frequency=2.0), duration=0.5, dt=5e-4)
    assert result.step.dt == 5e-4 and not result.step.chosen


@pytest.mark.parametrize("options, match", [
    (dict(dt=1e-4, tolerance=0.01), "give one of `dt`, `tolerance`"),
    (dict(tolerance=0.01, tolerance_state=1e-5), "give one of"),
    (dict(excitation=Sine(frequency=2.0), duration=1e308), "output samples"),
    (dict(step="fast"), "`step`"),
])
def test_inconsistent_or_impossible_requests_are_refused_before_any_run(options, match,
                                                                        monkeypatch):
    import qzs.engine.step_choice as step_choice

    def no_search(*args, **kwargs):
        raise AssertionError("a step was searched")

    monkeypatch.setattr(step_choice, "choose", no_search)
    with pytest.raises(ParameterError, match=match):
        qzs.resolve(**{"excitation": Chirp(), **options})


def test_a_transmissibility_tolerance_for_a_sine_is_refused():
    with pytest.raises(ParameterError, match="tolerance_state"):
        qzs.resolve(Sine(frequency=2.0), duration=1.0, tolerance=0.01)


def test_the_length_check_counts_at_the_kernels_own_speed():
    """1e12 steps (1e9 s at 1 kHz): 8.3 h of the single axis at its best, started; 3.5
    days of the six-leg platform, refused before any run (qzs hexapod transmissibility
    --duration 1e9 refused only in its worker processes)."""
    from qzs.engine.run_spec import check_length
    from qzs.errors import ParameterError

    check_length(1e9, 1000.0, None)
    with pytest.raises(ParameterError, match="`duration` 1e[+]09 s is at least 1e[+]12 "
                                             "integration steps") as caught:
        check_length(1e9, 1000.0, None, kernel="hexapod")
    assert caught.value.options == ("duration", "sample_rate")
    # a given dt: the same count, refused as the driver refuses it (RunTooLongError)
    check_length(1e9, 1000.0, 1e-3)
    with pytest.raises(qzs.errors.RunTooLongError):
        check_length(1e9, 1000.0, 1e-3, kernel="hexapod")
