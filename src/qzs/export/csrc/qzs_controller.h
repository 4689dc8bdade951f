/* qzs: the sampled controller of the isolator: PI + active damping (docs/model.md §5) and the
 * blocks a user adds to them (§5.1: friction compensation with deadband and observer, dither,
 * a discrete linear controller with back-calculation anti-windup).
 *
 * Position loop (PI on the relative position z, setpoint z_ref) plus active damping on the
 * measured absolute velocity (the charge amplifier's high-passed signal, a sensor of the
 * plant), summed and saturated at +-f_max, with anti-windup by conditional integration.
 * Sampled with zero-order hold: qzs_controller_step() is called once per sample period, it
 * returns the command held until the next call and advances the PI integral by
 * rate * period_steps * step_time (the operations of qzs.engine.kernels.sample_controller,
 * in the same order, so a sampled qzs run and this code give the same bits).
 *
 * The blocks' laws below (static inline) are the ones qzs's C model of the isolator runs
 * (qzs_plant.c calls them): qzs_block_controller_step() applies them in the order of
 * qzs.engine.kernels.sample_controller then sample_linear, so fed what a sampled qzs run's
 * controller reads it returns the forces that run holds, bit for bit.
 *
 * Plain C99 and libm (fma, floor, fabs, sin): the same text runs on a real-time target,
 * inside the qzs FMU and in qzs's C model of the isolator.
 */
#ifndef QZS_CONTROLLER_H
#define QZS_CONTROLLER_H

#include <math.h>
#include <stdint.h>
#include <string.h>

/* Python's max(a, b) / min(a, b) as numba compiles them: a unless b is larger / smaller. */
#define QZS_PYMAX(a, b) ((b) > (a) ? (b) : (a))
#define QZS_PYMIN(a, b) ((b) < (a) ? (b) : (a))
#if defined(__GNUC__)
#define QZS_INLINE static inline __attribute__((always_inline))
#else
#define QZS_INLINE static inline
#endif

/* The controller blocks' states (kernels.X_*): a linear controller's (at most QZS_NX_MAX),
 * then the friction observer's estimate [N]. */
enum { QZS_NX_MAX = 8, QZS_X_OBSERVER = QZS_NX_MAX, QZS_N_X };
typedef struct { double x[QZS_N_X]; } QzsBlocks;
/* The sensors a linear controller reads, in the kernels' order (qzs.model.sensors.SENSORS):
 * position error z_ref - z [m], measured payload velocity [m/s], payload acceleration and
 * base acceleration [m/s^2], relative velocity [m/s]. */
enum { QZS_N_SENSORS = 5 };
/* The controller's blocks beyond PI + damping, packed as qzs packs them (kernels.M_*,
 * qzs.engine.prepare.pack_model): all zeros for PI + damping alone. The compensator's law
 * Fs' Fc' [N], Cbc' [s/m], Cv' [N*s/m], deadband [m/s]; the observer's rate 2 pi f_o [1/s];
 * the dither's amplitude [N] and 2 pi f [rad/s]; a linear controller's state count, period
 * in integration steps (0: continuous), A (8x8 row-major), B (8x5, by sensor), C (8), D (5),
 * anti-windup gain L (8), zero-padded. */
enum { QZS_M_BLOCKS, QZS_M_COMP_FRACTION, QZS_M_COMP_FS, QZS_M_COMP_FC, QZS_M_COMP_CBC,
       QZS_M_COMP_CV, QZS_M_COMP_DEADBAND, QZS_M_OBSERVER_RATE, QZS_M_DITHER_AMPLITUDE,
       QZS_M_DITHER_OMEGA, QZS_M_LINEAR, QZS_M_LINEAR_STATES, QZS_M_LINEAR_STEPS, QZS_M_A,
       QZS_M_B = QZS_M_A + QZS_NX_MAX * QZS_NX_MAX, QZS_M_C = QZS_M_B + QZS_NX_MAX * QZS_N_SENSORS,
       QZS_M_D = QZS_M_C + QZS_NX_MAX, QZS_M_ANTIWINDUP = QZS_M_D + QZS_N_SENSORS,
       QZS_N_MODEL = QZS_M_ANTIWINDUP + QZS_NX_MAX };
/* a linear controller of at most this many states takes the short loops (kernels.NX_SHORT) */
#define QZS_NX_SHORT 4

/* ---- qzs.engine.arithmetic and laws: the kernels' own exp and tanh, the blocks' laws */

