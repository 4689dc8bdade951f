"""The channel map template of ``qzs experiment``: every key the map reader accepts, commented.

``qzs experiment LOG --map MAP.toml`` needs a channel map (:mod:`qzs.iotools.rig`):
which signal of the log plays which role, in which unit and with which scale.
:func:`channel_map_template` writes one from the reader's own tables
(:data:`~qzs.iotools.rig.channel_map.ROLES`, :data:`~qzs.iotools.rig.channel_map.UNITS`, the ``[time]``,
``[options]`` and ``[experiment]`` keys) and the experiment's defaults, so that the template
names every key the reader takes and nothing else. The two velocity channels the experiment
needs are active tables with a placeholder ``source``; the other roles and the optional keys
are commented out. With the placeholders replaced by the log's signal names, the file is a
valid map.

Command line: ``qzs experiment --write-map FILE.toml``.
"""
import dataclasses
import inspect
from pathlib import Path

from qzs.defaults import ANALYSIS
from qzs.errors import OutputPathError
from qzs.iotools.files import atomic_path
from qzs.iotools.paths import check_output_path
from qzs.iotools.rig.channel_map import (EXPERIMENT_KEYS, NAN_POLICIES, ROLES, TIME_UNITS,
                                         UNITS, ChannelMap)
from qzs.model.excitation import Chirp
from qzs.workflows.experiment.process import EXPERIMENT_AVERAGES, SIGNAL_PAIRS, process_experiment

__all__ = ["channel_map_template", "write_channel_map_template", "PLACEHOLDER"]

#: The ``source`` of every channel in the template: replace it with the log's signal name.
PLACEHOLDER = "SIGNAL-NAME"
#: The roles whose tables the template leaves active: the pair the experiment reads first.
ACTIVE_ROLES = SIGNAL_PAIRS["velocity"]
#: What each role is (the template's comment above its table).
ROLE_TEXT = {
    "base_velocity": "the base (shaker table) velocity",
    "base_acceleration": "the base (shaker table) acceleration",
    "payload_velocity": "the payload velocity",
    "payload_acceleration": "the payload acceleration",
    "relative_position": "the payload's position relative to the base, z = x - y (encoder)",
    "displacement": "an imposed displacement (the friction and spring tests)",
    "force": "a measured force (load cell)",
    "motor_command": "the motor command, as a voltage or a force",
}
#: What each ``[experiment]`` key is, with its unit (the defaults are added from the code).
EXPERIMENT_TEXT = {
    "highpass_corner": "[Hz] the charge amplifiers' first-order high-pass; the band below "
                       "1.5x it is flagged; 0: none",
    "amplitude": "[m] the chirp's base displacement amplitude; inferred from the base signal "
                 "if left out",
    "f0": "[Hz] the chirp's start frequency; inferred if left out",
    "f1": "[Hz] the chirp's end frequency; inferred if left out",
    "method": "the chirp's sweep law, \"linear\" or \"logarithmic\"",
    "fft_length": "[samples] Welch segment length, >= 8 (--fft-length overrides it)",
    "n_averages": "Welch averages, >= 1; fewer if the log is short (--averages overrides it)",
}


def _units_of(role):
    return [name for name, (si, _) in UNITS.items() if si in ROLES[role]]


def _experiment_defaults():
    """The value ``qzs experiment`` takes for each ``[experiment]`` key left out."""
    corner = inspect.signature(process_experiment).parameters["highpass_corner"].default
    chirp = Chirp()
    return {"highpass_corner": corner, "amplitude": chirp.amplitude, "f0": chirp.f0,
            "f1": chirp.f1, "method": chirp.method, "fft_length": ANALYSIS["fft_length"],
            "n_averages": EXPERIMENT_AVERAGES}


def _toml(value):
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    return repr(value)


def _channel_table(role):
    units = _units_of(role)
    prefix = "" if role in ACTIVE_ROLES else "# "
    return [f"# {ROLE_TEXT[role]} [{' or '.join(ROLES[role])}]; unit one of: "
            f"{', '.join(units)}",
            f"{prefix}[channels.{role}]",
            f'{prefix}source = "{PLACEHOLDER}"',
            f'{prefix}unit = "{units[0]}"',
            f"{prefix}scale = 1.0", ""]


