"""Test-rig logs: one module per source format, one :class:`Recording` out of each.

A channel map (TOML) says which signal of a log plays which role; :func:`read_recording`
reads a log of any supported format into a :class:`Recording` (uniform time base, channels
by role in SI units). As pvlib's iotools, one module per source:

=============  ==================================================================
``recording``  :class:`Recording`, channel maps and :func:`read_recording`
=============  ==================================================================
"""
from qzs._lazy import lazy_exports

_EXPORTS = {
    "Recording": "qzs.iotools.rig.recording", "ChannelMap": "qzs.iotools.rig.recording",
    "ChannelSpec": "qzs.iotools.rig.recording", "ROLES": "qzs.iotools.rig.recording",
    "UNITS": "qzs.iotools.rig.recording", "load_channel_map": "qzs.iotools.rig.recording",
    "read_recording": "qzs.iotools.rig.recording",
    "write_dspace_mat": "qzs.iotools.rig.recording",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
