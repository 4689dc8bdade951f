/* qzs: the single-axis isolator plant (see qzs_plant.h). Each function names the kernel it
 * mirrors; the order of the operations is the kernels'. */
#include "qzs_plant.h"

#include <math.h>
#include <string.h>

/* qzs_controller.h's: Python's max / min as numba compiles them, always inlined */
#define PYMAX(a, b) QZS_PYMAX(a, b)
#define PYMIN(a, b) QZS_PYMIN(a, b)
#define INLINE QZS_INLINE

static const double TWO_PI = 6.283185307179586; /* 2.0 * np.pi */
static const double PI = 3.141592653589793;
#define LOCATE_ITERATIONS 6

/* ------------------------------------------------------------ arithmetic.py */

/* ------------------------------------------------------------ laws.py */

INLINE double spring_law(double a, double b, double z) { return -a * qzs_tanh(b * z); }

INLINE double spring_energy_law(double a, double b, double z) {
    double u = fabs(b * z);
    return a / b * (u + log1p(exp(-2.0 * u)) - log(2.0));
}

/* kernels.general_spring / general_spring_energy: the law's force [N] (`want`
 * QZS_SPRING_FORCE) or energy [J] (QZS_SPRING_ENERGY), NaN outside a refusing table (the run
 * then stops, qzs_failure_status); the tanh's without a law */
INLINE double spring_of(const QzsPlant *plant, double z, int want) {
    double a = plant->P[QZS_P_SPRING_A], b = plant->P[QZS_P_SPRING_B];
    if (!plant->spring)
        return want == QZS_SPRING_FORCE ? spring_law(a, b, z) : spring_energy_law(a, b, z);
    QzsSpringValues values;
    qzs_spring_evaluate(plant->spring, z, want, &values);
    return want == QZS_SPRING_FORCE ? values.force : values.energy;
}

INLINE void compliant_stop_law(double z, double v, double z_low, double z_high,
                               double stiffness, double damping, double *f_stop,
                               double *f_elastic) {
    *f_stop = 0.0;
    *f_elastic = 0.0;
    if (z < z_low) {
        *f_elastic = stiffness * (z_low - z);
        *f_stop = PYMAX(*f_elastic - damping * v, 0.0); /* a stop pushes, never pulls */
    } else if (z > z_high) {
        *f_elastic = -stiffness * (z - z_high);
        *f_stop = PYMIN(*f_elastic - damping * v, 0.0);
    }
}

/* ------------------------------------------------------------ stickslip.py */

INLINE double slip_event(double direction, double v) { return direction * v; }

INLINE double hold_margin(int mode, double f_hold, double fs) {
    if (mode == QZS_MODE_STICK)
        return fs - fabs(f_hold);
    if (mode == QZS_MODE_WALL_LOW)
        return f_hold + fs;
    return fs - f_hold;
}

INLINE int release_direction(int mode, double f_hold) {
    if (mode == QZS_MODE_STICK)
        return f_hold > 0.0 ? -1 : 1;
    return mode == QZS_MODE_WALL_LOW ? 1 : -1;
}

INLINE int crossed_zero(double g0, double g1) { return g1 < 0.0 || (g1 == 0.0 && g0 > 0.0); }

INLINE double secant_fraction(double g0, double g1) { return g0 > g1 ? g0 / (g0 - g1) : 0.0; }

/* ------------------------------------------------------------ base_motion.py */

INLINE void phase_of(const double *E, double t, double *phase, double *omega, double *omega_dot) {
    int kind = (int)E[QZS_E_KIND];
    if (kind == QZS_KIND_CHIRP_LINEAR) {
        double f0 = E[QZS_E_F0];
        double rate = (E[QZS_E_F1] - f0) / E[QZS_E_DURATION];
        *phase = TWO_PI * (f0 * t + 0.5 * rate * t * t);
        *omega = TWO_PI * (f0 + rate * t);
        *omega_dot = TWO_PI * rate;
    } else if (kind == QZS_KIND_CHIRP_LOG) {
        double f0 = E[QZS_E_F0];
        double growth = log(E[QZS_E_F1] / f0) / E[QZS_E_DURATION];
        double w = TWO_PI * f0 * exp(growth * t);
        *phase = (w - TWO_PI * f0) / growth;
        *omega = w;
        *omega_dot = w * growth;
    } else {
        double w = TWO_PI * E[QZS_E_F0];
        *phase = w * t + E[QZS_E_PHASE];
        *omega = w;
        *omega_dot = 0.0;
    }
}

INLINE QzsBase table_motion(const QzsPlant *plant, double t) {
    const double *table = plant->table;
    long columns = plant->table_columns;
    long n = columns - 1;
    double spacing = plant->E[QZS_E_SPACING];
    long i;
    if (spacing > 0.0) {
        i = (long)((t - table[0]) / spacing);
    } else {
        long lo = 0, hi = n; /* bisection: table[0, lo] <= t < table[0, hi] */
        while (hi - lo > 1) {
            long mid = (lo + hi) / 2;
            if (table[mid] <= t)
                lo = mid;
            else
                hi = mid;
        }
        i = lo;
    }
    i = PYMIN(PYMAX(i, 0), n - 1);
    double dx = t - table[i];
    double c0 = table[columns + i], c1 = table[2 * columns + i], c2 = table[3 * columns + i],
           c3 = table[4 * columns + i];
    QzsBase b = {((c0 * dx + c1) * dx + c2) * dx + c3, (3.0 * c0 * dx + 2.0 * c1) * dx + c2,
                 6.0 * c0 * dx + 2.0 * c1};
    return b;
}

