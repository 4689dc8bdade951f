"""CSV logs: one header line of column names, then numbers; ``#`` lines are comments.

A units row under the names (as in the CSV files qzs writes) is skipped.
"""
from __future__ import annotations

from qzs.errors import DataError
from qzs.iotools.files import is_units_row
from qzs.iotools.rig.channel_map import find_signal, signal_name

__all__ = ["read_csv"]


def read_csv(path, channel_map):
    """A CSV log's signals by role (pandas).

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
    import pandas as pd

    try:
        table = pd.read_csv(path, comment="#", skipinitialspace=True)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as error:
        raise DataError(f"{str(path)!r} is not a readable CSV file with a header: "
                        f"{error}") from None
    names = [str(c).strip() for c in table.columns]
    if len(table) and is_units_row([str(v) for v in table.iloc[0] if not pd.isna(v)]):
        table = table.iloc[1:]  # a units row under the names (a CSV file qzs wrote)
    columns = {}
    for key, source in [("time", channel_map.time_source or "time"),
                        *((r, signal_name(s.source)) for r, s in channel_map.channels.items())]:
        values = pd.to_numeric(table.iloc[:, find_signal(source, names, path)], errors="coerce")
        columns[key] = values.to_numpy(dtype=float)
    time = columns.pop("time")
    return {role: (time, values) for role, values in columns.items()}
