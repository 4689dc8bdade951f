/* qzs: the single-axis isolator plant (see qzs_plant.h). Each function names the kernel it
 * mirrors; the order of the operations is the kernels'. */
#include "qzs_plant.h"

#include <math.h>
#include <string.h>

/* Python's max(a, b) / min(a, b) as numba compiles them: a unless b is larger / smaller. */
#define PYMAX(a, b) ((b) > (a) ? (b) : (a))
#define PYMIN(a, b) ((b) < (a) ? (b) : (a))
#define INLINE static inline __attribute__((always_inline))

static const double TWO_PI = 6.283185307179586; /* 2.0 * np.pi */
static const double PI = 3.141592653589793;
#define LOCATE_ITERATIONS 6

/* ------------------------------------------------------------ arithmetic.py */

INLINE double pow2i(int64_t k) { /* 2**k from the exponent bits */
    uint64_t bits = (uint64_t)(k + 1023) << 52;
    double d;
    memcpy(&d, &bits, sizeof d);
    return d;
}

INLINE double own_exp(double x) {
    x = PYMIN(PYMAX(x, -700.0), 700.0);
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
    return p * pow2i((int64_t)k);
}

INLINE double own_tanh(double u) {
    double a = PYMIN(fabs(u), 20.0);
    double r = 1.0 - 2.0 / (own_exp(2.0 * a) + 1.0);
    return u >= 0.0 ? r : -r;
}

/* ------------------------------------------------------------ laws.py */

INLINE double spring_law(double a, double b, double z) { return -a * own_tanh(b * z); }

INLINE double spring_energy_law(double a, double b, double z) {
    double u = fabs(b * z);
    return a / b * (u + log1p(exp(-2.0 * u)) - log(2.0));
}