INLINE QzsBase fade(double t, double fade_time, QzsBase b) {
    if (t >= fade_time || fade_time <= 0.0)
        return b;
    if (t <= 0.0)
        t = 0.0;
    double k = 2.0 * PI / fade_time;
    double s = sin(k * t), c = cos(k * t);
    double w = t / fade_time - s / (2.0 * PI);
    double w1 = (1.0 - c) / fade_time;
    double w2 = k * s / fade_time;
    QzsBase out = {w * b.y, w1 * b.y + w * b.yd, w2 * b.y + 2.0 * w1 * b.yd + w * b.ydd};
    return out;
}

INLINE QzsBase harmonic(double amplitude, double s, double c, double omega, double omega_dot) {
    QzsBase b = {amplitude * s, amplitude * c * omega,
                 amplitude * (c * omega_dot - s * omega * omega)};
    return b;
}

QzsBase qzs_base_motion(const QzsPlant *plant, double t) {
    const double *E = plant->E;
    QzsBase b;
    if ((int)E[QZS_E_KIND] == QZS_KIND_TABLE) {
        b = table_motion(plant, t);
    } else {
        double phase, omega, omega_dot;
        phase_of(E, t, &phase, &omega, &omega_dot);
        b = harmonic(E[QZS_E_AMPLITUDE], sin(phase), cos(phase), omega, omega_dot);
    }
    return fade(t, E[QZS_E_FADE], b);
}

INLINE void rotate(double phase, double phase0, double sin0, double cos0, double *s, double *c) {
    double d = phase - phase0;
    if (fabs(d) < 0.1) {
        double d2 = d * d;
        double sd =
            d * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0 * (1.0 - d2 / 42.0 * (1.0 - d2 / 72.0))));
        double cd = 1.0 - d2 / 2.0 * (1.0 - d2 / 12.0 * (1.0 - d2 / 30.0 * (1.0 - d2 / 56.0)));
        *s = sin0 * cd + cos0 * sd;
        *c = cos0 * cd - sin0 * sd;
    } else {
        *s = sin(phase);
        *c = cos(phase);
    }
}

INLINE QzsBase base_motion_near(const QzsPlant *plant, double t, QzsPhase near) {
    const double *E = plant->E;
    QzsBase b;
    if ((int)E[QZS_E_KIND] == QZS_KIND_TABLE) {
        b = table_motion(plant, t);
    } else {
        double phase, omega, omega_dot, s, c;
        phase_of(E, t, &phase, &omega, &omega_dot);
        rotate(phase, near.phase, near.sin0, near.cos0, &s, &c);
        b = harmonic(E[QZS_E_AMPLITUDE], s, c, omega, omega_dot);
    }
    return fade(t, E[QZS_E_FADE], b);
}

QzsPhase qzs_advance_phase(const QzsPlant *plant, double t, QzsPhase previous, int exact) {
    QzsPhase out = {0.0, 0.0, 1.0};
    if ((int)plant->E[QZS_E_KIND] == QZS_KIND_TABLE)
        return out;
    double omega, omega_dot;
    phase_of(plant->E, t, &out.phase, &omega, &omega_dot);
    if (exact) {
        out.sin0 = sin(out.phase);
        out.cos0 = cos(out.phase);
    } else {
        rotate(out.phase, previous.phase, previous.sin0, previous.cos0, &out.sin0, &out.cos0);
    }
    return out;
}

/* ------------------------------------------------------------ kernels.py */

void qzs_plant_init(QzsPlant *plant, const double *params, const double *model,
                    const double *excitation, const double *table, long table_columns) {
    memcpy(plant->P, params, sizeof plant->P);
    if (model)
        memcpy(plant->M, model, sizeof plant->M);
    else
        memset(plant->M, 0, sizeof plant->M);
    plant->spring = model && model[QZS_N_MODEL] != QZS_SPRING_TANH ? model + QZS_N_MODEL : 0;
    plant->blocks = plant->M[QZS_M_BLOCKS] != 0.0 || plant->spring;
    memcpy(plant->E, excitation, sizeof plant->E);
    plant->table = table;
    plant->table_columns = table_columns;
    const double *P = plant->P;
    QzsControllerParameters c = {P[QZS_P_ZREF], P[QZS_P_KP], P[QZS_P_KI], P[QZS_P_KD],
                                 P[QZS_P_FMAX], P[QZS_P_CONTROL_STEPS], P[QZS_P_DT]};
    plant->control = c;
}

