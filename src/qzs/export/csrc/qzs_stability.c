/* qzs: the linear stability of the explicit integrators (see qzs_stability.h). */
#include "qzs_stability.h"

#include <math.h>

#include "qzs_plant.h"

typedef struct { double re, im; } Complex;

/* The roots of m s^2 + c s + k (m > 0, c >= 0) into out; returns 2. */
static int quadratic_roots(double m, double c, double k, Complex *out) {
    double discriminant = c * c - 4.0 * m * k;
    if (discriminant < 0.0) {
        double re = -c / (2.0 * m), im = sqrt(-discriminant) / (2.0 * m);
        out[0].re = re; out[0].im = im;
        out[1].re = re; out[1].im = -im;
    } else {
        double q = -0.5 * (c + sqrt(discriminant)); /* no cancellation: c >= 0 */
        out[0].re = q / m; out[0].im = 0.0;
        out[1].re = q != 0.0 ? k / q : 0.0; out[1].im = 0.0;
    }
    return 2;
}

/* The eigenvalues [1/s] of qzs.engine.stability._stiff_modes; returns how many. */
static int stiff_modes(const double *P, int closed_loop, Complex *out) {
    double m = P[QZS_P_MASS];
    double stiffness = P[QZS_P_SPRING_A] * P[QZS_P_SPRING_B] + (closed_loop ? P[QZS_P_KP] : 0.0);
    double damping = P[QZS_P_CV] + (closed_loop ? P[QZS_P_KD] : 0.0);
    int n = 0;
    if (P[QZS_P_VREG] > 0.0)
        damping += P[QZS_P_FS] / P[QZS_P_VREG];
    out[n].re = -P[QZS_P_HP_OMEGA];
    out[n].im = 0.0;
    n += 1;
    n += quadratic_roots(m, damping, stiffness, out + n);
    if (P[QZS_P_PLASTIC] == 0.0)
        n += quadratic_roots(m, damping + P[QZS_P_STOP_C], stiffness + P[QZS_P_STOP_K], out + n);
    return n;
}

/* The solvers' stability polynomials R(z), Taylor coefficients from the constant term. */
static const double EULER[] = {1.0, 1.0};
static const double ODE3[] = {1.0, 1.0, 1.0 / 2.0, 1.0 / 6.0};
static const double RK4[] = {1.0, 1.0, 1.0 / 2.0, 1.0 / 6.0, 1.0 / 24.0};

int qzs_stable_step(const double *P, int solver, int closed_loop, double h) {
    const double *coefficients = solver == QZS_SOLVER_EULER ? EULER
                                 : (solver == QZS_SOLVER_RK4 ? RK4 : ODE3);
    int order = solver == QZS_SOLVER_EULER ? 1 : (solver == QZS_SOLVER_RK4 ? 4 : 3);
    Complex modes[5];
    int n = stiff_modes(P, closed_loop, modes);
    if (!(h > 0.0))
        return 0;
    for (int i = 0; i < n; i++) {
        double zr = h * modes[i].re, zi = h * modes[i].im;
        double rr = 0.0, ri = 0.0; /* Horner from the highest power, as numpy.polyval */
        for (int j = order; j >= 0; j--) {
            double tr = rr * zr - ri * zi, ti = rr * zi + ri * zr;
            rr = tr + coefficients[j];
            ri = ti;
        }
        if (!(log(hypot(rr, ri)) <= 1e-3 * h))
            return 0;
    }
    return 1;
}

double qzs_largest_stable_step(const double *P, int solver, int closed_loop) {
    double low = 0.0, high = 1.0;
    while (qzs_stable_step(P, solver, closed_loop, high) && high < 1e3) {
        low = high;
        high *= 2.0;
    }
    if (qzs_stable_step(P, solver, closed_loop, high))
        return high;
    for (int i = 0; i < 200; i++) { /* bisection on a log scale to relative precision ~1e-6 */
        double mid = low > 0.0 ? sqrt(low * high) : high / 2.0;
        if (qzs_stable_step(P, solver, closed_loop, mid))
            low = mid;
        else
            high = mid;
        if (low > 0.0 && high / low < 1.0 + 1e-6)
            break;
    }
    return low;
}
