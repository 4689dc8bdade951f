/* qzs: is an internal step small enough? The linear stability of qzs.engine.stability in C.
 *
 * The explicit integrators (euler, ode3, rk4) stay stable for a step h when their
 * amplification |R(h*lambda)| grows by at most 0.1 % per second for every eigenvalue lambda of
 * the stiffest linear modes: the charge amplifier's high-pass, the payload on its spring (with
 * the PI's Kp and the active damping Kd when the loop is closed inside, and the regularised
 * friction's slope Fs/v_reg), and the payload pressed on a compliant stop. The same modes,
 * polynomials and search as qzs.engine.stability (docs/model.md §7), so that the FMU refuses
 * at initialisation the steps qzs.simulate refuses. Plain C99 (no complex.h).
 */
#ifndef QZS_STABILITY_H
#define QZS_STABILITY_H

/* Does a step h [s] keep every stiff mode stable? P: the packed parameters (QZS_P_*); solver:
 * QZS_SOLVER_*; closed_loop: 1 when the PI and damping act inside the step (their Kp and Kd
 * stiffen the modes), 0 when the motor force is held from outside (plant mode). */
int qzs_stable_step(const double *P, int solver, int closed_loop, double h);
/* The largest such step [s] (qzs.engine.stability.largest_stable_step's search). */
double qzs_largest_stable_step(const double *P, int solver, int closed_loop);

#endif /* QZS_STABILITY_H */