/* kernels.block_forces: compensation, dither, linear output, and the feedforward alone */
INLINE void block_forces(const QzsPlant *plant, double t, const QzsOde *s, const QzsBlocks *x,
                         double v, double direction, double ydd, double v_measured,
                         const double *held, double *f_comp, double *f_dither,
                         double *f_linear, double *feedforward) {
    const double *P = plant->P, *M = plant->M;
    *feedforward = 0.0;
    if (P[QZS_P_CONTROL_STEPS] > 0.0) {
        *f_comp = held[QZS_H_COMPENSATION];
        *f_dither = held[QZS_H_DITHER];
    } else {
        *feedforward = qzs_compensation(M, P[QZS_P_VREG], v, direction);
        *f_comp = *feedforward - x->x[QZS_X_OBSERVER];
        *f_dither = 0.0;
        if (M[QZS_M_DITHER_AMPLITUDE] != 0.0)
            *f_dither = qzs_dither_law(t, M[QZS_M_DITHER_AMPLITUDE], M[QZS_M_DITHER_OMEGA]);
    }
    *f_linear = 0.0;
    if (M[QZS_M_LINEAR] != 0.0) {
        if (M[QZS_M_LINEAR_STEPS] > 0.0) {
            *f_linear = held[QZS_H_LINEAR];
        } else { /* the payload's acceleration enters only through B */
            double u[QZS_N_SENSORS] = {P[QZS_P_ZREF] - s->x[QZS_S_Z], v_measured, 0.0, ydd, v};
            *f_linear = qzs_linear_output(M, x, u);
        }
    }
}

/* kernels.rhs: m*xdd = F_spring + F_friction + F_stop + F_motor - m*g; held: v = 0, xdd = ydd.
 * The blocks (plant->blocks) add their forces and their states' rates (`rates`, may be NULL);
 * without them the operations are those of PI + damping alone. */
INLINE void rhs(const QzsPlant *plant, double t, QzsBase b, const QzsOde *s, const QzsBlocks *x,
                int mode, double direction, const double *held, QzsOde *deriv,
                QzsForces *force, QzsBlocks *rates) {
    const double *P = plant->P;
    double m = P[QZS_P_MASS];
    double z = s->x[QZS_S_Z];
    double v = mode == QZS_MODE_SLIP ? s->x[QZS_S_V] : 0.0;
    double xd = b.yd + v;
    double f_spring = spring_of(plant, z, QZS_SPRING_FORCE);

    double f_stop = 0.0, f_elastic = 0.0;
    if (P[QZS_P_PLASTIC] == 0.0)
        compliant_stop_law(z, v, P[QZS_P_Z_LOW], P[QZS_P_Z_HIGH], P[QZS_P_STOP_K],
                           P[QZS_P_STOP_C], &f_stop, &f_elastic);

    double v_measured = P[QZS_P_HP_OMEGA] > 0.0 ? xd - s->x[QZS_S_HP] : xd;
    double f_pi, f_damp, f_motor, integral_rate;
    if (P[QZS_P_CONTROL_STEPS] > 0.0) {
        f_pi = held[QZS_H_PI];
        f_damp = held[QZS_H_DAMP];
        f_motor = held[QZS_H_MOTOR];
        integral_rate = 0.0;
    } else {
        QzsControllerOutput c = qzs_controller_law(&plant->control, z, v_measured,
                                                   s->x[QZS_S_INT]);
        f_pi = c.pi;
        f_damp = c.damping;
        f_motor = c.motor;
        integral_rate = c.integral_rate;
    }
    double f_comp = 0.0, f_dither = 0.0, f_linear = 0.0, feedforward = 0.0;
    double command = f_motor;
    if (plant->blocks) {
        block_forces(plant, t, s, x, v, direction, b.ydd, v_measured, held, &f_comp, &f_dither,
                     &f_linear, &feedforward);
        command = f_pi + f_damp + f_comp + f_dither + f_linear;
        double rate;
        f_motor = qzs_saturation_law(command, P[QZS_P_ZREF] - z, P[QZS_P_KI], P[QZS_P_FMAX], &rate);
        if (P[QZS_P_CONTROL_STEPS] == 0.0)
            integral_rate = rate;
    }

    double f_applied = f_spring + f_stop + f_motor - m * P[QZS_P_GRAVITY];
    double f_hold = m * b.ydd - f_applied;
    double f_friction, xdd;
    if (mode == QZS_MODE_SLIP) {
        f_friction = qzs_sliding_friction_law(v, direction, P[QZS_P_FS], P[QZS_P_FC], P[QZS_P_CBC],
                                          P[QZS_P_CV], P[QZS_P_VREG]);
        xdd = (f_applied + f_friction) * (1.0 / m);
    } else {
        f_friction = f_hold;
        if (mode == QZS_MODE_WALL_LOW) { /* the stop takes the upward part, friction the rest */
            double f_wall = PYMAX(f_hold, 0.0);
            f_friction = f_hold - f_wall;
            f_stop += f_wall;
        } else if (mode == QZS_MODE_WALL_HIGH) {
            double f_wall = PYMIN(f_hold, 0.0);
            f_friction = f_hold - f_wall;
            f_stop += f_wall;
        }
        xdd = b.ydd;
    }
    if (rates) {
        for (int i = 0; i < QZS_N_X; i++)
            rates->x[i] = 0.0;
        if (plant->blocks) {
            const double *M = plant->M;
            double observer = 0.0;
            if (P[QZS_P_CONTROL_STEPS] == 0.0 && M[QZS_M_OBSERVER_RATE] > 0.0)
                observer = M[QZS_M_OBSERVER_RATE] *
                           (f_friction + f_stop + feedforward - x->x[QZS_X_OBSERVER]);
            if (M[QZS_M_LINEAR] != 0.0 && M[QZS_M_LINEAR_STEPS] == 0.0) {
                double u[QZS_N_SENSORS] = {P[QZS_P_ZREF] - z, v_measured, xdd, b.ydd, v};
                qzs_linear_rates(M, x, u, f_motor - command, observer, rates);
            } else {
                rates->x[QZS_X_OBSERVER] = observer;
            }
        }
    }
    if (deriv) {
        deriv->x[0] = v;
        deriv->x[1] = xdd - b.ydd;
        deriv->x[2] = P[QZS_P_HP_OMEGA] * (xd - s->x[QZS_S_HP]);
        deriv->x[3] = integral_rate;
        deriv->x[4] = (f_spring + f_friction + f_stop + f_motor) * b.yd;
        deriv->x[5] = -f_friction * v;
        deriv->x[6] = f_motor * v;
        deriv->x[7] = -(f_stop - f_elastic) * v;
    }
    if (force) {
        QzsForces f = {b.y, b.yd, b.ydd, f_spring, f_friction, f_stop, f_elastic, f_motor,
                       f_pi, f_damp, v_measured, f_hold, xdd, f_comp, f_dither, f_linear,
                       plant->blocks ? x->x[QZS_X_OBSERVER] : 0.0};
        *force = f;
    }
}

