"""``qzs experiment``: a measured log beside its simulation (docs/workflows/identification.md).

================  ================================================================
``process``       the log's measured transmissibility beside the matching simulation
``map_template``  the commented channel map template (``--write-map``)
================  ================================================================
"""
