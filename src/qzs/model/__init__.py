"""The model: parameters, force laws in numpy, excitations and the parameter registry.

No numba here: the kernels that integrate this model are in :mod:`qzs.engine`, and
they call the same laws written once as numba functions (:mod:`qzs.engine.laws`).
The equations, signs and defaults are described in docs/model.md.
"""
from qzs.model.controller import ControllerParameters, closed_loop_natural_frequency
from qzs.model.excitation import (EXCITATION_KINDS, EXCITATION_OPTIONS, Chirp, DisplacementRecord,
                                  RandomExcitation, Sine, build_excitation)
from qzs.model.isolator import (STOP_MODELS, InitialState, IsolatorParameters, friction_force,
                                passive_natural_frequency, spring_energy, spring_force,
                                spring_stiffness)
from qzs.model.registry import (PARAMETERS, ParameterInfo, parameter_info, unit_of,
                                update_parameters)

__all__ = ["IsolatorParameters", "ControllerParameters", "InitialState", "STOP_MODELS",
           "Chirp", "Sine", "RandomExcitation", "DisplacementRecord", "EXCITATION_KINDS",
           "EXCITATION_OPTIONS", "build_excitation", "spring_force", "spring_stiffness",
           "spring_energy", "friction_force", "passive_natural_frequency",
           "closed_loop_natural_frequency", "PARAMETERS", "ParameterInfo", "parameter_info",
           "unit_of", "update_parameters"]
