/* qzs: the single-axis isolator plant in C (docs/model.md §2-§9).
 *
 * The physics of qzs's numba kernels (qzs.engine.kernels, laws, stickslip, base_motion,
 * arithmetic), operation for operation and in the same order, so that the same packed inputs
 * give the same bits: the force laws, the base motion (chirp, sine, tabulated cubic), the
 * fixed-step Runge-Kutta schemes (euler, ode3, rk4), the stick-slip events located inside a
 * step by regula falsi, compliant and plastic stops, the energy ledger and the recorded
 * channels. Its inputs are packed as qzs packs them (qzs.engine.prepare.prepare_run):
 * parameters P_*, state S_* and the held controller outputs, excitation E_* and its table.
 * A change to the kernels that is not made here too fails tests/export/test_cmodel.py.
 *
 * Build without fast-math and without implicit contraction (-ffp-contract=off): the fused
 * multiply-adds are explicit fma() calls, as in the kernels.
 */
#ifndef QZS_PLANT_H
#define QZS_PLANT_H

#include <stdint.h>

#include "qzs_controller.h"
#include "qzs_spring.h"

/* packed parameters (qzs.engine.kernels.P_*) */
enum { QZS_P_MASS, QZS_P_GRAVITY, QZS_P_SPRING_A, QZS_P_SPRING_B, QZS_P_FS, QZS_P_FC,
       QZS_P_CBC, QZS_P_CV, QZS_P_Z_LOW, QZS_P_Z_HIGH, QZS_P_STOP_K, QZS_P_STOP_C,
       QZS_P_PLASTIC, QZS_P_FMAX, QZS_P_ZREF, QZS_P_KP, QZS_P_KI, QZS_P_KD, QZS_P_HP_OMEGA,
       QZS_P_CONTROL_STEPS, QZS_P_DT, QZS_P_VREG, QZS_N_PARAMS };
/* ODE state (S_*), then the held controller outputs and the holding margin (A_*), the
 * controller blocks' states (X_*, qzs_controller.h: a linear controller's, then the friction
 * observer's) and the held outputs of the sampled blocks */
enum { QZS_S_Z, QZS_S_V, QZS_S_HP, QZS_S_INT, QZS_S_W_BASE, QZS_S_D_FRICTION, QZS_S_W_MOTOR,
       QZS_S_D_STOP, QZS_N_ODE, QZS_A_F_PI = QZS_N_ODE, QZS_A_F_DAMP, QZS_A_F_MOTOR,
       QZS_A_MARGIN, QZS_A_X0, QZS_A_F_COMPENSATION = QZS_A_X0 + QZS_N_X, QZS_A_F_DITHER,
       QZS_A_F_LINEAR, QZS_N_STATE };
/* the held outputs (kernels.held_tuple): PI, damping, motor, compensation, dither, linear */
enum { QZS_H_PI, QZS_H_DAMP, QZS_H_MOTOR, QZS_H_COMPENSATION, QZS_H_DITHER, QZS_H_LINEAR,
       QZS_N_HELD };
/* the controller's blocks beyond PI + damping: QZS_M_* in qzs_controller.h */
/* integer flags (I_*) */
enum { QZS_I_MODE, QZS_I_DIRECTION, QZS_I_STEP, QZS_I_CONTACT, QZS_I_N_CONTACTS,
       QZS_I_N_STICKS, QZS_N_FLAGS };
/* excitation scalars (qzs.model.excitation.E_*) and kinds */
enum { QZS_E_KIND, QZS_E_AMPLITUDE, QZS_E_F0, QZS_E_F1, QZS_E_DURATION, QZS_E_PHASE,
       QZS_E_SPACING, QZS_E_FADE, QZS_N_EXCITATION };
enum { QZS_KIND_CHIRP_LINEAR, QZS_KIND_CHIRP_LOG, QZS_KIND_SINE, QZS_KIND_TABLE };
/* output channels (C_*) and flags (O_*) */
enum { QZS_C_TIME, QZS_C_BASE_Y, QZS_C_BASE_YD, QZS_C_BASE_YDD, QZS_C_X, QZS_C_XD, QZS_C_XDD,
       QZS_C_Z, QZS_C_V, QZS_C_F_SPRING, QZS_C_F_FRICTION, QZS_C_F_STOP, QZS_C_F_MOTOR,
       QZS_C_F_PI, QZS_C_F_DAMP, QZS_C_V_MEASURED, QZS_C_W_BASE, QZS_C_D_FRICTION,
       QZS_C_W_MOTOR, QZS_C_D_STOP, QZS_C_E_KINETIC, QZS_C_E_SPRING, QZS_C_E_GRAVITY,
       QZS_C_E_STOP, QZS_C_F_COMPENSATION, QZS_C_F_DITHER, QZS_C_F_LINEAR, QZS_C_F_OBSERVER,
       QZS_N_CHANNELS };
/* the channels of every run; the blocks' (the last four) are written only with blocks */
#define QZS_N_BASE_CHANNELS QZS_C_F_COMPENSATION
enum { QZS_O_LOCKED, QZS_O_CONTACT, QZS_N_OUTPUT_FLAGS };
/* modes of the payload: slipping, stuck to the base, resting on the lower / upper plastic stop */
enum { QZS_MODE_SLIP, QZS_MODE_STICK, QZS_MODE_WALL_LOW, QZS_MODE_WALL_HIGH };
enum { QZS_SOLVER_EULER, QZS_SOLVER_ODE3, QZS_SOLVER_RK4 };
/* a run's status (kernels.STATUS_*): going; diverged; stopped outside a refusing spring table */
enum { QZS_STATUS_OK, QZS_STATUS_DIVERGED, QZS_STATUS_OUTSIDE };
/* excitation's sine and cosine computed exactly every this many steps (kernels.PHASE_PERIOD) */
#define QZS_PHASE_PERIOD 256

