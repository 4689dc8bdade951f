"""Files in and out: results and configs, rig logs, shipped definitions.

=================  ==================================================================
``files``          atomic writes; results as NetCDF or CSV, streamed chunk by chunk
``hexapod_files``  a six-leg platform's run streamed to NetCDF
``paths``          output paths checked before the work starts
``config``         run configurations (TOML)
``readers``        test-rig logs (CSV, dSPACE MAT, MF4, NetCDF) through a channel map
``shipped``        the study, sweep and hexapod files shipped with qzs
=================  ==================================================================
"""
from qzs.iotools.config import load_config, save_config
from qzs.iotools.files import (ResultWriter, atomic_path, read_displacement_csv, read_result,
                              save_result)
from qzs.iotools.paths import check_output_path
from qzs.iotools.readers import (ChannelMap, Recording, load_channel_map, read_recording,
                                 write_dspace_mat)

__all__ = ["atomic_path", "save_result", "read_result", "ResultWriter", "check_output_path",
           "read_displacement_csv", "load_config",
           "save_config", "Recording", "ChannelMap", "load_channel_map", "read_recording",
           "write_dspace_mat"]