def channel_map_template() -> str:
    """The text of a commented channel map naming every key the map reader accepts.

    Returns
    -------
    str
        TOML: the ``[channels.<role>]`` tables (base and payload velocity active, with the
        ``source`` :data:`PLACEHOLDER`; the other roles commented out), ``[time]``,
        ``[options]`` and ``[experiment]`` with every key: the optional ones commented out,
        at the value used when they are left out (the chirp's at the paper's, as an example:
        left out, they are inferred from the base signal).
    """
    options = {field.name: field.default for field in dataclasses.fields(ChannelMap)}
    experiment = _experiment_defaults()
    lines = [
        "# Channel map for `qzs experiment LOG --map THIS.toml`: which signal of the log plays",
        "# which role, in which unit (written by `qzs experiment --write-map`).",
        f'# 1. Replace every source = "{PLACEHOLDER}" with the signal\'s name in the log: a CSV',
        "#    column, an MF4 channel, a NetCDF variable, or in a dSPACE MAT export a Y(k).Name",
        "#    (\"Y[3]/name\" takes Y(3) and checks its name). A name also matches a signal whose",
        "#    last /-separated part it is (dSPACE names carry a model path).",
        "# 2. unit is the unit of raw * scale; it is converted to SI on reading. scale is a",
        "#    sensitivity: SI value = raw * scale * unit factor (default 1.0).",
        "# 3. The experiment needs base_velocity and payload_velocity, or base_acceleration and",
        "#    payload_acceleration (uncomment those two tables and delete the velocity ones).",
        "# Layout and reader: `qzs docs identification`; the reader is",
        "# qzs.iotools.rig.load_channel_map.",
        "",
    ]
    for role in ROLES:
        lines += _channel_table(role)
    time_units = " or ".join(f'"{unit}"' for unit in TIME_UNITS)
    lines += [
        "# The time base (optional table).",
        "[time]",
        '# source = "time"    # CSV column or NetCDF variable (default "time"); MAT: a Y signal',
        "#                    # (default X(1).Data); MF4: leave out (each channel's own times)",
        f'unit = "{options["time_unit"]}"          # {time_units}',
        "",
        "# Reading (optional table).",
        "[options]",
        f"resample = {_toml(options['resample'])}      # put a non-uniform time base on a "
        "uniform grid (or --resample)",
        f"tolerance = {_toml(options['tolerance'])}     # allowed relative jitter of the "
        "sample interval [-], in (0, 1)",
        f"nan = {_toml(options['nan'])}         # "
        + " or ".join(f'"{policy}"' for policy in NAN_POLICIES)
        + ": fill NaN samples linearly, with a warning",
        '# variable = "NAME"  # MAT files holding several top-level structs: the one to read',
        "",
        "# The experiment (optional table): the analysis, and the chirp if it is known.",
        "[experiment]",
    ]
    for key in EXPERIMENT_KEYS:
        prefix = "" if key == "highpass_corner" else "# "
        lines += [f"# {EXPERIMENT_TEXT[key]}", f"{prefix}{key} = {_toml(experiment[key])}"]
    return "\n".join(lines) + "\n"


def write_channel_map_template(path: str | Path, *, overwrite: bool = False) -> Path:
    """Write :func:`channel_map_template` to a file, atomically.

    Parameters
    ----------
    path : str or Path
        The ``.toml`` file to write; its folder is created if missing.
    overwrite : bool
        Replace an existing file; default False (a map someone filled in is kept).

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    OutputPathError
        ``path`` does not end in ``.toml``, cannot be written, or exists without
        ``overwrite``.
    """
    path = check_output_path(path, argument="path", suffixes=(".toml",),
                             estimated_bytes=16 * 1024)
    if path.exists() and not overwrite:
        raise OutputPathError("path", str(path), "exists; choose another name, or pass "
                              "overwrite=True to replace it")
    text = channel_map_template()
    with atomic_path(path) as temporary:
        Path(temporary).write_text(text, encoding="utf-8")
    return path