QZS_INLINE double qzs_pow2i(int64_t k) { /* 2**k from the exponent bits */
    uint64_t bits = (uint64_t)(k + 1023) << 52;
    double d;
    memcpy(&d, &bits, sizeof d);
    return d;
}

QZS_INLINE double qzs_exp(double x) {
    x = QZS_PYMIN(QZS_PYMAX(x, -700.0), 700.0);
    double k = floor(fma(x, 1.4426950408889634, 0.5));
    double r = fma(k, -1.90821492927058770002e-10, fma(k, -6.93147180369123816490e-01, x));
    double r2 = r * r;
    double r4 = r2 * r2;
    double low = fma(fma(fma(r, 1.0 / 5040.0, 1.0 / 720.0), r2, fma(r, 1.0 / 120.0, 1.0 / 24.0)),
                     r4, fma(fma(r, 1.0 / 6.0, 0.5), r2, 1.0 + r));
    double high = fma(fma(r, 1.0 / 6227020800.0, 1.0 / 479001600.0), r4,
                      fma(fma(r, 1.0 / 39916800.0, 1.0 / 3628800.0), r2,
                          fma(r, 1.0 / 362880.0, 1.0 / 40320.0)));
    double p = fma(high, r4 * r4, low);
    return p * qzs_pow2i((int64_t)k);
}

QZS_INLINE double qzs_tanh(double u) {
    double a = QZS_PYMIN(fabs(u), 20.0);
    double r = 1.0 - 2.0 / (qzs_exp(2.0 * a) + 1.0);
    return u >= 0.0 ? r : -r;
}

/* laws.sliding_friction_law: the friction force of a slip at v (sign: the slip direction,
 * or tanh(v / v_reg) where v_reg > 0) */
QZS_INLINE double qzs_sliding_friction_law(double v, double sign, double fs, double fc, double cbc,
                                   double cv, double v_reg) {
    double level = fc + (fs - fc) * qzs_exp(-cbc * fabs(v));
    if (v_reg > 0.0)
        sign = qzs_tanh(v / v_reg);
    return -level * sign - cv * v;
}

/* laws.saturation_law: the command clipped at +-f_max, the integral's rate (anti-windup) */
QZS_INLINE double qzs_saturation_law(double command, double error, double ki, double f_max,
                             double *rate) {
    *rate = error;
    if (command > f_max) {
        command = f_max;
        if (error * ki > 0.0)
            *rate = 0.0;
    } else if (command < -f_max) {
        command = -f_max;
        if (error * ki < 0.0)
            *rate = 0.0;
    }
    return command;
}

/* laws.compensation_law: a fraction of the compensator's friction law, cancelled */
QZS_INLINE double qzs_compensation_law(double v, double sign, double fraction, double fs, double fc,
                               double cbc, double cv, double v_reg, double deadband) {
    if (fabs(v) <= deadband)
        return 0.0;
    return -fraction * qzs_sliding_friction_law(v, sign, fs, fc, cbc, cv, v_reg);
}

/* laws.dither_law: A sin(omega t) */
QZS_INLINE double qzs_dither_law(double t, double amplitude, double omega) {
    return amplitude * sin(omega * t);
}

/* kernels._linear_output: C x + D u over the zero-padded rows (short ones for a small
 * controller; a padded term adds an exact zero) */
QZS_INLINE double qzs_linear_output(const double *M, const QzsBlocks *x, const double u[QZS_N_SENSORS]) {
    double y = 0.0;
    int width = M[QZS_M_LINEAR_STATES] <= QZS_NX_SHORT ? QZS_NX_SHORT : QZS_NX_MAX;
    for (int j = 0; j < width; j++)
        y = fma(M[QZS_M_C + j], x->x[j], y);
    for (int k = 0; k < QZS_N_SENSORS; k++)
        y = fma(M[QZS_M_D + k], u[k], y);
    return y;
}

/* kernels._linear_rates: A x + B u + L excess row by row (a padded row 0), then `observer` */
QZS_INLINE void qzs_linear_rates(const double *M, const QzsBlocks *x, const double u[QZS_N_SENSORS],
                         double excess, double observer, QzsBlocks *rates) {
    int width = M[QZS_M_LINEAR_STATES] <= QZS_NX_SHORT ? QZS_NX_SHORT : QZS_NX_MAX;
    for (int i = 0; i < QZS_NX_MAX; i++) {
        double rate = 0.0;
        if (i < width) {
            rate = M[QZS_M_ANTIWINDUP + i] * excess;
            for (int j = 0; j < width; j++)
                rate = fma(M[QZS_M_A + i * QZS_NX_MAX + j], x->x[j], rate);
            for (int k = 0; k < QZS_N_SENSORS; k++)
                rate = fma(M[QZS_M_B + i * QZS_N_SENSORS + k], u[k], rate);
        }
        rates->x[i] = rate;
    }
    rates->x[QZS_X_OBSERVER] = observer;
}

