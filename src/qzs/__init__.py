"""qzs: simulation and analysis of semi-active quasi-zero-stiffness vibration isolators.

The isolator of Leav et al. (constant-force MagSpring + linear motor, stick-slip
friction, guide hard stops, PI position loop and active damping), simulated as
docs/model.md describes, and the tools to judge it by transmissibility.

This module is the flat public API (``dir(qzs)`` lists it: ``__all__``). The top-level
modules are the base every layer may use; the subpackages are the architecture, each importing
only from those listed before it (``tests/test_layers.py`` reads the layers from this table):

===============  ====================================================================
``errors``       every exception and warning class, each subclassing a built-in
``defaults``     the settings and names the layers share: run, analysis, the six axes
``_validation``  the argument checks of the parameter classes and public functions
``_format``      how numbers are shown: dB, text, JSON, CSV, report tables
``_optional``    optional dependencies: imported, or named with the extra to install
``_lazy``        names a package exports but imports on first use (PEP 562)
``_version``     the installed version
``model``        parameters, spring laws, controllers, excitations, the parameter registry
``iotools``      the file schema and its streaming writer, config files, rig-log readers
``analysis``     spectral estimation and metrics, linearisation, run statistics
``engine``       numba kernels, single, lockstep and six-leg drivers, simulate, results
``identify``     spring, friction and transmissibility fits
``viz``          every figure
``workflows``    paper studies, experiments, sweeps, response, design, design space, six axes
``export``       the isolator and its controller as C, and as an FMU (FMI 2.0 / 3.0)
``app``          the interactive tuning page (``qzs app``; Panel, optional)
``cli``          the ``qzs`` command
===============  ====================================================================
"""
from typing import TYPE_CHECKING

from qzs._lazy import lazy_exports
from qzs._version import __version__
from qzs.errors import (CaseError, CompilerError, DataError, DataWarning, ExcitationError,
                        FitError, FitWarning, MissingDependencyError, OutputPathError,
                        ParameterError, ProblemError, ResultTooLargeError, SimulationError,
                        SizeLimitError, StabilityError, ToleranceNotMetError)
from qzs.model import (Chirp, ControllerParameters, Dither, DisplacementRecord,
                       FrictionCompensation, InitialState, IsolatorParameters, LinearController,
                       ObliqueSpringQZS, PIDamping, PolynomialSpring, RandomExcitation, Sine,
                       SpringLaw, TabulatedSpring, TanhSpring, check_equilibrium,
                       closed_loop_natural_frequency, friction_force, passive_natural_frequency,
                       spring_force, spring_stiffness)

# Loaded on first use, so that ``import qzs`` stays lean (PEP 562).
# The engine (numba) is loaded on first use, so that ``qzs --help`` and the command line's
# parsing start at once (issue 32: no silence before the first line).
_LAZY = {
    "simulate": "qzs.engine.simulate", "SimulationResult": "qzs.engine.result",
    "SOLVERS": "qzs.engine.stability", "largest_stable_step": "qzs.engine.stability",
    "simulate_batch": "qzs.engine.batch", "BatchResult": "qzs.engine.batch",
    "resolve": "qzs.engine.run_spec", "ResolvedRun": "qzs.engine.run_spec",
    "StepChoice": "qzs.engine.step_search",
    "transmissibility": "qzs.analysis.spectral",
    "TransmissibilityEstimate": "qzs.analysis.spectral",
    "transmissibility_metrics": "qzs.analysis.spectral",
    "linearize": "qzs.analysis.linear",
    "loop_margins": "qzs.analysis.control_design",
    "loop_stability": "qzs.analysis.control_design",
    "fit_spring": "qzs.identify", "fit_friction": "qzs.identify",
    "fit_transmissibility": "qzs.identify",
    "read_recording": "qzs.iotools", "load_channel_map": "qzs.iotools",
    "load_config": "qzs.iotools", "read_result": "qzs.engine.result_file",
    "read_controller": "qzs.engine.result_file",
    "run_sweep": "qzs.workflows.sweeps", "open_sweep": "qzs.workflows.sweeps",
    "simulate_to_file": "qzs.workflows.run",
    "simulate_hexapod": "qzs.engine.hexapod.simulate",
    "HexapodResult": "qzs.engine.hexapod.result",
    "simulate_hexapods": "qzs.engine.hexapod.simulate",
    "steady_state_response": "qzs.workflows.response.sweep",
    "SteadyStateResponse": "qzs.workflows.response.result",
    "design_controller": "qzs.workflows.design.driver",
    "DesignResult": "qzs.workflows.design.result",
    "hexapod_transmissibility": "qzs.workflows.hexapod.transmissibility",
    "HexapodTransmissibility": "qzs.workflows.hexapod.transmissibility",
    "optimize": "qzs.workflows.design_space.optimizer",
    "sensitivity": "qzs.workflows.design_space.sensitivity",
    "load_problem": "qzs.workflows.design_space.problem",
    "OptimizationResult": "qzs.workflows.design_space.result",
    "SensitivityResult": "qzs.workflows.design_space.sensitivity",
    "export_controller": "qzs.export.controller",
    "export_fmu": "qzs.export.fmu",
}

