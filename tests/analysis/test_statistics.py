"""Run statistics (qzs.analysis.statistics): closed forms of a sampled sine, and blocks added
in any cut and any order of cases give the statistics of the whole run.

The energy ledger (docs/model.md §8): ``E(t) - E(0) = W_base + W_motor - D_friction - D_stop``,
its residual ``dE - (W_base + W_motor - D_friction - D_stop)``. Property that fails if the
code is wrong: on a hand-built block whose ledger closes the residual is zero; a term moved
by ``+x`` moves the residual by ``x`` times that term's sign in the ledger (+1 for ``E``
and the two dissipations, -1 for the two works), so two terms moved together cancel when
their signs differ (work the base puts in and friction takes out) and add when they agree;
a real run's summary residual is the signed ``SimulationResult.energy_residual`` of the
same samples (friction and stop terms non-zero there).
"""
import itertools

import numpy as np
import pytest

from qzs import Chirp, ControllerParameters, simulate
from qzs.analysis.statistics import RunStatistics, SummaryStatistics, run_statistics


def test_statistics_of_a_sine_are_its_closed_forms():
    """One period of z = c + A sin, force F sin, locked a quarter of the time."""
    t = np.arange(1000) / 1000.0
    center, amplitude, force = -0.06, 0.01, 3.0
    stats = run_statistics(center + amplitude * np.sin(2 * np.pi * t),
                           force * np.sin(2 * np.pi * t), t < 0.25, center)
    assert stats["z_min"] == pytest.approx(center - amplitude, abs=1e-15)
    assert stats["z_max"] == pytest.approx(center + amplitude, abs=1e-15)
    assert stats["peak_stroke"] == pytest.approx(amplitude, rel=1e-12)
    assert stats["motor_force_rms"] == pytest.approx(force / np.sqrt(2), rel=1e-12)
    assert stats["locked_fraction"] == 0.25


def test_blocks_of_cases_give_the_statistics_of_the_whole_run():
    rng = np.random.default_rng(3)
    z, force = rng.normal(size=(3, 500)), rng.normal(size=(3, 500))
    locked = rng.random((3, 500)) < 0.3
    centers = np.array([0.0, 0.5, -0.5])
    statistics = RunStatistics(centers)
    for cases in (slice(0, 2), slice(2, 3)):       # the cases in two groups ...
        for cut in (slice(0, 123), slice(123, 500)):  # ... each in two blocks
            statistics.add(z[cases, cut], force[cases, cut], locked[cases, cut], cases)
    result = statistics.result()
    np.testing.assert_array_equal(result["z_min"], z.min(axis=1))
    np.testing.assert_array_equal(result["z_max"], z.max(axis=1))
    np.testing.assert_array_equal(result["peak_stroke"],
                                  np.abs(z - centers[:, None]).max(axis=1))
    np.testing.assert_allclose(result["motor_force_rms"], np.sqrt((force ** 2).mean(axis=1)),
                               rtol=1e-14)
    np.testing.assert_array_equal(result["locked_fraction"], locked.mean(axis=1))


def test_the_summary_measures_the_ledger_residual_and_saturation():
    """A ledger that closes but for a 2 mJ drift, and loops asking for the limit 1/4 of the time."""
    n = 400
    t = np.arange(n) / 100.0
    base_work = 0.05 * np.sin(t)
    drift = 0.002 * t / t[-1]
    block = {"time": t, "relative_position": np.zeros(n), "motor_force": np.zeros(n),
             "pi_force": np.where(np.arange(n) % 4 == 0, 12.0, 1.0), "damping_force": np.zeros(n),
             "locked": np.zeros(n, bool), "stop_contact": np.zeros(n, bool),
             "mechanical_energy": 1.0 + base_work + drift, "base_work": base_work,
             "motor_work": np.zeros(n), "friction_dissipation": np.zeros(n),
             "stop_dissipation": np.zeros(n)}
    summary = SummaryStatistics(stop_center=0.0, motor_force_max=12.0)
    for cut in (slice(0, 150), slice(150, n)):
        summary.add({name: values[cut] for name, values in block.items()})
    result = summary.result()
    assert result["energy_residual_max"] == pytest.approx(0.002, rel=1e-12)
    assert result["base_work_max"] == pytest.approx(np.abs(base_work).max(), rel=1e-15)
    assert result["saturated_fraction"] == 0.25
    assert result["samples"] == n and (result["time_first"], result["time_last"]) == (0.0, t[-1])


# ---------------------------------------------------------------- the energy ledger's signs
#: Each term of the ledger and its sign in the residual dE - (W_b + W_m - D_f - D_s).
LEDGER_SIGNS = {"mechanical_energy": +1, "base_work": -1, "motor_work": -1,
                "friction_dissipation": +1, "stop_dissipation": +1}