/* kernels._compensation: the friction compensation's feedforward at slip velocity v */
QZS_INLINE double qzs_compensation(const double *M, double v_reg, double v, double direction) {
    if (M[QZS_M_COMP_FRACTION] == 0.0)
        return 0.0;
    return qzs_compensation_law(v, direction, M[QZS_M_COMP_FRACTION], M[QZS_M_COMP_FS],
                                M[QZS_M_COMP_FC], M[QZS_M_COMP_CBC], M[QZS_M_COMP_CV], v_reg,
                                M[QZS_M_COMP_DEADBAND]);
}


/* Parameters of the PI + damping, SI units. */
typedef struct {
    double position_setpoint; /* z_ref [m] */
    double pi_kp;             /* proportional gain [N/m] */
    double pi_ki;             /* integral gain [N/(m*s)] */
    double damping_gain;      /* active damping gain [N*s/m] */
    double motor_force_max;   /* motor saturation [N] */
    double period_steps;      /* sample period in integration steps [-] (1 on a target) */
    double step_time;         /* integration step [s] (the sample period on a target) */
} QzsControllerParameters;

/* One command: PI part, damping part, the saturated motor force [N], the integral's rate [m]. */
typedef struct {
    double pi;
    double damping;
    double motor;
    double integral_rate;
} QzsControllerOutput;

/* The controller: its parameters, the PI integral [m*s] and the command it holds [N]. */
typedef struct {
    QzsControllerParameters parameters;
    double integral;
    QzsControllerOutput output;
} QzsController;

/* The control law at (z [m], v_measured [m/s], integral [m*s]); no state is changed.
 * (qzs.engine.laws.controller_law, operation for operation.) */
static inline QzsControllerOutput qzs_controller_law(const QzsControllerParameters *p, double z,
                                                     double v_measured, double integral) {
    QzsControllerOutput out;
    double error = p->position_setpoint - z;
    double f_pi = p->pi_kp * error + p->pi_ki * integral;
    double f_damp = -p->damping_gain * v_measured;
    double command = f_pi + f_damp;
    double rate;
    command = qzs_saturation_law(command, error, p->pi_ki, p->motor_force_max, &rate);
    out.pi = f_pi;
    out.damping = f_damp;
    out.motor = command;
    out.integral_rate = rate;
    return out;
}

/* Set the parameters and the PI integral [m*s] (qzs's preload, or 0); the held command is
 * the law's at (position_setpoint, 0). */
void qzs_controller_init(QzsController *controller, const QzsControllerParameters *parameters,
                         double integral);

/* One sample: the command for (z [m], v_measured [m/s]), held until the next call; the
 * integral advances by one sample period. */
QzsControllerOutput qzs_controller_step(QzsController *controller, double z, double v_measured);

/* ---- the controller with its blocks (docs/model.md §5.1) */

/* One sample's forces [N]: the PI, the damping, the friction compensation (its feedforward net
 * of the observer's estimate), the dither, the linear controller's output, the saturated motor
 * force, and the observer's estimate of the friction left after the feedforward. */
typedef struct {
    double pi;
    double damping;
    double compensation;
    double dither;
    double linear;
    double motor;
    double friction_estimate;
} QzsBlockOutput;

/* kernels.sample_controller with blocks: the PI and damping with the current integral; the
 * observer (rate M[QZS_M_OBSERVER_RATE] > 0) advanced by forward Euler over the period from what
 * it measures now, `friction` (F_friction + F_stop [N]) plus the compensation applied until now
 * (`held_compensation` + the estimate); the compensation with the new estimate at the slip
 * velocity v [m/s] in the slip `direction` (+-1); the dither at t [s]; the sum with `linear` (the
 * linear controller's output held until now) saturated; then the integral [m*s] advanced by one
 * period. The plant's qzs_sample_blocks() and qzs_block_controller_step() both call it. */
