"""Workflows built on the layers below: the paper's studies and report, experiment logs, sweeps.

============================  ================================================================
``run``                       one run streamed to a file as it is simulated (bounded memory)
``studies``                   the paper's studies as TOML definitions (``study_files/``), run
                              in parallel
``report``                    ``qzs paper``: figures, metrics, claims decided from the data
``report_step``               the studies' integration step as the report states it
``curves``                    the curves behind a figure as data: NetCDF and CSV per study
``experiment``                a measured log beside its simulation
``experiment_map``            the commented channel map template (``--write-map``)
``sweeps``                    parameter sweeps and Monte Carlo runs into Zarr stores, locally
                              or on Dask
``design``                    ``qzs design``: PI and damping gains searched by simulation,
                              with the evidence
``response``                  steady-state frequency response: stepped-sine sweeps up and
                              down, beside the harmonic balance and the paper's chirp estimate
``hexapod``                   six-axis set-ups: hexapod files (``hexapod_files/``), defaults,
                              the reports behind ``qzs hexapod``
``hexapod_transmissibility``  the simulated 6x6 transmissibility of a platform, chirp per axis
``hexapod_study``             ``qzs hexapod study``: six paper legs with and without PI
``design_space``              ``qzs optimize`` and ``qzs sensitivity``: problem files, NSGA-II,
                              robust design, Sobol and Morris indices
============================  ================================================================
"""
