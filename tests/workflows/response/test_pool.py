"""The sweeps' chains (qzs.workflows.response.pool): a pool of processes gives the numbers of
one process, every sweep starting from rest and every later frequency from the last state."""
from qzs.workflows.response import steady_state_response


def test_parallel_sweeps_equal_serial_ones():
    options = dict(direction="both", dt=1e-3, harmonic_balance=False)
    frequencies = [2.0, 3.0, 5.0]
    serial = steady_state_response(frequencies, workers=1, **options)
    parallel = steady_state_response(frequencies, workers=2, **options)
    strip = [{k: v for k, v in p.to_dict().items() if k != "seconds"} for p in serial.points]
    assert strip == [{k: v for k, v in p.to_dict().items() if k != "seconds"}
                     for p in parallel.points]
    # every sweep starts from rest, later frequencies from the previous state
    assert [p.start for p in serial.points] == ["rest", "continued", "continued"] * 2