/* kernels.rhs_at, with the blocks' rates (NULL: not wanted) */
INLINE void rhs_at(const QzsPlant *plant, double t, const QzsOde *s, const QzsBlocks *x,
                   int mode, double direction, const double *held, QzsOde *deriv,
                   QzsForces *force, QzsBlocks *rates) {
    rhs(plant, t, qzs_base_motion(plant, t), s, x, mode, direction, held, deriv, force, rates);
}

void qzs_rhs_at(const QzsPlant *plant, double t, const QzsOde *s, const QzsBlocks *x, int mode,
                double direction, const double held[QZS_N_HELD], QzsOde *deriv,
                QzsForces *force) {
    rhs_at(plant, t, s, x, mode, direction, held, deriv, force, 0);
}

INLINE double hold_at(const QzsPlant *plant, double t, const QzsOde *s, const QzsBlocks *x,
                      int mode, const double *held) {
    QzsForces f;
    rhs_at(plant, t, s, x, mode, 0.0, held, 0, &f, 0);
    return f.hold;
}

INLINE QzsOde axpy(const QzsOde *s, double a, const QzsOde *k) {
    QzsOde out;
    for (int j = 0; j < QZS_N_ODE; j++)
        out.x[j] = fma(a, k->x[j], s->x[j]);
    return out;
}

/* kernels._axpy_blocks */
INLINE QzsBlocks axpy_blocks(const QzsBlocks *x, double a, const QzsBlocks *k) {
    QzsBlocks out;
    for (int j = 0; j < QZS_N_X; j++)
        out.x[j] = fma(a, k->x[j], x->x[j]);
    return out;
}

INLINE int n_stages(int solver) {
    if (solver == QZS_SOLVER_EULER)
        return 1;
    return solver == QZS_SOLVER_ODE3 ? 3 : 4;
}

/* kernels.tableau: (offset, a, weight) of a stage */
INLINE void tableau(int solver, double h, int stage, double *offset, double *a, double *weight) {
    if (solver == QZS_SOLVER_EULER) {
        *offset = 0.0; *a = 0.0; *weight = h;
    } else if (solver == QZS_SOLVER_ODE3) {
        if (stage == 0) {
            *offset = 0.0; *a = 0.0; *weight = h * (2.0 / 9.0);
        } else if (stage == 1) {
            *offset = 0.5 * h; *a = 0.5 * h; *weight = h * (1.0 / 3.0);
        } else {
            *offset = 0.75 * h; *a = 0.75 * h; *weight = h * (4.0 / 9.0);
        }
    } else if (stage == 0) {
        *offset = 0.0; *a = 0.0; *weight = h * (1.0 / 6.0);
    } else if (stage == 3) {
        *offset = h; *a = h; *weight = h * (1.0 / 6.0);
    } else {
        *offset = 0.5 * h; *a = 0.5 * h; *weight = h * (1.0 / 3.0);
    }
}

/* kernels.rk_step: the base motion at each stage rotated from a nearby phase; the blocks'
 * states step with the plant's (only with blocks: without, *x_out is not written) */
INLINE QzsOde rk_step(const QzsPlant *plant, int solver, double t, double h, const QzsOde *s,
                      const QzsBlocks *x, int mode, double direction, const double *held,
                      QzsPhase near, QzsBlocks *x_out) {
    QzsOde result = *s, k = *s, input;
    QzsBlocks result_x, k_x, input_x;
    if (plant->blocks) {
        result_x = *x;
        k_x = *x;
    }
    int stages = n_stages(solver);
    for (int stage = 0; stage < stages; stage++) {
        double offset, a, weight;
        tableau(solver, h, stage, &offset, &a, &weight);
        QzsBase b = base_motion_near(plant, t + offset, near);
        if (stage == 0)
            input = *s;
        else
            input = axpy(s, a, &k);
        if (plant->blocks) {
            input_x = stage == 0 ? *x : axpy_blocks(x, a, &k_x);
            rhs(plant, t + offset, b, &input, &input_x, mode, direction, held, &k, 0, &k_x);
            result_x = axpy_blocks(&result_x, weight, &k_x);
        } else {
            rhs(plant, t + offset, b, &input, x, mode, direction, held, &k, 0, 0);
        }
        result = axpy(&result, weight, &k);
    }
    if (plant->blocks)
        *x_out = result_x;
    return result;
}

