"""Workflows built on the layers below, one subpackage per thing a user asks for.

==================  ==========================================================================
``run``             one run streamed to a file as it is simulated (bounded memory)
``forked``          one job run by a helper process forked now, which prepares (imports,
                    warm-up) while this one works; dies with it, ignores Ctrl-C
``figure_process``  a run's figure drawn in a second process while the file is written
``paper``           ``qzs paper`` and ``qzs study``: the paper's studies (``study_files/``),
                    figures, curves as data, claims decided from the data
``experiment``      ``qzs experiment``: a measured log beside its simulation, the channel map
                    template
``sweeps``          parameter sweeps and Monte Carlo runs into Zarr stores, locally or on Dask
                    (``sweep_files/``)
``response``        steady-state frequency response: stepped-sine sweeps up and down, beside
                    the harmonic balance and the paper's chirp estimate
``design``          ``qzs design``: PI and damping gains searched by simulation, with the
                    evidence
``design_space``    ``qzs optimize`` and ``qzs sensitivity``: Pareto search (NSGA-II), robust
                    design, Sobol and Morris indices (``problem_files/``)
``hexapod``         ``qzs hexapod``: six-axis set-ups (``hexapod_files/``), the platform's 6x6
                    transmissibility, the six-leg study
``questions``       ``qzs study friction_compensation``, ``damping_design``: the paper's two
                    open questions answered, each with one verdict
``findings``        verdicts, tables, figures, HTML and Markdown: the findings and report rooms
                    the paper and the six-axis study share
==================  ==========================================================================
"""
