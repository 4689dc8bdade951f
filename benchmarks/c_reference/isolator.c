/* C reference model of the qzs isolator: one case, a plain scalar loop.
 *
 * The baseline of the speed targets of issue 11 (benchmarks/run_all.py). It integrates the
 * single-axis model of docs/model.md (§2-§9) with the same fixed-step scheme as qzs' ode3
 * (Bogacki-Shampine 3rd order without its error stage: stages at t, t + h/2, t + 3h/4,
 * weights 2/9, 1/3, 4/9) and does the same work per ordinary (slipping) step as
 * qzs.engine.kernels.grid_step inside qzs.engine.lanes.run_single:
 *
 *   - 8 states: z, v, the high-pass state, the PI integral and the 4-entry energy ledger;
 *   - per stage: the base motion (chirp or sine, phase rotated from a nearby sine/cosine by
 *     the same Taylor series, libm sin/cos every 256 steps), the MagSpring -a*tanh(b*z)
 *     (qzs' own tanh: one own exp), Stribeck + Coulomb + viscous friction (one own exp),
 *     compliant stops, PI + active damping on the high-passed velocity with anti-windup
 *     and motor saturation, gravity, and the ledger rates;
 *   - explicit fused multiply-adds where qzs has them (fma()), none elsewhere: build with
 *     -ffp-contract=off and no fast-math, as numba compiles qzs;
 *   - after each step: the divergence test, the stop-contact flag and counter;
 *   - every `decimation` steps (and at t = 0): one output row of the same 24 channels as
 *     qzs (qzs.engine.kernels.C_*), plus the two flags (locked, stop contact).
 *
 * What it does NOT do: qzs' stick-slip events. The slip direction is sign(v) at the start
 * of each step (continued through the step, as qzs does between events); a zero crossing
 * of v is not located, the payload never locks, so on a sticking case it chatters around
 * v = 0 where qzs sticks. Plastic stops and tabulated excitations are not modelled, nor a
 * sampled controller (controller_rate > 0). On a case without events (no friction force
 * at v = 0, no stop contact) it computes the same operations in the same order as qzs.
 *
 * Parameters, state and excitation come packed exactly as qzs packs them
 * (qzs.engine.prepare.prepare_run: P_* and S_* of qzs.engine.kernels, E_* of
 * qzs.model.excitation), so the wrapper (reference.py) takes them from qzs.
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

/* packed parameters (qzs.engine.kernels.P_*) */
enum { P_MASS, P_GRAVITY, P_SPRING_A, P_SPRING_B, P_FS, P_FC, P_CBC, P_CV, P_Z_LOW, P_Z_HIGH,
       P_STOP_K, P_STOP_C, P_PLASTIC, P_FMAX, P_ZREF, P_KP, P_KI, P_KD, P_HP_OMEGA,
       P_CONTROL_STEPS, P_DT, N_PARAMS };
/* state (qzs.engine.kernels.S_*) */
enum { S_Z, S_V, S_HP, S_INT, S_W_BASE, S_D_FRICTION, S_W_MOTOR, S_D_STOP, N_ODE };
/* excitation scalars (qzs.model.excitation.E_*) and kinds */
enum { E_KIND, E_AMPLITUDE, E_F0, E_F1, E_DURATION, E_PHASE, E_SPACING, E_FADE };
enum { KIND_CHIRP_LINEAR = 0, KIND_CHIRP_LOG = 1, KIND_SINE = 2, KIND_TABLE = 3 };
#define N_CHANNELS 24
/* Python's max(a, b) / min(a, b), as numba compiles them (a unless b is larger / smaller):
 * inline compares, where fmax/fmin would be library calls without -ffinite-math-only. */
#define PYMAX(a, b) ((b) > (a) ? (b) : (a))
#define PYMIN(a, b) ((b) < (a) ? (b) : (a))

#define REF_OK 0
#define REF_DIVERGED 1
#define REF_UNSUPPORTED 2
#define REF_BUFFER_TOO_SMALL 3

static const double TWO_PI = 6.283185307179586;  /* 2*np.pi */

typedef struct { double y, yd, ydd; } Base;

/* numba inlines every law, the right-hand side and the Runge-Kutta step into the driver
 * (inline="always"); gcc's heuristics would leave rhs() a call, so force it as well. */