/* kernels._rk: the same step for the event path, each stage at the exact base motion; k0, k0_x
 * the first stage's rates. The blocks' states only with blocks (else *x_out = *x). */
static QzsOde rk_exact(const QzsPlant *plant, int solver, double t, double h, const QzsOde *s,
                       const QzsBlocks *x, const QzsOde *k0, const QzsBlocks *k0_x, int mode,
                       double direction, const double *held, QzsBlocks *x_out) {
    double offset, a, weight;
    tableau(solver, h, 0, &offset, &a, &weight);
    QzsOde result = axpy(s, weight, k0);
    QzsOde k = *k0;
    int blocks = plant->blocks;
    QzsBlocks result_x = *x, k_x = *x;
    if (blocks) {
        result_x = axpy_blocks(x, weight, k0_x);
        k_x = *k0_x;
    }
    int stages = n_stages(solver);
    for (int stage = 1; stage < stages; stage++) {
        tableau(solver, h, stage, &offset, &a, &weight);
        QzsOde input = axpy(s, a, &k);
        QzsOde next;
        if (blocks) {
            QzsBlocks input_x = axpy_blocks(x, a, &k_x), next_x;
            rhs_at(plant, t + offset, &input, &input_x, mode, direction, held, &next, 0, &next_x);
            k_x = next_x;
            result = axpy(&result, weight, &next);
            result_x = axpy_blocks(&result_x, weight, &k_x);
        } else {
            rhs_at(plant, t + offset, &input, x, mode, direction, held, &next, 0, 0);
            result = axpy(&result, weight, &next);
        }
        k = next;
    }
    *x_out = result_x;
    return result;
}

/* kernels.energies: kinetic, spring, gravity and stop-elastic energy [J] */
static void energies(const QzsPlant *plant, double y, double yd, const QzsOde *s, int mode,
                     double e[4]) {
    const double *P = plant->P;
    double z = s->x[QZS_S_Z];
    double v = mode == QZS_MODE_SLIP ? s->x[QZS_S_V] : 0.0;
    double m = P[QZS_P_MASS];
    double pen = 0.0;
    if (P[QZS_P_PLASTIC] == 0.0)
        pen = PYMAX(P[QZS_P_Z_LOW] - z, 0.0) + PYMAX(z - P[QZS_P_Z_HIGH], 0.0);
    double xd = yd + v;
    e[0] = 0.5 * m * (xd * xd);
    e[1] = spring_of(plant, z, QZS_SPRING_ENERGY);
    e[2] = m * P[QZS_P_GRAVITY] * (y + z);
    e[3] = 0.5 * P[QZS_P_STOP_K] * pen * pen;
}

static double mechanical_energy(const QzsPlant *plant, double t, const QzsOde *s, int mode) {
    QzsBase b = qzs_base_motion(plant, t);
    double e[4];
    energies(plant, b.y, b.yd, s, mode, e);
    return e[0] + e[1] + e[2] + e[3];
}

/* kernels._book_impulse: v set to exactly 0, the impulse that does it booked in `ledger` */
static QzsOde book_impulse(const QzsPlant *plant, double t, QzsOde s, int ledger) {
    QzsBase b = qzs_base_motion(plant, t);
    double m = plant->P[QZS_P_MASS];
    double v = s.x[QZS_S_V];
    s.x[QZS_S_V] = 0.0;
    s.x[QZS_S_W_BASE] = s.x[QZS_S_W_BASE] - m * v * b.yd;
    s.x[ledger] = s.x[ledger] + 0.5 * m * v * v;
    return s;
}

/* kernels._settle: at a zero crossing of v, stick if friction can hold, else reverse */
static QzsOde settle(const QzsPlant *plant, double t, QzsOde s, const QzsBlocks *x,
                     const double *held, int *mode, int *direction) {
    s = book_impulse(plant, t, s, QZS_S_D_FRICTION);
    double f_hold = hold_at(plant, t, &s, x, QZS_MODE_STICK, held);
    if (fabs(f_hold) <= plant->P[QZS_P_FS]) {
        *mode = QZS_MODE_STICK;
    } else {
        *mode = QZS_MODE_SLIP;
        *direction = release_direction(QZS_MODE_STICK, f_hold);
    }
    return s;
}

/* kernels._hit_wall: perfectly plastic impact on a stop */
static QzsOde hit_wall(const QzsPlant *plant, double t, QzsOde s, const QzsBlocks *x, int low,
                       const double *held, int *mode, int *direction) {
    const double *P = plant->P;
    s = book_impulse(plant, t, s, QZS_S_D_STOP);
    double before = mechanical_energy(plant, t, &s, QZS_MODE_SLIP);
    s.x[QZS_S_Z] = low ? P[QZS_P_Z_LOW] : P[QZS_P_Z_HIGH];
    s.x[QZS_S_D_STOP] = s.x[QZS_S_D_STOP] + before - mechanical_energy(plant, t, &s, QZS_MODE_SLIP);
    int wall = low ? QZS_MODE_WALL_LOW : QZS_MODE_WALL_HIGH;
    double f_hold = hold_at(plant, t, &s, x, wall, held);
    if (hold_margin(wall, f_hold, P[QZS_P_FS]) < 0.0) {
        *mode = QZS_MODE_SLIP;
        *direction = release_direction(wall, f_hold);
    } else {
        *mode = wall;
        *direction = 0;
    }
    return s;
}