INLINE double sliding_friction_law(double v, double sign, double fs, double fc, double cbc,
                                   double cv, double v_reg) {
    double level = fc + (fs - fc) * own_exp(-cbc * fabs(v));
    if (v_reg > 0.0)
        sign = own_tanh(v / v_reg);
    return -level * sign - cv * v;
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

void qzs_plant_init(QzsPlant *plant, const double *params, const double *excitation,
                    const double *table, long table_columns) {
    memcpy(plant->P, params, sizeof plant->P);
    memcpy(plant->E, excitation, sizeof plant->E);
    plant->table = table;
    plant->table_columns = table_columns;
    const double *P = plant->P;
    QzsControllerParameters c = {P[QZS_P_ZREF], P[QZS_P_KP], P[QZS_P_KI], P[QZS_P_KD],
                                 P[QZS_P_FMAX], P[QZS_P_CONTROL_STEPS], P[QZS_P_DT]};
    plant->control = c;
}

/* kernels.rhs: m*xdd = F_spring + F_friction + F_stop + F_motor - m*g; held: v = 0, xdd = ydd */
INLINE void rhs(const QzsPlant *plant, QzsBase b, const QzsOde *s, int mode, double direction,
                const double held[3], QzsOde *deriv, QzsForces *force) {
    const double *P = plant->P;
    double m = P[QZS_P_MASS];
    double z = s->x[QZS_S_Z];
    double v = mode == QZS_MODE_SLIP ? s->x[QZS_S_V] : 0.0;
    double xd = b.yd + v;
    double f_spring = spring_law(P[QZS_P_SPRING_A], P[QZS_P_SPRING_B], z);

    double f_stop = 0.0, f_elastic = 0.0;
    if (P[QZS_P_PLASTIC] == 0.0)
        compliant_stop_law(z, v, P[QZS_P_Z_LOW], P[QZS_P_Z_HIGH], P[QZS_P_STOP_K],
                           P[QZS_P_STOP_C], &f_stop, &f_elastic);

    double v_measured = P[QZS_P_HP_OMEGA] > 0.0 ? xd - s->x[QZS_S_HP] : xd;
    double f_pi, f_damp, f_motor, integral_rate;
    if (P[QZS_P_CONTROL_STEPS] > 0.0) {
        f_pi = held[0];
        f_damp = held[1];
        f_motor = held[2];
        integral_rate = 0.0;
    } else {
        QzsControllerOutput c = qzs_controller_law(&plant->control, z, v_measured,
                                                   s->x[QZS_S_INT]);
        f_pi = c.pi;
        f_damp = c.damping;
        f_motor = c.motor;
        integral_rate = c.integral_rate;
    }

    double f_applied = f_spring + f_stop + f_motor - m * P[QZS_P_GRAVITY];
    double f_hold = m * b.ydd - f_applied;
    double f_friction, xdd;
    if (mode == QZS_MODE_SLIP) {
        f_friction = sliding_friction_law(v, direction, P[QZS_P_FS], P[QZS_P_FC], P[QZS_P_CBC],
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
                       f_pi, f_damp, v_measured, f_hold, xdd};
        *force = f;
    }
}

void qzs_rhs_at(const QzsPlant *plant, double t, const QzsOde *s, int mode, double direction,
                const double held[3], QzsOde *deriv, QzsForces *force) {
    rhs(plant, qzs_base_motion(plant, t), s, mode, direction, held, deriv, force);
}

INLINE double hold_at(const QzsPlant *plant, double t, const QzsOde *s, int mode,
                      const double held[3]) {
    QzsForces f;
    qzs_rhs_at(plant, t, s, mode, 0.0, held, 0, &f);
    return f.hold;
}

INLINE QzsOde axpy(const QzsOde *s, double a, const QzsOde *k) {
    QzsOde out;
    for (int j = 0; j < QZS_N_ODE; j++)
        out.x[j] = fma(a, k->x[j], s->x[j]);
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

/* kernels.rk_step: the base motion at each stage rotated from a nearby phase */
INLINE QzsOde rk_step(const QzsPlant *plant, int solver, double t, double h, const QzsOde *s,
                      int mode, double direction, const double held[3], QzsPhase near) {
    QzsOde result = *s, k = *s, x;
    int stages = n_stages(solver);
    for (int stage = 0; stage < stages; stage++) {
        double offset, a, weight;
        tableau(solver, h, stage, &offset, &a, &weight);
        QzsBase b = base_motion_near(plant, t + offset, near);
        if (stage == 0)
            x = *s;
        else
            x = axpy(s, a, &k);
        rhs(plant, b, &x, mode, direction, held, &k, 0);
        result = axpy(&result, weight, &k);
    }
    return result;
}

/* kernels._rk: the same step for the event path, each stage at the exact base motion */
static QzsOde rk_exact(const QzsPlant *plant, int solver, double t, double h, const QzsOde *s,
                       const QzsOde *k0, int mode, double direction, const double held[3]) {
    double offset, a, weight;
    tableau(solver, h, 0, &offset, &a, &weight);
    QzsOde result = axpy(s, weight, k0);
    QzsOde k = *k0;
    int stages = n_stages(solver);
    for (int stage = 1; stage < stages; stage++) {
        tableau(solver, h, stage, &offset, &a, &weight);
        QzsOde x = axpy(s, a, &k);
        QzsOde next;
        qzs_rhs_at(plant, t + offset, &x, mode, direction, held, &next, 0);
        k = next;
        result = axpy(&result, weight, &k);
    }
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
    e[1] = spring_energy_law(P[QZS_P_SPRING_A], P[QZS_P_SPRING_B], z);
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
static QzsOde settle(const QzsPlant *plant, double t, QzsOde s, const double held[3], int *mode,
                     int *direction) {
    s = book_impulse(plant, t, s, QZS_S_D_FRICTION);
    double f_hold = hold_at(plant, t, &s, QZS_MODE_STICK, held);
    if (fabs(f_hold) <= plant->P[QZS_P_FS]) {
        *mode = QZS_MODE_STICK;
    } else {
        *mode = QZS_MODE_SLIP;
        *direction = release_direction(QZS_MODE_STICK, f_hold);
    }
    return s;
}

/* kernels._hit_wall: perfectly plastic impact on a stop */
static QzsOde hit_wall(const QzsPlant *plant, double t, QzsOde s, int low, const double held[3],
                       int *mode, int *direction) {
    const double *P = plant->P;
    s = book_impulse(plant, t, s, QZS_S_D_STOP);
    double before = mechanical_energy(plant, t, &s, QZS_MODE_SLIP);
    s.x[QZS_S_Z] = low ? P[QZS_P_Z_LOW] : P[QZS_P_Z_HIGH];
    s.x[QZS_S_D_STOP] = s.x[QZS_S_D_STOP] + before - mechanical_energy(plant, t, &s, QZS_MODE_SLIP);
    int wall = low ? QZS_MODE_WALL_LOW : QZS_MODE_WALL_HIGH;
    double f_hold = hold_at(plant, t, &s, wall, held);
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
static double event_value(const QzsPlant *plant, int event, double t, const QzsOde *s, int mode,
                          int direction, const double held[3]) {
    const double *P = plant->P;
    if (event == 1)
        return slip_event((double)direction, s->x[QZS_S_V]);
    if (event == 2)
        return s->x[QZS_S_Z] - P[QZS_P_Z_LOW];
    if (event == 3)
        return P[QZS_P_Z_HIGH] - s->x[QZS_S_Z];
    return hold_margin(mode, hold_at(plant, t, s, mode, held), P[QZS_P_FS]);
}

/* kernels._margin_near */
static double margin_near(const QzsPlant *plant, double t, const QzsOde *s, int mode,
                          const double held[3], QzsPhase near) {
    QzsForces f;
    rhs(plant, base_motion_near(plant, t, near), s, mode, 0.0, held, 0, &f);
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
                     const QzsOde *s, double g0, double g1, int mode, int direction,
                     const double held[3], QzsOde *state) {
    *state = *s;
    if (!(g0 > 0.0))
        return 0.0;
    QzsOde k0;
    qzs_rhs_at(plant, t, s, mode, (double)direction, held, &k0, 0);
    double lo = 0.0, hi = h, g_lo = g0, g_hi = g1;
    double at = h * g0 / (g0 - g1);
    int side = 0;
    for (int i = 0; i < LOCATE_ITERATIONS; i++) {
        *state = rk_exact(plant, solver, t, at, s, &k0, mode, (double)direction, held);
        double g = event_value(plant, event, t + at, state, mode, direction, held);
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

QzsStep qzs_grid_step(const QzsPlant *plant, int solver, double t, double h, QzsOde s, int mode,
                      int direction, const double held[3], double margin, QzsPhase phase) {
    const double *P = plant->P;
    QzsStep out;
    out.sticks = 0;
    out.impacts = 0;
    /* a zero crossing missed earlier */
    if (mode == QZS_MODE_SLIP && P[QZS_P_VREG] == 0.0 &&
        slip_event((double)direction, s.x[QZS_S_V]) < 0.0) {
        s = settle(plant, t, s, held, &mode, &direction);
        out.sticks += mode == QZS_MODE_STICK;
        margin = NAN;
    }
    if (mode != QZS_MODE_SLIP) {
        if (margin != margin)
            margin = margin_near(plant, t, &s, mode, held, phase);
        if (margin < 0.0) {
            double f_hold = hold_at(plant, t, &s, mode, held);
            direction = release_direction(mode, f_hold);
            mode = QZS_MODE_SLIP;
        }
    }

    QzsOde s1 = rk_step(plant, solver, t, h, &s, mode, (double)direction, held, phase);
    double margin1 = NAN;
    if (mode != QZS_MODE_SLIP)
        margin1 = margin_near(plant, t + h, &s1, mode, held, phase);
    double theta;
    int event = first_event(plant, &s, &s1, mode, direction, margin, margin1, &theta);
    if (event == 0) {
        out.s = s1;
        out.mode = mode;
        out.direction = direction;
        out.margin = margin1;
        return out;
    }

    double g0 = event == 4 ? margin : event_value(plant, event, t, &s, mode, direction, held);
    double g1 = event == 4 ? margin1
                           : event_value(plant, event, t + h, &s1, mode, direction, held);
    QzsOde s_event;
    double at = locate(plant, solver, event, t, h, &s, g0, g1, mode, direction, held, &s_event);
    double t_event = t + at;
    if (event == 1) {
        s_event = settle(plant, t_event, s_event, held, &mode, &direction);
        out.sticks += mode == QZS_MODE_STICK;
    } else if (event == 2 || event == 3) {
        s_event = hit_wall(plant, t_event, s_event, event == 2, held, &mode, &direction);
        out.impacts += 1;
    } else {
        double f_hold = hold_at(plant, t_event, &s_event, mode, held);
        direction = release_direction(mode, f_hold);
        mode = QZS_MODE_SLIP;
    }
    double rest = h - at;
    s1 = s_event;
    if (rest > 0.0) {
        QzsOde k0;
        qzs_rhs_at(plant, t_event, &s_event, mode, (double)direction, held, &k0, 0);
        s1 = rk_exact(plant, solver, t_event, rest, &s_event, &k0, mode, (double)direction, held);
    }
    if (mode == QZS_MODE_SLIP && P[QZS_P_PLASTIC] != 0.0) { /* a second event: clamp */
        if (s1.x[QZS_S_Z] < P[QZS_P_Z_LOW] || s1.x[QZS_S_Z] > P[QZS_P_Z_HIGH]) {
            s1 = hit_wall(plant, t + h, s1, s1.x[QZS_S_Z] < P[QZS_P_Z_LOW], held, &mode,
                          &direction);
            out.impacts += 1;
        }
    }
    margin1 = NAN;
    if (mode != QZS_MODE_SLIP)
        margin1 = margin_near(plant, t + h, &s1, mode, held, phase);
    out.s = s1;
    out.mode = mode;
    out.direction = direction;
    out.margin = margin1;
    return out;
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

int qzs_in_contact(const QzsPlant *plant, const QzsOde *s, int mode) {
    return mode >= QZS_MODE_WALL_LOW || s->x[QZS_S_Z] < plant->P[QZS_P_Z_LOW] ||
           s->x[QZS_S_Z] > plant->P[QZS_P_Z_HIGH];
}

void qzs_record(const QzsPlant *plant, double t, const QzsOde *s, int mode, int direction,
                const double held[3], double *row, unsigned char *row_flags, QzsPhase phase) {
    QzsForces f;
    rhs(plant, base_motion_near(plant, t, phase), s, mode, (double)direction, held, 0, &f);
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
    row_flags[QZS_O_LOCKED] = mode != QZS_MODE_SLIP;
    row_flags[QZS_O_CONTACT] = (unsigned char)qzs_in_contact(plant, s, mode);
}
