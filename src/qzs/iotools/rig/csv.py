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
        # a units row under the names (a CSV file qzs wrote) is a second header row: read
        # as data it would make every column text (pandas' "mixed types" warning)
        header = [0, 1] if _has_units_row(path) else 0
        table = pd.read_csv(path, comment="#", skipinitialspace=True, header=header)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as error:
        raise DataError(f"{str(path)!r} is not a readable CSV file with a header: "
                        f"{error}") from None
    names = [str(c).strip() for c in table.columns.get_level_values(0)]
    columns = {}
    for key, source in [("time", channel_map.time_source or "time"),
                        *((r, signal_name(s.source)) for r, s in channel_map.channels.items())]:
        values = pd.to_numeric(table.iloc[:, find_signal(source, names, path)], errors="coerce")
        columns[key] = values.to_numpy(dtype=float)
    time = columns.pop("time")
    return {role: (time, values) for role, values in columns.items()}


def _has_units_row(path):
    """Whether the second row of the table (comments and blank lines skipped, as pandas
    skips them) is a row of units (:func:`qzs.iotools.files.is_units_row`)."""
    import csv
    import itertools

    with open(path, encoding="utf-8", newline="") as handle:
        lines = (line.split("#", 1)[0] for line in handle)
        rows = csv.reader(line for line in lines if line.strip())
        first_two = list(itertools.islice(rows, 2))
    return len(first_two) == 2 and is_units_row(first_two[1])