#define INLINE static inline __attribute__((always_inline))

/* ------------------------------------------------------------ arithmetic (docs §9) */

INLINE double pow2i(int64_t k) {  /* 2**k from the exponent bits */
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

/* ------------------------------------------------------------ base motion (docs §6) */

INLINE void phase_of(double t, const double *E, double *phase, double *omega,
                            double *omega_dot) {
    if ((int)E[E_KIND] == KIND_CHIRP_LINEAR) {
        double f0 = E[E_F0];
        double rate = (E[E_F1] - f0) / E[E_DURATION];
        *phase = TWO_PI * (f0 * t + 0.5 * rate * t * t);
        *omega = TWO_PI * (f0 + rate * t);
        *omega_dot = TWO_PI * rate;
    } else {  /* KIND_SINE (the wrapper refuses the other kinds) */
        double w = TWO_PI * E[E_F0];
        *phase = w * t + E[E_PHASE];
        *omega = w;
        *omega_dot = 0.0;
    }
}

INLINE void rotate(double phase, double phase0, double sin0, double cos0, double *s,
                          double *c) {
    double d = phase - phase0;
    if (fabs(d) < 0.1) {
        double d2 = d * d;
        double sd = d * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0 * (1.0 - d2 / 42.0 * (1.0 - d2 / 72.0))));
        double cd = 1.0 - d2 / 2.0 * (1.0 - d2 / 12.0 * (1.0 - d2 / 30.0 * (1.0 - d2 / 56.0)));
        *s = sin0 * cd + cos0 * sd;
        *c = cos0 * cd - sin0 * sd;
    } else {
        *s = sin(phase);
        *c = cos(phase);
    }
}

INLINE Base fade(double t, double fade_time, Base b) {
    if (t >= fade_time || fade_time <= 0.0)
        return b;
    if (t <= 0.0)
        t = 0.0;
    double k = 2.0 * 3.141592653589793 / fade_time;
    double s = sin(k * t), c = cos(k * t);
    double w = t / fade_time - s / (2.0 * 3.141592653589793);
    double w1 = (1.0 - c) / fade_time;
    double w2 = k * s / fade_time;
    Base out = {w * b.y, w1 * b.y + w * b.yd, w2 * b.y + 2.0 * w1 * b.yd + w * b.ydd};
    return out;
}

INLINE Base base_near(double t, double phase0, double sin0, double cos0,
                             const double *E) {
    double phase, omega, omega_dot, s, c;
    phase_of(t, E, &phase, &omega, &omega_dot);
    rotate(phase, phase0, sin0, cos0, &s, &c);
    double A = E[E_AMPLITUDE];
    Base b = {A * s, A * c * omega, A * (c * omega_dot - s * omega * omega)};
    return fade(t, E[E_FADE], b);
}

INLINE void advance_phase(double t, double *phase, double *sin0, double *cos0,
                                 const double *E, int exact) {
    double p, omega, omega_dot;
    phase_of(t, E, &p, &omega, &omega_dot);
    if (exact) {
        *sin0 = sin(p);
        *cos0 = cos(p);
    } else {
        double s, c;
        rotate(p, *phase, *sin0, *cos0, &s, &c);
        *sin0 = s;
        *cos0 = c;
    }
    *phase = p;
}

/* ------------------------------------------------------------ right-hand side (docs §2-§5, §8) */

typedef struct {
    double spring, friction, stop, elastic, motor, pi, damp, v_measured, xdd;
} Forces;

