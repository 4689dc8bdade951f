"""Files in and out: the file schema, results and configs, rig logs, shipped definitions.

This layer knows no result type: each declares its own schema beside its class
(``qzs.engine.channels.simulation_schema``, ...) and hands it to the functions here.

================  ==================================================================
``schema``        a result's variables, dimensions, units and flags; its dataset
``cf_layout``     the NetCDF file layout: what CF-1.10 has no home for, in CF's own means
``writer``        the atomic CF writer of a schema: streamed (NetCDF, CSV, MATLAB), whole datasets, tables
``matfile``       MATLAB files (MAT 5, MAT 7.3) of a dataset or a streamed schema
``files``         atomic writes; result files read back
``result_files``  a result's ``save``: the format chosen by the extension (.nc, .csv, .mat, .json)
``paths``         output paths checked before the work starts
``config``        run configurations (TOML)
``rig``           subpackage: test-rig logs (CSV, dSPACE MAT, MF4, NetCDF) through a channel map
``shipped``       the study, sweep and hexapod files shipped with qzs
``docs``          the model and workflow pages shipped inside the package (``qzs docs``)
================  ==================================================================
"""
from qzs._lazy import lazy_exports

# Loaded on first use: the engine imports the schema and the writer, not the rig-log readers.
_EXPORTS = {
    "atomic_path": "qzs.iotools.files", "read_result": "qzs.iotools.files",
    "read_displacement_csv": "qzs.iotools.files", "check_output_path": "qzs.iotools.paths",
    "load_config": "qzs.iotools.config", "save_config": "qzs.iotools.config",
    "Recording": "qzs.iotools.rig", "ChannelMap": "qzs.iotools.rig",
    "load_channel_map": "qzs.iotools.rig", "read_recording": "qzs.iotools.rig",
    "write_dspace_mat": "qzs.iotools.rig", "Schema": "qzs.iotools.schema",
    "Variable": "qzs.iotools.schema", "to_dataset": "qzs.iotools.schema",
    "StreamWriter": "qzs.iotools.writer", "estimated_file_size": "qzs.iotools.writer",
    "write_mat": "qzs.iotools.matfile",
    "write_dataset": "qzs.iotools.writer", "write_table": "qzs.iotools.writer",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