/* The ODE state (z, v, high-pass, integral, ledger), by value like the kernels' tuples. */
typedef struct { double x[QZS_N_ODE]; } QzsOde;
/* Base displacement [m], velocity [m/s], acceleration [m/s^2]. */
typedef struct { double y, yd, ydd; } QzsBase;
/* The force breakdown of the right-hand side (kernels.F_*). */
typedef struct {
    double y, yd, ydd, spring, friction, stop, elastic, motor, pi, damp, v_measured, hold, xdd;
    double compensation, dither, linear, observer; /* the blocks' (0 without) */
} QzsForces;

/* What does not change during a run: the parameters and the excitation. */
typedef struct {
    double P[QZS_N_PARAMS];
    double E[QZS_N_EXCITATION];
    const double *table;  /* 5 rows of table_columns (the excitation's piecewise cubic) */
    long table_columns;
    QzsControllerParameters control;  /* the controller's part of P */
    double M[QZS_N_MODEL];  /* the controller's blocks (QZS_M_*) */
    const double *spring;   /* the spring law packed (qzs_spring.h, kept by pointer); NULL: the
                               tanh of P[QZS_P_SPRING_A], P[QZS_P_SPRING_B] */
    int blocks;             /* the general path (kernels.general): blocks (M[QZS_M_BLOCKS] != 0)
                               or a spring law other than the tanh; their code runs */
} QzsPlant;

/* Where the excitation's sine and cosine were last computed. */
typedef struct { double phase, sin0, cos0; } QzsPhase;

/* The result of one grid step. */
typedef struct {
    QzsOde s;
    QzsBlocks x;
    int mode, direction;
    double margin;
    int sticks, impacts;
} QzsStep;

/* Fill the plant from packed parameters, the model row (qzs.engine.prepare.pack_model: the
 * controller's blocks, QZS_N_MODEL values, then the spring law packed, kept by pointer; NULL
 * for no blocks and the tanh of the parameters), excitation scalars and table (kept by
 * pointer). */
void qzs_plant_init(QzsPlant *plant, const double *params, const double *model,
                    const double *excitation, const double *table, long table_columns);
/* Base motion at t [s], exact (libm sine). */
QzsBase qzs_base_motion(const QzsPlant *plant, double t);
/* Phase and its sine/cosine at t, rotated from `previous` or computed exactly. */
QzsPhase qzs_advance_phase(const QzsPlant *plant, double t, QzsPhase previous, int exact);
/* Right-hand side at t (exact base motion): derivatives and forces. */
void qzs_rhs_at(const QzsPlant *plant, double t, const QzsOde *s, const QzsBlocks *x, int mode,
                double direction, const double held[QZS_N_HELD], QzsOde *deriv,
                QzsForces *force);
/* One grid step of length h from t, locating at most one transition inside it. */
QzsStep qzs_grid_step(const QzsPlant *plant, int solver, double t, double h, QzsOde s,
                      QzsBlocks x, int mode, int direction, const double held[QZS_N_HELD],
                      double margin, QzsPhase phase);
/* The sampled controller with blocks at t (kernels.sample_controller): the PI, damping,
 * compensation (the observer advanced first) and dither computed and held, the integral
 * advanced. */
void qzs_sample_blocks(const QzsPlant *plant, double t, QzsOde *s, QzsBlocks *x, int mode,
                       int direction, double held[QZS_N_HELD]);
/* A discrete linear controller's sample at t (kernels.sample_linear): its output held, its
 * states stepped. */
void qzs_sample_linear(const QzsPlant *plant, double t, const QzsOde *s, QzsBlocks *x, int mode,
                       int direction, double held[QZS_N_HELD]);
/* The blocks' states are finite (lanes._finite_blocks). */
int qzs_finite_blocks(const QzsBlocks *x);
/* The measured quantities a sampled controller reads at t: z [m] and v_measured [m/s]. */
void qzs_measure(const QzsPlant *plant, double t, const QzsOde *s, int mode, double *z,
                 double *v_measured);
/* The divergence test: finite, within 100 strokes of the stops and below 1e4 m/s. */
int qzs_finite(const QzsPlant *plant, const QzsOde *s);
/* The status of a run stopped on a non-finite state (kernels.failure_status): QZS_STATUS_OUTSIDE
 * when its spring is a table that refuses positions outside it, else QZS_STATUS_DIVERGED. */
int qzs_failure_status(const QzsPlant *plant);
/* Is the payload on or beyond a stop? */
int qzs_in_contact(const QzsPlant *plant, const QzsOde *s, int mode);
/* One output sample: channels C_* into row, flags O_* into row_flags. */
void qzs_record(const QzsPlant *plant, double t, const QzsOde *s, const QzsBlocks *x, int mode,
                int direction, const double held[QZS_N_HELD], double *row,
                unsigned char *row_flags, QzsPhase phase);

#endif /* QZS_PLANT_H */
