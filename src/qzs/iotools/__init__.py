"""Files in and out: the file schema, results and configs, rig logs, shipped definitions.

This layer knows no result type: each declares its own schema beside its class
(``qzs.engine.results.simulation_schema``, ...) and hands it to the functions here.

===========  ==================================================================
``schema``   a result's variables, dimensions, units and flags; its dataset
``writer``   the streaming, atomic CF writer (NetCDF, CSV) of a schema
``files``    atomic writes; result files read back
``paths``    output paths checked before the work starts
``config``   run configurations (TOML)
``readers``  test-rig logs (CSV, dSPACE MAT, MF4, NetCDF) through a channel map
``shipped``  the study and sweep files shipped with qzs
===========  ==================================================================
"""
from qzs.iotools.config import load_config, save_config
from qzs.iotools.files import atomic_path, read_displacement_csv, read_result
from qzs.iotools.paths import check_output_path
from qzs.iotools.readers import (ChannelMap, Recording, load_channel_map, read_recording,
                                 write_dspace_mat)
from qzs.iotools.schema import Schema, Variable, to_dataset
from qzs.iotools.writer import StreamWriter, estimated_file_size

__all__ = ["atomic_path", "read_result", "check_output_path", "read_displacement_csv",
           "load_config", "save_config", "Recording", "ChannelMap", "load_channel_map",
           "read_recording", "write_dspace_mat", "Schema", "Variable", "to_dataset",
           "StreamWriter", "estimated_file_size"]
