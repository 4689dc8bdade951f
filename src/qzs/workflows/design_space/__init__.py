"""The design space: multi-objective optimisation, robust design and global sensitivity.

A problem file (:mod:`.problem`) names the decision variables (registry parameters with
bounds), the uncertain parameters (distributions), and the objectives and constraints
(metrics of a run or of the linear analysis, :mod:`.metrics`). ``qzs optimize`` searches
it with pymoo's NSGA-II, one lockstep batch per generation (:mod:`.optimizer`), keeping
every evaluated design in a resumable Zarr store (:mod:`.store`); ``qzs sensitivity``
ranks the parameters by Sobol or Morris indices (:mod:`.sensitivity`). The guide is
``qzs docs design-space``.

======================  ================================================================
``problem``             problem files: variables, uncertainty, objectives, constraints
``problem_types``       the validated problem: its variables, uncertainty and goals
``metrics``             the metrics, and how a design's draws combine
``evaluation``          a population evaluated, a batch per task: runs, estimates, linear metrics
``optimizer``           NSGA-II over the problem, generation by generation (pymoo)
``store``               the Zarr store of every evaluated design: resume, replay
``result``              the Pareto set: files, figure, chosen design, report
``sensitivity``         Sobol and Morris indices of the metrics (SALib)
``sensitivity_result``  the indices as a result: ranking, table, dataset, files
======================  ================================================================
"""
from qzs.workflows.design_space.evaluation import Evaluation, evaluate
from qzs.workflows.design_space.metrics import METRICS
from qzs.workflows.design_space.optimizer import optimize
from qzs.workflows.design_space.problem import (DesignProblem, Goal, Uncertainty, Variable,
                                                load_problem, plan_text, shipped_problems)
from qzs.workflows.design_space.result import OptimizationResult, write_files
from qzs.workflows.design_space.sensitivity import SensitivityResult, sensitivity

__all__ = ["optimize", "sensitivity", "load_problem", "shipped_problems", "plan_text",
           "DesignProblem", "Variable", "Uncertainty", "Goal", "METRICS", "Evaluation",
           "evaluate", "OptimizationResult", "SensitivityResult", "write_files"]