/* kernels._event_value */
static double event_value(const QzsPlant *plant, int event, double t, const QzsOde *s,
                          const QzsBlocks *x, int mode, int direction, const double *held) {
    const double *P = plant->P;
    if (event == 1)
        return slip_event((double)direction, s->x[QZS_S_V]);
    if (event == 2)
        return s->x[QZS_S_Z] - P[QZS_P_Z_LOW];
    if (event == 3)
        return P[QZS_P_Z_HIGH] - s->x[QZS_S_Z];
    return hold_margin(mode, hold_at(plant, t, s, x, mode, held), P[QZS_P_FS]);
}

/* kernels._margin_near */
static double margin_near(const QzsPlant *plant, double t, const QzsOde *s, const QzsBlocks *x,
                          int mode, const double *held, QzsPhase near) {
    QzsForces f;
    rhs(plant, t, base_motion_near(plant, t, near), s, x, mode, 0.0, held, 0, &f, 0);
    return hold_margin(mode, f.hold, plant->P[QZS_P_FS]);
}

/* kernels._first_event: kind (0: none) and time fraction of the first transition */
INLINE int first_event(const QzsPlant *plant, const QzsOde *s, const QzsOde *s1, int mode,
                       int direction, double margin, double margin1, double *fraction) {
    const double *P = plant->P;
    double theta = 2.0;
    int event = 0;
    if (mode == QZS_MODE_SLIP) {
        double v0 = slip_event((double)direction, s->x[QZS_S_V]);
        double v1 = slip_event((double)direction, s1->x[QZS_S_V]);
        if (P[QZS_P_VREG] == 0.0 && crossed_zero(v0, v1)) {
            theta = secant_fraction(v0, v1);
            event = 1;
        }
        if (P[QZS_P_PLASTIC] != 0.0) {
            if (s1->x[QZS_S_Z] < P[QZS_P_Z_LOW]) {
                double f = (s->x[QZS_S_Z] - P[QZS_P_Z_LOW]) / (s->x[QZS_S_Z] - s1->x[QZS_S_Z]);
                if (f < theta) {
                    theta = f;
                    event = 2;
                }
            } else if (s1->x[QZS_S_Z] > P[QZS_P_Z_HIGH]) {
                double f = (P[QZS_P_Z_HIGH] - s->x[QZS_S_Z]) / (s1->x[QZS_S_Z] - s->x[QZS_S_Z]);
                if (f < theta) {
                    theta = f;
                    event = 3;
                }
            }
        }
    } else if (margin1 < 0.0) {
        theta = secant_fraction(margin, margin1);
        event = 4;
    }
    *fraction = PYMIN(PYMAX(theta, 0.0), 1.0);
    return event;
}

/* stickslip.locate with kernels._locate's trial: regula falsi (Illinois) on fresh steps */
static double locate(const QzsPlant *plant, int solver, int event, double t, double h,
                     const QzsOde *s, const QzsBlocks *x, double g0, double g1, int mode,
                     int direction, const double *held, QzsOde *state, QzsBlocks *state_x) {
    *state = *s;
    *state_x = *x;
    if (!(g0 > 0.0))
        return 0.0;
    QzsOde k0;
    QzsBlocks k0_x;
    rhs_at(plant, t, s, x, mode, (double)direction, held, &k0, 0, plant->blocks ? &k0_x : 0);
    double lo = 0.0, hi = h, g_lo = g0, g_hi = g1;
    double at = h * g0 / (g0 - g1);
    int side = 0;
    for (int i = 0; i < LOCATE_ITERATIONS; i++) {
        *state = rk_exact(plant, solver, t, at, s, x, &k0, &k0_x, mode, (double)direction, held,
                          state_x);
        double g = event_value(plant, event, t + at, state, state_x, mode, direction, held);
        /* stickslip.illinois_step */
        if (fabs(g) <= 1e-15 * (fabs(g0) + 1e-300) || hi - lo <= 1e-12 * h)
            break;
        if (g > 0.0) {
            lo = at;
            g_lo = g;
            if (side == 1)
                g_hi *= 0.5;
            side = 1;
        } else {
            hi = at;
            g_hi = g;
            if (side == -1)
                g_lo *= 0.5;
            side = -1;
        }
        at = lo + (hi - lo) * g_lo / (g_lo - g_hi);
    }
    return at;
}