if TYPE_CHECKING:  # what type checkers see of the lazy names (kept in step by test_typing)
    from qzs.analysis.control_design import loop_margins, loop_stability
    from qzs.analysis.linear import linearize
    from qzs.analysis.spectral import (TransmissibilityEstimate, transmissibility,
                                       transmissibility_metrics)
    from qzs.engine.batch import BatchResult, simulate_batch
    from qzs.engine.hexapod.result import HexapodResult
    from qzs.engine.hexapod.simulate import simulate_hexapod, simulate_hexapods
    from qzs.engine.result import SimulationResult
    from qzs.engine.result_file import read_controller, read_result
    from qzs.engine.run_spec import ResolvedRun, resolve
    from qzs.engine.simulate import simulate
    from qzs.engine.stability import SOLVERS, largest_stable_step
    from qzs.engine.step_search import StepChoice
    from qzs.export.controller import export_controller
    from qzs.export.fmu import export_fmu
    from qzs.identify import fit_friction, fit_spring, fit_transmissibility
    from qzs.iotools.config import load_config
    from qzs.iotools.rig import load_channel_map, read_recording
    from qzs.workflows.design.driver import design_controller
    from qzs.workflows.design.result import DesignResult
    from qzs.workflows.design_space.optimizer import optimize
    from qzs.workflows.design_space.problem import load_problem
    from qzs.workflows.design_space.result import OptimizationResult
    from qzs.workflows.design_space.sensitivity import SensitivityResult, sensitivity
    from qzs.workflows.hexapod.transmissibility import (HexapodTransmissibility,
                                                        hexapod_transmissibility)
    from qzs.workflows.response.result import SteadyStateResponse
    from qzs.workflows.response.sweep import steady_state_response
    from qzs.workflows.run import simulate_to_file
    from qzs.workflows.sweeps import open_sweep, run_sweep

__all__ = [
    "__version__",
    "Chirp", "Sine", "RandomExcitation", "DisplacementRecord",
    "IsolatorParameters", "ControllerParameters", "InitialState",
    "PIDamping", "FrictionCompensation", "Dither", "LinearController",
    "spring_force", "spring_stiffness", "friction_force",
    "SpringLaw", "TanhSpring", "ObliqueSpringQZS", "PolynomialSpring", "TabulatedSpring",
    "check_equilibrium",
    "passive_natural_frequency", "closed_loop_natural_frequency",
    "ParameterError", "ExcitationError", "StabilityError", "CaseError", "SimulationError",
    "DataError", "FitError", "MissingDependencyError", "OutputPathError", "ResultTooLargeError",
    "ToleranceNotMetError", "SizeLimitError", "ProblemError", "CompilerError",
    "DataWarning", "FitWarning",
    *_LAZY,
]

__getattr__, __dir__ = lazy_exports(__name__, _LAZY, public=__all__)
