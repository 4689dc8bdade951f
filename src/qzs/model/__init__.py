"""The model: parameters, force laws in numpy, excitations and the parameter registry.

No numba here: the kernels that integrate this model are in :mod:`qzs.engine`, and
they call the same laws written once as numba functions (:mod:`qzs.engine.laws`).
The equations, signs and defaults are described in docs/model.md.

================  ================================================================
``isolator``      the plant's parameters and force laws (spring, friction), the rest state
``springs``       spring laws as values: tanh (MagSpring), oblique-spring QZS, polynomial, table
``spring_table``  a measured force curve's PCHIP pieces, their integrals, its CSV reader
``controller``    the controller as a value: PI + damping and the blocks that add to it
``excitation``    base excitations (chirp, sine, random, a displacement record)
``sensors``       what a user's controller may read, and its most states
``registry``      every parameter's name, unit, doc and default; ``--set`` parsing
``hexapod``       a six-leg platform of isolator legs: geometry, kinematics, statics
================  ================================================================
"""
from qzs.model.controller import (ControllerParameters, Dither, FrictionCompensation,
                                  LinearController, PIDamping, closed_loop_natural_frequency)
from qzs.model.excitation import (EXCITATION_KINDS, EXCITATION_OPTIONS, Chirp, DisplacementRecord,
                                  RandomExcitation, Sine, build_excitation)
from qzs.model.hexapod import (LEG_COUNT, HexapodGeometry, PlatformParameters, StrokeCheck,
                               angular_velocity_matrix, base_jacobian, cubic_geometry,
                               forward_kinematics, inverse_kinematics, jacobian, leg_positions,
                               leg_unit_vectors, leg_vectors, mass_matrix, radial_geometry,
                               rotation_angles, rotation_matrix, static_leg_forces, stroke_check,
                               weight_wrench)
from qzs.model.isolator import (STOP_MODELS, InitialState, IsolatorParameters, friction_force,
                                passive_natural_frequency, spring_energy, spring_force,
                                spring_stiffness)
from qzs.model.registry import (PARAMETERS, ParameterInfo, parameter_info, unit_of,
                                update_parameters)
from qzs.model.springs import (ObliqueSpringQZS, PolynomialSpring, SpringLaw, TabulatedSpring,
                               TanhSpring, check_equilibrium)

__all__ = ["IsolatorParameters", "ControllerParameters", "PIDamping", "FrictionCompensation",
           "Dither", "LinearController", "InitialState", "STOP_MODELS",
           "Chirp", "Sine", "RandomExcitation", "DisplacementRecord", "EXCITATION_KINDS",
           "EXCITATION_OPTIONS", "build_excitation", "spring_force", "spring_stiffness",
           "spring_energy", "friction_force", "passive_natural_frequency",
           "closed_loop_natural_frequency", "PARAMETERS", "ParameterInfo", "parameter_info",
           "unit_of", "update_parameters",
           "HexapodGeometry", "PlatformParameters", "StrokeCheck", "LEG_COUNT", "cubic_geometry",
           "radial_geometry", "rotation_matrix", "rotation_angles", "angular_velocity_matrix",
           "leg_vectors", "leg_unit_vectors", "inverse_kinematics", "forward_kinematics",
           "jacobian", "base_jacobian", "stroke_check", "leg_positions", "mass_matrix",
           "weight_wrench", "static_leg_forces",
           "SpringLaw", "TanhSpring", "ObliqueSpringQZS", "PolynomialSpring", "TabulatedSpring",
           "check_equilibrium"]