QZS_INLINE QzsBlockOutput qzs_sample_blocks_law(const QzsControllerParameters *p, const double *M,
                                                double v_reg, double t, double z,
                                                double v_measured, double v, double direction,
                                                double friction, double linear,
                                                double held_compensation, double *integral,
                                                double *observer) {
    QzsBlockOutput out;
    QzsControllerOutput c = qzs_controller_law(p, z, v_measured, *integral);
    if (M[QZS_M_OBSERVER_RATE] > 0.0) {
        double applied = held_compensation + *observer;
        double measured = friction + applied;
        *observer = *observer +
                    M[QZS_M_OBSERVER_RATE] * (measured - *observer) * p->period_steps * p->step_time;
    }
    double feedforward = qzs_compensation(M, v_reg, v, direction);
    out.pi = c.pi;
    out.damping = c.damping;
    out.compensation = feedforward - *observer; /* the new estimate, applied at once */
    out.dither = 0.0;
    if (M[QZS_M_DITHER_AMPLITUDE] != 0.0)
        out.dither = qzs_dither_law(t, M[QZS_M_DITHER_AMPLITUDE], M[QZS_M_DITHER_OMEGA]);
    out.linear = linear;
    double command = c.pi + c.damping + out.compensation + out.dither + linear;
    double rate;
    out.motor = qzs_saturation_law(command, p->position_setpoint - z, p->pi_ki,
                                   p->motor_force_max, &rate);
    *integral = *integral + rate * p->period_steps * p->step_time;
    out.friction_estimate = *observer;
    return out;
}

/* kernels.sample_linear: a discrete linear controller's sample with its sensors u (QZS_N_SENSORS)
 * and `others`, the sum of the PI, damping, compensation and dither forces held from this
 * sample [N]: the output C x + D u (returned), the motor force saturated (*motor), the states
 * stepped x <- A x + B u + L (F_motor - F_cmd). The plant's qzs_sample_linear() and
 * qzs_block_controller_step() both call it. */
QZS_INLINE double qzs_sample_linear_law(const QzsControllerParameters *p, const double *M,
                                        double z, const double u[QZS_N_SENSORS], double others,
                                        QzsBlocks *x, double *motor) {
    double output = qzs_linear_output(M, x, u);
    double command = others + output;
    double rate;
    double f_motor = qzs_saturation_law(command, p->position_setpoint - z, p->pi_ki,
                                        p->motor_force_max, &rate);
    QzsBlocks next;
    qzs_linear_rates(M, x, u, f_motor - command, x->x[QZS_X_OBSERVER], &next);
    *x = next;
    *motor = f_motor;
    return output;
}

/* What the rig measures at a sample, SI units (the sensors of docs/model.md §5.1). */
typedef struct {
    double time;                 /* t [s] since the start: the dither's phase */
    double position;             /* z [m], the encoder's relative position (error z_ref - z) */
    double measured_velocity;    /* v_meas [m/s], the charge amplifier's high-passed payload
                                    velocity */
    double relative_velocity;    /* v [m/s], the encoder's slip velocity: 0 while stuck; its
                                    sign is the slip direction the compensation takes */
    double payload_acceleration; /* [m/s^2], read only by a linear controller */
    double base_acceleration;    /* [m/s^2], read only by a linear controller */
    double friction_force;       /* F_friction + F_stop [N], read only by the friction observer:
                                    what the payload's balance m xdd - F_spring(z) - F_motor + m g
                                    gives with the motor force held until this sample */
} QzsSensors;

/* The controller with blocks: the PI + damping's parameters, the velocity v_reg [m/s] of a
 * regularised friction sign (0: the exact sign), the blocks packed (QZS_M_*). A linear
 * controller samples with the PI, every call (its period is the controller's). */
typedef struct {
    QzsControllerParameters control;
    double velocity_regularisation;
    double model[QZS_N_MODEL];
} QzsBlockParameters;

/* Its state: the PI integral [m*s], the blocks' states (a linear controller's, the observer's
 * estimate [N]) and the forces it holds until the next call. */
typedef struct {
    QzsBlockParameters parameters;
    double integral;
    QzsBlocks x;
    QzsBlockOutput output;
} QzsBlockController;

/* Set the parameters and the initial state: the integral [m*s], the blocks' states and the
 * forces held at t = 0 (those qzs starts a run with: QZS_BLOCK_CONTROLLER_INITIAL). */
void qzs_block_controller_init(QzsBlockController *controller,
                               const QzsBlockParameters *parameters, double integral,
                               const QzsBlocks *x, const QzsBlockOutput *held);

/* One sample: the forces for what the rig measures now, held until the next call (call it
 * every period_steps * step_time seconds); the integral, the observer and a linear
 * controller's states advance by one period. */
QzsBlockOutput qzs_block_controller_step(QzsBlockController *controller,
                                         const QzsSensors *sensors);

#endif /* QZS_CONTROLLER_H */
