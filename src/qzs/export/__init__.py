"""qzs outside Python: the isolator as C, the controller as C, and an FMU.

One C implementation of the single-axis model (``csrc/``: ``qzs_plant`` the physics,
``qzs_controller`` the sampled PI + active damping, ``qzs_model`` their closed loop), held
to the numba kernels bit for bit by the tests, and compiled at run time with the system C
compiler:

=================  ================================================================
``csource``        the shipped C sources, the system compiler, compile and load (ctypes)
``clayout``        the C model's packed indices and parameter checks, asserted against Python
``cmodel``         run a case through the C model as :func:`qzs.simulate` would
``controller``     the sampled controller as one dependency-free C file (``qzs export``)
``fmu``            ``qzs.export_fmu``: the isolator as an FMI 2.0 / 3.0 co-simulation FMU
``fmu_variables``  the FMU's variables: registry parameters, inputs, channels; as C too
``fmu_xml``        the FMU's ``modelDescription.xml`` and ``buildDescription.xml``
=================  ================================================================
"""