/* Derivatives of the 8 states while slipping in `direction`; the forces if `f` is given. */
INLINE void rhs(const Base *b, const double *s, double direction, const double *P,
                       double *k, Forces *f) {
    double m = P[P_MASS];
    double z = s[S_Z];
    double v = s[S_V];
    double xd = b->yd + v;
    double f_spring = -P[P_SPRING_A] * own_tanh(P[P_SPRING_B] * z);

    /* compliant stops: a spring-damper beyond either stop that pushes, never pulls */
    double f_stop = 0.0, f_elastic = 0.0;
    if (z < P[P_Z_LOW]) {
        f_elastic = P[P_STOP_K] * (P[P_Z_LOW] - z);
        f_stop = PYMAX(f_elastic - P[P_STOP_C] * v, 0.0);
    } else if (z > P[P_Z_HIGH]) {
        f_elastic = -P[P_STOP_K] * (z - P[P_Z_HIGH]);
        f_stop = PYMIN(f_elastic - P[P_STOP_C] * v, 0.0);
    }

    /* PI + damping on the high-passed velocity, saturated, anti-windup */
    double v_measured = P[P_HP_OMEGA] > 0.0 ? xd - s[S_HP] : xd;
    double error = P[P_ZREF] - z;
    double f_pi = P[P_KP] * error + P[P_KI] * s[S_INT];
    double f_damp = -P[P_KD] * v_measured;
    double f_motor = f_pi + f_damp;
    double integral_rate = error;
    double f_max = P[P_FMAX];
    if (f_motor > f_max) {
        f_motor = f_max;
        if (error * P[P_KI] > 0.0)
            integral_rate = 0.0;
    } else if (f_motor < -f_max) {
        f_motor = -f_max;
        if (error * P[P_KI] < 0.0)
            integral_rate = 0.0;
    }

    double f_applied = f_spring + f_stop + f_motor - m * P[P_GRAVITY];
    /* Stribeck + Coulomb + viscous friction, opposing the slip */
    double level = P[P_FC] + (P[P_FS] - P[P_FC]) * own_exp(-P[P_CBC] * fabs(v));
    double f_friction = -level * direction - P[P_CV] * v;
    double xdd = (f_applied + f_friction) * (1.0 / m);

    k[0] = v;
    k[1] = xdd - b->ydd;
    k[2] = P[P_HP_OMEGA] * (xd - s[S_HP]);
    k[3] = integral_rate;
    k[4] = (f_spring + f_friction + f_stop + f_motor) * b->yd;
    k[5] = -f_friction * v;
    k[6] = f_motor * v;
    k[7] = -(f_stop - f_elastic) * v;
    if (f) {
        f->spring = f_spring; f->friction = f_friction; f->stop = f_stop;
        f->elastic = f_elastic; f->motor = f_motor; f->pi = f_pi; f->damp = f_damp;
        f->v_measured = v_measured; f->xdd = xdd;
    }
}

/* ------------------------------------------------------------ output (docs §7, §8) */

static void record(double t, const double *s, double direction, const double *P,
                   const double *E, double phase, double sin0, double cos0, double *row,
                   unsigned char *row_flags) {
    Base b = base_near(t, phase, sin0, cos0, E);
    double k[N_ODE];
    Forces f;
    rhs(&b, s, direction, P, k, &f);
    double m = P[P_MASS], z = s[S_Z], v = s[S_V];
    row[0] = t;
    row[1] = b.y;
    row[2] = b.yd;
    row[3] = b.ydd;
    row[4] = b.y + z;
    row[5] = b.yd + v;
    row[6] = f.xdd;
    row[7] = z;
    row[8] = v;
    row[9] = f.spring;
    row[10] = f.friction;
    row[11] = f.stop;
    row[12] = f.motor;
    row[13] = f.pi;
    row[14] = f.damp;
    row[15] = f.v_measured;
    row[16] = s[S_W_BASE];
    row[17] = s[S_D_FRICTION];
    row[18] = s[S_W_MOTOR];
    row[19] = s[S_D_STOP];
    double pen = PYMAX(P[P_Z_LOW] - z, 0.0) + PYMAX(z - P[P_Z_HIGH], 0.0);
    double xd = b.yd + v;
    double u = fabs(P[P_SPRING_B] * z);
    row[20] = 0.5 * m * (xd * xd);
    row[21] = P[P_SPRING_A] / P[P_SPRING_B] * (u + log1p(exp(-2.0 * u)) - log(2.0));
    row[22] = m * P[P_GRAVITY] * (b.y + z);
    row[23] = 0.5 * P[P_STOP_K] * pen * pen;
    row_flags[0] = 0;  /* never locked: no stick-slip events here */
    row_flags[1] = z < P[P_Z_LOW] || z > P[P_Z_HIGH];
}

/* ------------------------------------------------------------ the driver */

/* Advance `n_steps` ode3 steps of dt = P[P_DT] from step `step0`, state `state` (8 entries,
 * updated in place), slip direction `*direction` (+-1, updated). Records a row at the start
 * if `record_first`, then every `decimation`-th step, into `out` (rows of 24 doubles) and
 * `out_flags` (rows of 2 bytes), at most `max_rows`. counters[0] += stop contacts,
 * counters[1] = rows written, counters[2] = steps taken. Returns REF_OK, REF_DIVERGED (the
 * state is then the last finite one), REF_UNSUPPORTED or REF_BUFFER_TOO_SMALL. */