def closed_ledger(n=300):
    """A block whose every ledger term is non-zero and whose ledger closes exactly."""
    t = np.arange(n) / 100.0
    terms = {"base_work": 0.4 * np.sin(1.3 * t) + 0.05 * t,
             "motor_work": -0.2 * np.sin(0.7 * t) ** 2,
             "friction_dissipation": 0.03 * t,
             "stop_dissipation": 0.01 * t ** 2 / t[-1]}
    net = (terms["base_work"] + terms["motor_work"] - terms["friction_dissipation"]
           - terms["stop_dissipation"])
    zeros = np.zeros(n)
    return {"time": t, "relative_position": zeros, "motor_force": zeros, "pi_force": zeros,
            "damping_force": zeros, "locked": zeros.astype(bool),
            "stop_contact": zeros.astype(bool), "mechanical_energy": 2.5 + net, **terms}


def ledger_residual(block, cuts=(slice(0, 70), slice(70, 300))):
    summary = SummaryStatistics(stop_center=0.0, motor_force_max=10.0)
    for cut in cuts:
        summary.add({name: values[cut] for name, values in block.items()})
    return summary.result()["energy_residual_max"]


#: A perturbation that is zero at the first sample (where E(0) is read), 7 mJ at its largest.
def _bump(t):
    return 0.007 * np.sin(np.pi * t / t[-1]) ** 2


def test_a_closed_ledger_has_no_residual():
    block = closed_ledger()
    assert ledger_residual(block) == pytest.approx(0.0, abs=1e-15)
    # the same in one block: E(0) is the run's first sample, not each block's
    assert ledger_residual(block, (slice(None),)) == pytest.approx(0.0, abs=1e-15)


@pytest.mark.parametrize("term", LEDGER_SIGNS)
def test_one_term_moved_by_x_moves_the_residual_by_x(term):
    block = closed_ledger()
    x = _bump(block["time"])
    block[term] = block[term] + x
    assert ledger_residual(block) == pytest.approx(np.abs(x).max(), rel=1e-12)


@pytest.mark.parametrize("first, second", list(itertools.combinations(LEDGER_SIGNS, 2)))
def test_two_terms_moved_together_cancel_or_add_as_their_signs_say(first, second):
    """E.g. energy the base puts in (W_base + x) that friction dissipates (D_friction + x)
    leaves the ledger closed; the base's extra work stored as energy (E + x) too."""
    block = closed_ledger()
    x = _bump(block["time"])
    block[first] = block[first] + x
    block[second] = block[second] + x
    expected = abs(LEDGER_SIGNS[first] + LEDGER_SIGNS[second]) * np.abs(x).max()
    assert ledger_residual(block) == pytest.approx(expected, rel=1e-12, abs=1e-15)


def test_a_runs_summary_residual_is_its_signed_ledger():
    """The passive guide with active damping under a 10 s chirp reaches the stops and slides,
    and its motor works: every term of its ledger moves. The summary's residual is the
    largest |E - E(0) - net| of ``SimulationResult.energy_residual`` (a second writing of
    the ledger), and the ledger closes to truncation error."""
    controller = ControllerParameters(pi_kp=0.0, pi_ki=0.0, damping_gain=20.0)
    result = simulate(Chirp(duration=10.0), controller=controller, dt=1e-4, sample_rate=1e3)
    for name in ("base_work", "motor_work", "friction_dissipation", "stop_dissipation"):
        assert np.abs(result[name]).max() > 0.1, name
    signed = result.energy_residual()
    assert result.statistics["energy_residual_max"] == pytest.approx(np.abs(signed).max(),
                                                                     rel=1e-9)
    # a wrong sign on any term would leave joules; truncation leaves 1e-4 J of 257 J
    assert np.abs(signed).max() < 1e-6 * result.statistics["base_work_max"]


def test_the_dithers_acceleration_is_the_amplitude_of_its_first_harmonic_block_by_block():
    """Over whole dither periods, a payload acceleration ``3 sin(w t + 0.4)`` plus a 4 m/s^2
    component ``4 cos(w t)`` and a harmonic at ``2 w`` that the coefficient rejects has the
    amplitude ``hypot(3, 4) = 5`` m/s^2 at the dither's frequency, fed whole or in uneven
    blocks; a block force ``F0 sin(w t)`` has the RMS ``F0 / sqrt(2)``."""
    from qzs.analysis.statistics import BlockStatistics

    frequency, n = 40.0, 4000
    w = 2 * np.pi * frequency
    t = np.arange(n) / (n / 0.25)  # 0.25 s: ten whole dither periods
    acceleration = np.array([3 * np.sin(w * t + 0.4) + 2 * np.sin(2 * w * t),
                             4 * np.cos(w * t)])
    force = 1.5 * np.sin(w * t)
    expected = {"dither_force_rms": 1.5 / np.sqrt(2), "dither_payload_acceleration": 5.0}
    for cuts in ((n,), (1000, 2999, n)):
        stats = BlockStatistics([("dither_force",)], [frequency])
        start = 0
        for end in cuts:
            stats.add(t[start:end], {"dither_force": force[None, start:end]},
                      acceleration[:, start:end])
            start = end
        result = stats.result()
        assert set(result) == set(expected), cuts
        for name, value in expected.items():
            assert result[name] == pytest.approx(value, rel=1e-9, abs=1e-12), (cuts, name)
