"""A six-axis run's result (qzs.engine.hexapod.result): its channels and flags tile the kernels'
output columns exactly, and its file layout gives every variable its dims and units."""
import numpy as np

from qzs.engine.hexapod.layout import AXES, LEG_COUNT, N_BASE_CHANNELS, N_CHANNELS, N_FLAGS
from qzs.engine.hexapod.result import (HEXAPOD_BLOCK_CHANNELS, HEXAPOD_CHANNELS, HEXAPOD_FLAGS,
                                       hexapod_file_layout)

WIDTH = {None: 1, "dof": 6, "leg": LEG_COUNT}


def test_the_channels_and_flags_tile_the_output_columns():
    """Every column of the kernels' output belongs to exactly one channel (and every flag
    column to one flag): no channel reads another's column, none is left unnamed; the legs'
    block forces fill the columns a row with blocks adds."""
    columns = sorted(c for first, dim, _, _ in HEXAPOD_CHANNELS.values()
                     for c in range(first, first + WIDTH[dim]))
    assert columns == list(range(N_BASE_CHANNELS))
    extra = sorted(c for first, dim, _, _ in HEXAPOD_BLOCK_CHANNELS.values()
                   for c in range(first, first + WIDTH[dim]))
    assert extra == list(range(N_BASE_CHANNELS, N_CHANNELS))
    flags = sorted(c for first, _ in HEXAPOD_FLAGS.values() for c in range(first, first + 6))
    assert flags == list(range(N_FLAGS))


def test_the_file_layout_gives_dims_and_units_per_variable():
    layout = hexapod_file_layout()
    variables = layout["variables"]
    assert set(variables) == (set(HEXAPOD_CHANNELS) - {"time"}) | set(HEXAPOD_FLAGS)
    for name, (_, dim, unit, _) in HEXAPOD_CHANNELS.items():
        if name == "time":
            continue
        dims, attrs = variables[name]
        assert dims == (("time",) if dim is None else ("time", dim))
        if dim == "dof":   # translations in m..., rotations in rad...
            assert attrs["units"].split(", ") == list(unit)
            assert [u.startswith("rad") for u in unit] == [a.startswith("r") for a in AXES]
        else:
            assert attrs["units"] == unit
    for name in HEXAPOD_FLAGS:
        dims, attrs = variables[name]
        assert dims == ("time", "leg")
        np.testing.assert_array_equal(attrs["flag_values"], [0, 1])
        assert len(attrs["flag_meanings"].split()) == 2
    assert layout["coordinates"]["dof"][1] == list(AXES)
    np.testing.assert_array_equal(layout["coordinates"]["leg"][1], np.arange(1, 7))