QzsStep qzs_grid_step(const QzsPlant *plant, int solver, double t, double h, QzsOde s,
                      QzsBlocks x, int mode, int direction, const double held[QZS_N_HELD],
                      double margin, QzsPhase phase) {
    const double *P = plant->P;
    QzsStep out;
    out.sticks = 0;
    out.impacts = 0;
    /* a zero crossing missed earlier */
    if (mode == QZS_MODE_SLIP && P[QZS_P_VREG] == 0.0 &&
        slip_event((double)direction, s.x[QZS_S_V]) < 0.0) {
        s = settle(plant, t, s, &x, held, &mode, &direction);
        out.sticks += mode == QZS_MODE_STICK;
        margin = NAN;
    }
    if (mode != QZS_MODE_SLIP) {
        if (margin != margin)
            margin = margin_near(plant, t, &s, &x, mode, held, phase);
        if (margin < 0.0) {
            double f_hold = hold_at(plant, t, &s, &x, mode, held);
            direction = release_direction(mode, f_hold);
            mode = QZS_MODE_SLIP;
        }
    }

    QzsBlocks x1 = x;
    QzsOde s1 = rk_step(plant, solver, t, h, &s, &x, mode, (double)direction, held, phase, &x1);
    double margin1 = NAN;
    if (mode != QZS_MODE_SLIP)
        margin1 = margin_near(plant, t + h, &s1, &x1, mode, held, phase);
    double theta;
    int event = first_event(plant, &s, &s1, mode, direction, margin, margin1, &theta);
    if (event == 0) {
        out.s = s1;
        out.x = x1;
        out.mode = mode;
        out.direction = direction;
        out.margin = margin1;
        return out;
    }

    double g0 = event == 4 ? margin
                           : event_value(plant, event, t, &s, &x, mode, direction, held);
    double g1 = event == 4 ? margin1
                           : event_value(plant, event, t + h, &s1, &x1, mode, direction, held);
    QzsOde s_event;
    QzsBlocks x_event;
    double at = locate(plant, solver, event, t, h, &s, &x, g0, g1, mode, direction, held,
                       &s_event, &x_event);
    if (!plant->blocks)
        x_event = x; /* unchanged without blocks */
    double t_event = t + at;
    if (event == 1) {
        s_event = settle(plant, t_event, s_event, &x_event, held, &mode, &direction);
        out.sticks += mode == QZS_MODE_STICK;
    } else if (event == 2 || event == 3) {
        s_event = hit_wall(plant, t_event, s_event, &x_event, event == 2, held, &mode,
                           &direction);
        out.impacts += 1;
    } else {
        double f_hold = hold_at(plant, t_event, &s_event, &x_event, mode, held);
        direction = release_direction(mode, f_hold);
        mode = QZS_MODE_SLIP;
    }
    double rest = h - at;
    s1 = s_event;
    x1 = x_event;
    if (rest > 0.0) {
        QzsOde k0;
        QzsBlocks k0_x;
        rhs_at(plant, t_event, &s_event, &x_event, mode, (double)direction, held, &k0, 0,
               plant->blocks ? &k0_x : 0);
        s1 = rk_exact(plant, solver, t_event, rest, &s_event, &x_event, &k0, &k0_x, mode,
                      (double)direction, held, &x1);
        if (!plant->blocks)
            x1 = x;
    }
    if (mode == QZS_MODE_SLIP && P[QZS_P_PLASTIC] != 0.0) { /* a second event: clamp */
        if (s1.x[QZS_S_Z] < P[QZS_P_Z_LOW] || s1.x[QZS_S_Z] > P[QZS_P_Z_HIGH]) {
            s1 = hit_wall(plant, t + h, s1, &x1, s1.x[QZS_S_Z] < P[QZS_P_Z_LOW], held, &mode,
                          &direction);
            out.impacts += 1;
        }
    }
    margin1 = NAN;
    if (mode != QZS_MODE_SLIP)
        margin1 = margin_near(plant, t + h, &s1, &x1, mode, held, phase);
    out.s = s1;
    out.x = x1;
    out.mode = mode;
    out.direction = direction;
    out.margin = margin1;
    return out;
}

/* kernels.sample_controller with blocks: what the controller reads at t (z, the measured
 * velocity, the slip velocity, the friction and stop forces with the forces held until now),
 * then qzs_sample_blocks_law (qzs_controller.h): the forces held, the integral advanced */
void qzs_sample_blocks(const QzsPlant *plant, double t, QzsOde *s, QzsBlocks *x, int mode,
                       int direction, double held[QZS_N_HELD]) {
    QzsBase b = qzs_base_motion(plant, t);
    double v = mode == QZS_MODE_SLIP ? s->x[QZS_S_V] : 0.0;
    QzsForces force;
    rhs(plant, t, b, s, x, mode, (double)direction, held, 0, &force, 0);
    QzsBlockOutput out = qzs_sample_blocks_law(
        &plant->control, plant->M, plant->P[QZS_P_VREG], t, s->x[QZS_S_Z], force.v_measured, v,
        (double)direction, force.friction + force.stop, force.linear, held[QZS_H_COMPENSATION],
        &s->x[QZS_S_INT], &x->x[QZS_X_OBSERVER]);
    held[QZS_H_PI] = out.pi;
    held[QZS_H_DAMP] = out.damping;
    held[QZS_H_MOTOR] = out.motor;
    held[QZS_H_COMPENSATION] = out.compensation;
    held[QZS_H_DITHER] = out.dither;
}

/* kernels.sample_linear: the sensors read (the payload's acceleration with the force held until
 * now), then qzs_sample_linear_law (qzs_controller.h): the output C x + D u held, the states
 * stepped x <- A x + B u + L (F_motor - command) */
