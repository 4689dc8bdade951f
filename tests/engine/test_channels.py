"""A run's channels and flags (qzs.engine.channels): the schema names each once with its unit,
the kernel columns are distinct, and the named block's mechanical energy is the sum of its
four parts."""
import numpy as np

from qzs.engine import kernels as K
from qzs.engine.channels import (CHANNELS, FLAG_MEANINGS, FLAGS, named_block, run_channels,
                                 simulation_schema,
                                 variable_attributes)


def test_channels_and_flags_take_distinct_kernel_columns():
    columns = [column for column, _, _ in CHANNELS.values()]
    assert sorted(columns) == list(range(K.N_BASE_CHANNELS))
    # the blocks' channels follow, each its own column
    every = [column for column, _, _ in run_channels(every_block=True).values()]
    assert sorted(every) == list(range(K.N_CHANNELS))
    assert sorted(column for column, _ in FLAGS.values()) == [0, 1]


def test_the_schema_holds_every_channel_and_flag_with_its_unit():
    attributes = variable_attributes()
    assert list(attributes)[0] == "time"
    assert set(attributes) == set(CHANNELS) | set(FLAGS)
    for name, (_, unit, doc) in CHANNELS.items():
        assert attributes[name]["units"] == unit
        if name != "time":
            assert attributes[name]["long_name"] == doc
    for name in FLAGS:
        assert attributes[name]["flag_meanings"] == FLAG_MEANINGS[name]
        assert len(FLAG_MEANINGS[name].split()) == 2  # the words for 0 and 1
    assert simulation_schema().dimensions == {"time": None}  # unlimited: streamed


def test_named_block_takes_columns_by_name_and_sums_the_energy():
    rng = np.random.default_rng(1)
    data = rng.normal(size=(7, K.N_CHANNELS))
    flags = rng.integers(0, 2, size=(7, 2)).astype(bool)
    block = named_block(data, flags)
    for name, (column, _, _) in CHANNELS.items():
        np.testing.assert_array_equal(block[name], data[:, column])
    for name, (column, _) in FLAGS.items():
        np.testing.assert_array_equal(block[name], flags[:, column])
    expected = (data[:, K.C_E_KINETIC] + data[:, K.C_E_SPRING] + data[:, K.C_E_GRAVITY]
                + data[:, K.C_E_STOP])
    np.testing.assert_array_equal(block["mechanical_energy"], expected)


def test_the_friction_estimate_is_a_channel_only_with_an_observer():
    from qzs import FrictionCompensation, PIDamping

    without = run_channels(PIDamping() + FrictionCompensation(fraction=0.5))
    assert "compensation_force" in without and "friction_estimate" not in without
    observed = run_channels(PIDamping() + FrictionCompensation(observer_bandwidth=5.0))
    assert "friction_estimate" in observed


def test_the_block_costs_are_the_recorded_block_channels_and_the_dithers_frequency():
    """block_costs gives what BlockStatistics takes: the block channels the run records and
    the dither's frequency [Hz] (not its amplitude), None without a dither."""
    from qzs import Dither, FrictionCompensation, PIDamping
    from qzs.engine.channels import BLOCK_CHANNELS, block_costs

    dithered = PIDamping(dither=Dither(amplitude=3.0, frequency=40.0))
    blocks, frequency = block_costs(dithered)
    assert frequency == 40.0
    assert "dither_force" in blocks and set(blocks) <= set(BLOCK_CHANNELS)
    blocks, frequency = block_costs(PIDamping(compensation=FrictionCompensation(fraction=0.5)))
    assert frequency is None and "compensation_force" in blocks
    assert "friction_estimate" not in blocks  # no observer: no estimate recorded
    observed = PIDamping(compensation=FrictionCompensation(fraction=0.5,
                                                           observer_bandwidth=5.0))
    assert {"compensation_force", "friction_estimate"} <= set(block_costs(observed)[0])
