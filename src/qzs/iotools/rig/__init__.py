"""Test-rig logs: one module per source format, one :class:`Recording` out of each.

A channel map (TOML) says which signal of a log plays which role; :func:`read_recording`
reads a log of any supported format into a :class:`Recording` (uniform time base, channels
by role in SI units). As pvlib's iotools, one module per source:

===============  ================================================================
``channel_map``  :class:`ChannelMap`: which signal plays which role, in which unit
``recording``    :class:`Recording` and :func:`read_recording`, the checks and SI units
``csv``          CSV logs
``dspace``       dSPACE ControlDesk MAT exports (v5/v7, v7.3), read and written
``mf4``          ASAM MDF 4 logs (asammdf)
``netcdf``       NetCDF logs (xarray)
===============  ================================================================
"""
from qzs._lazy import lazy_exports

_EXPORTS = {
    "Recording": "qzs.iotools.rig.recording", "read_recording": "qzs.iotools.rig.recording",
    "ChannelMap": "qzs.iotools.rig.channel_map", "ChannelSpec": "qzs.iotools.rig.channel_map",
    "ROLES": "qzs.iotools.rig.channel_map", "UNITS": "qzs.iotools.rig.channel_map",
    "load_channel_map": "qzs.iotools.rig.channel_map",
    "write_dspace_mat": "qzs.iotools.rig.dspace",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