void qzs_sample_linear(const QzsPlant *plant, double t, const QzsOde *s, QzsBlocks *x, int mode,
                       int direction, double held[QZS_N_HELD]) {
    QzsForces force;
    rhs_at(plant, t, s, x, mode, (double)direction, held, 0, &force, 0);
    double v = mode == QZS_MODE_SLIP ? s->x[QZS_S_V] : 0.0;
    double u[QZS_N_SENSORS] = {plant->P[QZS_P_ZREF] - s->x[QZS_S_Z], force.v_measured, force.xdd,
                               force.ydd, v};
    double motor;
    held[QZS_H_LINEAR] = qzs_sample_linear_law(
        &plant->control, plant->M, s->x[QZS_S_Z], u,
        force.pi + force.damp + force.compensation + force.dither, x, &motor);
}

int qzs_finite_blocks(const QzsBlocks *x) {
    int finite = 1;
    for (int i = 0; i < QZS_N_X; i++)
        finite = finite && isfinite(x->x[i]);
    return finite;
}

/* kernels.sample_controller's reading: z and the measured velocity at the exact base motion */
void qzs_measure(const QzsPlant *plant, double t, const QzsOde *s, int mode, double *z,
                 double *v_measured) {
    QzsBase b = qzs_base_motion(plant, t);
    double xd = b.yd + (mode == QZS_MODE_SLIP ? s->x[QZS_S_V] : 0.0);
    *z = s->x[QZS_S_Z];
    *v_measured = plant->P[QZS_P_HP_OMEGA] > 0.0 ? xd - s->x[QZS_S_HP] : xd;
}

int qzs_finite(const QzsPlant *plant, const QzsOde *s) {
    const double *P = plant->P;
    double bound = 100.0 * (P[QZS_P_Z_HIGH] - P[QZS_P_Z_LOW]) + fabs(P[QZS_P_Z_LOW]) +
                   fabs(P[QZS_P_Z_HIGH]);
    return isfinite(s->x[QZS_S_Z]) && isfinite(s->x[QZS_S_V]) && isfinite(s->x[QZS_S_HP]) &&
           isfinite(s->x[QZS_S_INT]) && fabs(s->x[QZS_S_Z]) <= bound &&
           fabs(s->x[QZS_S_V]) <= 1e4;
}

int qzs_failure_status(const QzsPlant *plant) {
    const double *law = plant->spring;
    if (law && law[0] == QZS_SPRING_TABLE && law[QZS_TABLE_OUTSIDE] == 0.0)
        return QZS_STATUS_OUTSIDE;
    return QZS_STATUS_DIVERGED;
}

int qzs_in_contact(const QzsPlant *plant, const QzsOde *s, int mode) {
    return mode >= QZS_MODE_WALL_LOW || s->x[QZS_S_Z] < plant->P[QZS_P_Z_LOW] ||
           s->x[QZS_S_Z] > plant->P[QZS_P_Z_HIGH];
}

void qzs_record(const QzsPlant *plant, double t, const QzsOde *s, const QzsBlocks *x, int mode,
                int direction, const double held[QZS_N_HELD], double *row,
                unsigned char *row_flags, QzsPhase phase) {
    QzsForces f;
    rhs(plant, t, base_motion_near(plant, t, phase), s, x, mode, (double)direction, held, 0, &f,
        0);
    double v = mode == QZS_MODE_SLIP ? s->x[QZS_S_V] : 0.0;
    row[QZS_C_TIME] = t;
    row[QZS_C_BASE_Y] = f.y;
    row[QZS_C_BASE_YD] = f.yd;
    row[QZS_C_BASE_YDD] = f.ydd;
    row[QZS_C_X] = f.y + s->x[QZS_S_Z];
    row[QZS_C_XD] = f.yd + v;
    row[QZS_C_XDD] = f.xdd;
    row[QZS_C_Z] = s->x[QZS_S_Z];
    row[QZS_C_V] = v;
    row[QZS_C_F_SPRING] = f.spring;
    row[QZS_C_F_FRICTION] = f.friction;
    row[QZS_C_F_STOP] = f.stop;
    row[QZS_C_F_MOTOR] = f.motor;
    row[QZS_C_F_PI] = f.pi;
    row[QZS_C_F_DAMP] = f.damp;
    row[QZS_C_V_MEASURED] = f.v_measured;
    row[QZS_C_W_BASE] = s->x[QZS_S_W_BASE];
    row[QZS_C_D_FRICTION] = s->x[QZS_S_D_FRICTION];
    row[QZS_C_W_MOTOR] = s->x[QZS_S_W_MOTOR];
    row[QZS_C_D_STOP] = s->x[QZS_S_D_STOP];
    energies(plant, f.y, f.yd, s, mode, row + QZS_C_E_KINETIC);
    if (plant->M[QZS_M_BLOCKS] != 0.0) { /* a row without blocks holds QZS_N_BASE_CHANNELS */
        row[QZS_C_F_COMPENSATION] = f.compensation;
        row[QZS_C_F_DITHER] = f.dither;
        row[QZS_C_F_LINEAR] = f.linear;
        row[QZS_C_F_OBSERVER] = f.observer;
    }
    row_flags[QZS_O_LOCKED] = mode != QZS_MODE_SLIP;
    row_flags[QZS_O_CONTACT] = (unsigned char)qzs_in_contact(plant, s, mode);
}
