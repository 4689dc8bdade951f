"""``qzs paper`` and ``qzs study``: the paper's studies, its figures, and its claims decided.

The studies are TOML definitions (``study_files/``, :mod:`.studies`) resolved to typed cases
(:mod:`.cases`) and run in parallel; the
report (:mod:`.report`) draws the paper's figures from them, writes the curves behind each
figure as data (:mod:`.curves`) and decides every claim the studies name from the numbers,
stating how the integration step was set (:mod:`.report_step`) and which spring every case
ran (:mod:`.report_spring`). The guide is
``qzs docs workflows/paper``.

=================  ==============================================================
``studies``        the paper's studies as TOML definitions (``study_files/``), planned
                   (steps chosen) and run in parallel
``cases``          one case of a study: its inputs, its run (alone or in a lockstep
                   batch), its curve, metrics and statistics
``report``         ``qzs paper``: figures, metrics, claims decided from the data
``report_step``    the studies' integration step as the report states it
``report_spring``  the studies' spring law as the report states it, the spring fit
``curves``         the curves behind a figure as data: NetCDF and CSV per study
=================  ==============================================================
"""
