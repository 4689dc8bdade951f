"""``qzs design``: PI and damping gains for the isolator, searched by simulation (docs/design.md).

From the isolator's parameters and a description of the disturbance (a base motion, payload
force steps, ranges of stiction and payload mass), :func:`design_controller` finds

1. the smallest PI gains (``Ki = ratio*Kp``, the ratio of the given controller) that keep the
   payload inside the spring's constant-force band and off the stops in every case, by
   simulation: a log grid of ``Kp``, then bisection between the last failing and the first
   passing gain above which every grid gain passes;
2. whether the PI loop hunts at rest (describing functions of
   :func:`qzs.analysis.control_design.predict_hunting`, and simulations that confirm or refute
   them);
3. the damping gain that minimises a transmissibility cost over a band (RMS or peak), within
   the linear stability bound and the sampled loop's margins;
4. the sampled loop's margins at the controller's rate with a delay, and the rate the design
   needs;
5. why active damping "did not help much" in the paper: the cost's change with damping
   against the charge amplifier's high-pass, the guide's viscous friction, the controller
   rate (simulated) and a delay (the linear sampled model: the simulator has none);
6. the static design (:func:`qzs.analysis.control_design.static_design`).

Three families of cases, each over the ends of the stiction and mass ranges (and the middle
stiction, unless ``quick``):

``base``
    The base motion alone, from the default start (the integral preloaded for the case's own
    weight). Run through :func:`qzs.simulate_batch`, every gain and case in one lockstep batch.
``step``
    The base motion plus a payload force step ``dF`` [N] (upward positive) at ``t = 0``: the
    integral starts ``dF/Ki`` above its preload, which adds ``dF`` to the motor's force exactly
    as a load change would (both are constant and add before the saturation; the anti-windup
    sees the same command while the motor is not saturated). ``simulate_batch`` starts every
    case from the default state, so these run through :func:`qzs.simulate` with an
    ``InitialState``, in threads (the kernel releases the GIL).
``hunting``
    The base at rest, the payload stuck off the setpoint at the plateau the describing
    function predicts for its hunting cycle (at least 1 mm, at most half the stroke), the
    loop in balance: the integral winds up, the payload breaks away, and hunts or settles.

Every public name is importable from here (``from qzs.workflows.design import
design_controller``); the modules, in the order of the stages:

==========================  =======================================================================
``driver``                  :func:`design_controller`: the stages in order, timed, and their record
``inputs``                  every argument checked before any simulation; the validated settings
``settings``                defaults and search sizes (``COSTS``, ``KP_GRID``, ...), shared settings
``integration_step``        the accuracy-driven step and the coarser step of the PI search's runs
``cases``                   :class:`DesignCase`: the cases of the PI search and how each starts
``proportional_search``     the PI search: grid and bisection in ``Kp`` over every case
``cost``                    :func:`transmissibility_cost`: simulated and linear costs over the band
``damping_search``          the damping gain of least cost within the stability bound and margins
``hunting``                 hunting at rest: describing-function predictions against simulations
``margins``                 the sampled loop's margins over rates and delays, the rate it needs
``damping_effect``          why active damping did not help much: experiments and the answer
``result``                  :class:`DesignResult`: the gains, the evidence, ``save`` and ``plot``
``report``                  :func:`design_text` and the HTML report
==========================  =======================================================================
"""
from qzs.workflows.design.cases import DesignCase
from qzs.workflows.design.cost import transmissibility_cost
from qzs.workflows.design.driver import design_controller
from qzs.workflows.design.report import design_text
from qzs.workflows.design.result import DesignResult
from qzs.workflows.design.settings import COSTS, FAMILIES

__all__ = ["DesignCase", "DesignResult", "design_controller", "COSTS", "FAMILIES",
           "transmissibility_cost", "design_text"]
