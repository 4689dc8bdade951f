"""The response's points and views (qzs.workflows.response.result): branches in ascending
frequency, the table."""
import numpy as np


def test_branches_are_in_ascending_frequency(small_response):
    assert small_response.directions == ("up", "down")
    assert [p.frequency for p in small_response.points] == [2.0, 4.0, 8.0, 8.0, 4.0, 2.0]
    for direction in small_response.directions:
        branch = small_response.branch(direction)
        np.testing.assert_array_equal(branch["frequency"], [2.0, 4.0, 8.0])
        assert branch["harmonics"].shape == (3, 4)
        assert set(branch["direction"]) == {direction}


def test_summary(small_response):
    text = small_response.summary()
    assert "steady-state response" in text and "8.000" in text
