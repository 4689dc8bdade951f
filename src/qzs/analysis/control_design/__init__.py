"""Controller design at the operating point: static balance, stability, margins, hunting.

Pure analysis (python-control, numpy, scipy; no simulation): the numbers behind
``qzs design`` (docs/design.md), each in closed form where one exists, checked against
python-control. Every public name is importable from here
(``from qzs.analysis.control_design import routh_hurwitz``); each module holds one of them:

========================  ======================================================================
``static``                the static design: spring load, static deficit, force left, the band
``linear_stability``      the characteristic polynomial, Routh-Hurwitz bounds on gains, the poles
``loop_transfers``        the loop at the motor force, continuous or sampled with a delay
``stability_margins``     gain and phase margins, continuous or sampled; the rate a design needs;
                          the one verdict on a controller's loop (stable, margins, why not)
``describing_functions``  the friction law (net of a compensation) as a memoryless nonlinearity of
                          slip velocity; the sliding cycle of over-compensation
``hunting``               the stick-slip relay in the integral loop: slip jump, hunting prediction
``hunting_population``    the same prediction for a whole population at once, solved directly
``linear_population``     transmissibility, stability and margins of a population at once
========================  ======================================================================

References
----------
H. Olsson, K. J. Åström, "Friction generated limit cycles", IEEE Trans. Control Syst.
Technol. 9(4), 2001; H. Olsson, "Describing function analysis of a system with friction",
Proc. IEEE CCA 1995. B. Armstrong-Hélouvry, B. Amin, "PID control in the presence of
static friction: a comparison of algebraic and describing function analysis",
Automatica 32(5), 1996. K. J. Åström, B. Wittenmark, *Computer-Controlled Systems*,
3rd ed., §2.3 (sampling a system with a time delay).
"""
from qzs.analysis.control_design.describing_functions import (FrictionNonlinearity,
                                                              NetFrictionNonlinearity,
                                                              SlidingCycle,
                                                              coulomb_describing_function,
                                                              friction_describing_function,
                                                              friction_velocity_loop,
                                                              net_describing_function,
                                                              predict_sliding_cycle)
from qzs.analysis.control_design.hunting import (SLIP_JUMP_FLOOR, HuntingPrediction,
                                                 hunting_stiffness, integral_loop,
                                                 predict_hunting, restick_force, slip_jump)
from qzs.analysis.control_design.linear_stability import (RouthHurwitz,
                                                          characteristic_polynomial,
                                                          closed_loop_poles,
                                                          damping_gain_limits,
                                                          integral_gain_limit, routh_hurwitz)
from qzs.analysis.control_design.loop_transfers import (PADE_ORDER, discretize_with_delay,
                                                        frequency_response, loop_transfer,
                                                        sampled_loop, sampled_transmissibility)
from qzs.analysis.control_design.stability_margins import (GAIN_MARGIN_MIN, MARGIN_LOWEST,
                                                           MARGIN_POINTS_PER_DECADE,
                                                           PHASE_MARGIN_MIN, LoopMargins,
                                                           LoopStability, loop_margins,
                                                           loop_stability,
                                                           required_controller_rate,
                                                           stability_margins_of)
from qzs.analysis.control_design.static import (PAPER_ADDED_MASS, StaticDesign,
                                                constant_force_band, static_design)

__all__ = ["StaticDesign", "static_design", "characteristic_polynomial", "RouthHurwitz",
           "routh_hurwitz", "integral_gain_limit", "damping_gain_limits",
           "closed_loop_poles", "constant_force_band", "integral_loop", "loop_transfer",
           "sampled_loop", "discretize_with_delay", "LoopMargins", "loop_margins",
           "stability_margins_of", "LoopStability", "loop_stability", "frequency_response", "required_controller_rate",
           "sampled_transmissibility", "coulomb_describing_function",
           "FrictionNonlinearity", "friction_describing_function", "restick_force", "slip_jump",
           "NetFrictionNonlinearity", "net_describing_function", "friction_velocity_loop",
           "SlidingCycle", "predict_sliding_cycle",
           "HuntingPrediction", "predict_hunting", "hunting_stiffness",
           "PAPER_ADDED_MASS", "GAIN_MARGIN_MIN", "PHASE_MARGIN_MIN", "SLIP_JUMP_FLOOR",
           "PADE_ORDER", "MARGIN_POINTS_PER_DECADE", "MARGIN_LOWEST"]
