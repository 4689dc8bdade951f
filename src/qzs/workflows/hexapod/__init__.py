"""``qzs hexapod``: the six-axis platform's set-ups, its 6x6 transmissibility and its study.

A set-up (:mod:`.setups`) is a hexapod file (``hexapod_files/``) or a cubic configuration
with defaults; ``qzs hexapod linear`` and ``qzs hexapod simulate`` report on it. The
simulated 6x6 transmissibility runs one chirp per excited base axis
(:mod:`.transmissibility`); ``qzs hexapod study`` sets six paper legs with and without PI
side by side (:mod:`.study`). The model is described in docs/hexapod.md.

=====================  ================================================================
``setups``             set-ups from hexapod files, and a set-up's simulated run
``platform_setup``     the set-up object, the default platform, set-ups from objects
``linear_report``      the linear analysis as data, text and the 6x6 grid (``linear``)
``legs``               each leg's own controller: ``[legs.N.controller]`` tables,
                       ``--leg-controller N=FILE.toml``
``transmissibility``   the simulated 6x6 transmissibility of a platform, chirp per axis
``study``              ``qzs hexapod study``: six paper legs with and without PI
=====================  ================================================================
"""
