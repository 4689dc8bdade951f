"""Hunting at rest in the design: the relay's prediction confirmed by simulation."""
import pytest


def test_hunting_of_the_pi_loop_alone_confirms_the_relay_and_refutes_the_friction_law(design):
    alone = [r for r in design.hunting["rows"] if r["damping_gain"] == 0.0]
    assert {r["stiction_force"] for r in alone} == {8.0, 10.0, 12.0}
    for row in alone:
        assert row["simulation"]["hunts"] and row["prediction"]["hunts"]
        assert row["relay_confirmed"] is True
        assert row["memoryless_confirmed"] is False  # it predicted no cycle
        assert row["simulation"]["amplitude"] == pytest.approx(row["prediction"]["amplitude"],
                                                               rel=0.15)


def test_the_locus_meets_the_relays_minus_inverse_at_the_predicted_point(design):
    locus = design.hunting["loop"]
    assert locus["stiction_force"] == 12.0  # the highest stiction of the range
    point = locus["intersection"]
    assert point is not None
    # the relay's -1/N at its amplitudes passes through the intersection
    assert min(abs(locus["minus_inverse"] - point)) < 0.05 * abs(point)
    # and so does the loop's Nyquist curve
    assert min(abs(locus["loop"] - point)) < 0.05 * abs(point)