int qzs_ref_run(const double *params, const double *excitation, double *state,
                long *direction, long step0, long n_steps, long decimation, int record_first,
                double *out, unsigned char *out_flags, long max_rows, long *counters) {
    double P[N_PARAMS], E[8];
    memcpy(P, params, sizeof P);
    memcpy(E, excitation, sizeof E);
    int kind = (int)E[E_KIND];
    if ((kind != KIND_CHIRP_LINEAR && kind != KIND_SINE) || P[P_PLASTIC] != 0.0 ||
        P[P_CONTROL_STEPS] > 0.0 || decimation < 1)
        return REF_UNSUPPORTED;
    long rows_needed = n_steps / decimation + (record_first ? 1 : 0);
    if (rows_needed > max_rows)
        return REF_BUFFER_TOO_SMALL;

    const double h = P[P_DT];
    const double w0 = h * (2.0 / 9.0), w1 = h * (1.0 / 3.0), w2 = h * (4.0 / 9.0);
    const double a1 = 0.5 * h, a2 = 0.75 * h;
    const double bound = 100.0 * (P[P_Z_HIGH] - P[P_Z_LOW]) + fabs(P[P_Z_LOW]) + fabs(P[P_Z_HIGH]);
    double s[N_ODE];
    memcpy(s, state, sizeof s);
    double dir = (double)*direction;
    long step = step0, row = 0;
    int contact = s[S_Z] < P[P_Z_LOW] || s[S_Z] > P[P_Z_HIGH];
    int status = REF_OK;
    double phase = 0.0, sin0 = 0.0, cos0 = 1.0;
    advance_phase(step * h, &phase, &sin0, &cos0, E, 1);
    if (record_first) {
        record(step * h, s, dir, P, E, phase, sin0, cos0, out, out_flags);
        row = 1;
    }

    for (long i = 0; i < n_steps; i++) {
        double t = step * h;
        /* the simple event handling: the slip direction is the sign of v at the step's start */
        if (dir * s[S_V] < 0.0)
            dir = -dir;
        Base b0 = base_near(t, phase, sin0, cos0, E);
        Base b1 = base_near(t + 0.5 * h, phase, sin0, cos0, E);
        Base b2 = base_near(t + 0.75 * h, phase, sin0, cos0, E);
        double k[N_ODE], x[N_ODE], s1[N_ODE];
        rhs(&b0, s, dir, P, k, 0);
        for (int j = 0; j < N_ODE; j++) {
            s1[j] = fma(w0, k[j], s[j]);
            x[j] = fma(a1, k[j], s[j]);
        }
        rhs(&b1, x, dir, P, k, 0);
        for (int j = 0; j < N_ODE; j++) {
            s1[j] = fma(w1, k[j], s1[j]);
            x[j] = fma(a2, k[j], s[j]);
        }
        rhs(&b2, x, dir, P, k, 0);
        for (int j = 0; j < N_ODE; j++)
            s1[j] = fma(w2, k[j], s1[j]);

        if (!(isfinite(s1[S_Z]) && isfinite(s1[S_V]) && isfinite(s1[S_HP]) &&
              isfinite(s1[S_INT]) && fabs(s1[S_Z]) <= bound && fabs(s1[S_V]) <= 1e4)) {
            status = REF_DIVERGED;
            break;
        }
        memcpy(s, s1, sizeof s);
        step++;
        advance_phase(step * h, &phase, &sin0, &cos0, E, step % 256 == 0);
        int now = s[S_Z] < P[P_Z_LOW] || s[S_Z] > P[P_Z_HIGH];
        counters[0] += now && !contact;
        contact = now;
        if (step % decimation == 0) {
            record(step * h, s, dir, P, E, phase, sin0, cos0, out + row * N_CHANNELS,
                   out_flags + 2 * row);
            row++;
        }
    }
    memcpy(state, s, sizeof s);
    *direction = dir > 0.0 ? 1 : -1;
    counters[1] = row;
    counters[2] = step - step0;
    return status;
}
