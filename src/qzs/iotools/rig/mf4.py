"""MF4 logs (ASAM MDF 4, via the optional asammdf): channels by name, each with its own time
stamps."""
from __future__ import annotations

import numpy as np

from qzs._optional import require
from qzs.errors import DataError
from qzs.iotools.rig.channel_map import find_signal, signal_name

__all__ = ["read_mf4"]


def read_mf4(path, channel_map):
    """An MF4 log's signals by role, each on its own time stamps.

    Parameters
    ----------
    path : Path
        The log file.
    channel_map : ChannelMap
        Which signal is which role (:mod:`qzs.iotools.rig.channel_map`).

    Returns
    -------
    dict of str to (ndarray, ndarray)
        Role -> (time in the map's time unit, raw samples), checked and converted to SI by
        :func:`qzs.iotools.rig.recording.read_recording`.

    Raises
    ------
    DataError
        An unreadable file, or a signal missing (the message lists those found).
    """
    MDF = require("asammdf", "reading MF4 logs").MDF

    try:
        mdf = MDF(path)
    except Exception as error:  # asammdf raises its own and built-in errors alike
        raise DataError(f"{str(path)!r} is not a readable MDF file: {error}") from None
    with mdf:
        names = sorted(n for n in mdf.channels_db if not n.startswith("$") and n != "time")
        signals = {}
        for role, channel in channel_map.channels.items():
            name = names[find_signal(signal_name(channel.source), names, path)]
            if len(mdf.channels_db[name]) > 1:
                raise DataError(f"{str(path)!r}: channel {name!r} is in several groups "
                                f"{list(mdf.channels_db[name])}; rename or export one.")
            signal = mdf.get(name)
            signals[role] = (np.asarray(signal.timestamps, float),
                             np.asarray(signal.samples, float))
    return signals
