/* qzs: the spring laws in C (see qzs_spring.h). Each function names the Python it mirrors;
 * the order of the operations is its. */
#include "qzs_spring.h"

#include <math.h>

#include "qzs_controller.h" /* qzs_tanh: arithmetic.tanh, as the kernels' */

/* springs.EQUILIBRIUM_SAMPLES: the positions of the stiffness peak's search */
#define PEAK_SAMPLES 4097

/* ------------------------------------------------------------ springs.evaluate_packed */

/* the piece of the table that holds z (binary search, laws._table_piece) */
static long table_piece(const double *law, long n, double z) {
    const double *x = law + QZS_TABLE_POSITIONS;
    long low = 0, high = n - 1;
    while (high - low > 1) {
        long middle = (low + high) / 2;
        if (z >= x[middle])
            low = middle;
        else
            high = middle;
    }
    return low;
}

/* springs._evaluate_packed_table: outside (refused, or linear with the end slope), or the
 * piece's cubic by Horner's rule */
static int evaluate_table(const double *law, double z, int want, QzsSpringValues *out) {
    long n = (long)law[QZS_TABLE_COUNT];
    double x0 = law[QZS_TABLE_POSITIONS], xn = law[QZS_TABLE_POSITIONS + n - 1];
    const double *pieces = law + QZS_TABLE_POSITIONS + n;
    const double *energies = pieces + 4 * (n - 1);
    if (z < x0 || z > xn) {
        if (law[QZS_TABLE_OUTSIDE] == 0.0) {
            out->force = out->stiffness = out->energy = NAN;
            return QZS_SPRING_OUTSIDE;
        }
        double t, force, slope, energy;
        if (z < x0) {
            t = z - x0;
            force = pieces[0];
            slope = pieces[1];
            energy = energies[0];
        } else {
            t = z - xn;
            force = law[QZS_TABLE_END_FORCE];
            slope = law[QZS_TABLE_END_SLOPE];
            energy = energies[n - 1];
        }
        if (want & QZS_SPRING_FORCE)
            out->force = force + t * slope;
        if (want & QZS_SPRING_STIFFNESS)
            out->stiffness = -slope;
        if (want & QZS_SPRING_ENERGY)
            out->energy = energy - t * (force + t * (slope / 2.0));
        return QZS_SPRING_OK;
    }
    long i = table_piece(law, n, z);
    double t = z - law[QZS_TABLE_POSITIONS + i];
    const double *c = pieces + 4 * i;
    if (want & QZS_SPRING_FORCE)
        out->force = c[0] + t * (c[1] + t * (c[2] + t * c[3]));
    if (want & QZS_SPRING_STIFFNESS)
        out->stiffness = -(c[1] + t * (2.0 * c[2] + t * (3.0 * c[3])));
    if (want & QZS_SPRING_ENERGY)
        out->energy = energies[i] - t * (c[0] + t * (c[1] / 2.0 + t * (c[2] / 3.0 +
                                                                        t * (c[3] / 4.0))));
    return QZS_SPRING_OK;
}

int qzs_spring_evaluate(const double *law, double z, int want, QzsSpringValues *out) {
    int code = (int)law[0];
    if (code == QZS_SPRING_OBLIQUE) { /* k_v, k_o, L0, d, center, preload */
        double u = z - law[5];
        double d = law[4];
        double length = hypot(u, d);
        if (want & QZS_SPRING_FORCE)
            out->force = law[6] - law[1] * u - 2.0 * law[2] * (1.0 - law[3] / length) * u;
        if (want & QZS_SPRING_STIFFNESS)
            out->stiffness = law[1] + 2.0 * law[2] * (1.0 - law[3] * d * d / pow(length, 3.0));
        if (want & QZS_SPRING_ENERGY) {
            double spread = 2.0 * law[3] / (length + d);
            out->energy = u * (-law[6] + u * (0.5 * law[1] + law[2] * (1.0 - spread)));
        }
        return QZS_SPRING_OK;
    }
    if (code == QZS_SPRING_POLYNOMIAL) { /* center, n, c_0 .. c_(n-1) */
        double u = z - law[1];
        long n = (long)law[2];
        double force = 0.0, slope = 0.0, work = 0.0;
        for (long k = n - 1; k >= 0; k--) {
            double c = law[3 + k];
            force = force * u + c;
            work = work * u + c / (double)(k + 1);
            if (k > 0)
                slope = slope * u + (double)k * c;
        }
        if (want & QZS_SPRING_FORCE)
            out->force = force;
        if (want & QZS_SPRING_STIFFNESS)
            out->stiffness = -slope;
        if (want & QZS_SPRING_ENERGY)
            out->energy = -work * u;
        return QZS_SPRING_OK;
    }
    if (code == QZS_SPRING_TABLE)
        return evaluate_table(law, z, want, out);
    /* the tanh [0, a, b] (qzs_plant.c evaluates the default one from the parameters) */
    double a = law[1], b = law[2];
    if (want & QZS_SPRING_FORCE)
        out->force = -a * qzs_tanh(b * z);
    if (want & QZS_SPRING_STIFFNESS)
        out->stiffness = a * b / pow(cosh(b * z), 2.0);
    if (want & QZS_SPRING_ENERGY) {
        double u = fabs(b * z);
        out->energy = a / b * (u + log1p(exp(-2.0 * u)) - log(2.0));
    }
    return QZS_SPRING_OK;
}

long qzs_spring_size(const double *law) {
    int code = (int)law[0];
    if (code == QZS_SPRING_OBLIQUE)
        return 7;
    if (code == QZS_SPRING_POLYNOMIAL)
        return 3 + (long)law[2];
    if (code == QZS_SPRING_TABLE)
        return qzs_spring_table_size((long)law[QZS_TABLE_COUNT]);
    return 3;
}

/* ------------------------------------------------------------ spring_table.py */

long qzs_spring_table_size(long n) { return QZS_TABLE_POSITIONS + n + 4 * (n - 1) + n; }

/* np.sign */
static double sign(double x) { return x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0); }

/* spring_table._end_slope: the one-sided three-point slope, made shape-preserving */
static double end_slope(double h0, double h1, double m0, double m1) {
    double slope = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1);
    if (sign(slope) != sign(m0))
        return 0.0;
    if (sign(m0) != sign(m1) && fabs(slope) > 3.0 * fabs(m0))
        return 3.0 * m0;
    return slope;
}

/* the secant and the step of the interval i */
static double step_of(const double *x, long i) { return x[i + 1] - x[i]; }
static double secant_of(const double *x, const double *y, long i) {
    return (y[i + 1] - y[i]) / step_of(x, i);
}

void qzs_spring_table(double *law, long n, const double *x, const double *y, int outside) {
    double *positions = law + QZS_TABLE_POSITIONS;
    double *pieces = positions + n;
    double *energies = pieces + 4 * (n - 1);
    /* spring_table.pchip_slopes, kept in the energies' place until the pieces are made */
    double *slopes = energies;
    for (long k = 1; k < n - 1; k++) {
        double h0 = step_of(x, k - 1), h1 = step_of(x, k);
        double left = secant_of(x, y, k - 1), right = secant_of(x, y, k);
        double w1 = 2.0 * h1 + h0;
        double w2 = h1 + 2.0 * h0;
        int flat = sign(left) != sign(right) || left == 0.0 || right == 0.0;
        slopes[k] = flat ? 0.0 : (w1 + w2) / (w1 / left + w2 / right);
    }
    slopes[0] = end_slope(step_of(x, 0), step_of(x, 1), secant_of(x, y, 0), secant_of(x, y, 1));
    slopes[n - 1] = end_slope(step_of(x, n - 2), step_of(x, n - 3), secant_of(x, y, n - 2),
                              secant_of(x, y, n - 3));
    law[0] = QZS_SPRING_TABLE;
    law[QZS_TABLE_OUTSIDE] = outside ? 1.0 : 0.0;
    law[QZS_TABLE_COUNT] = (double)n;
    law[QZS_TABLE_END_FORCE] = y[n - 1];
    law[QZS_TABLE_END_SLOPE] = slopes[n - 1];
    for (long i = 0; i < n; i++)
        positions[i] = x[i];
    /* spring_table.hermite_pieces */
    for (long i = 0; i < n - 1; i++) {
        double h = step_of(x, i), secant = secant_of(x, y, i);
        double excess = (slopes[i] + slopes[i + 1] - 2.0 * secant) / h;
        double *c = pieces + 4 * i;
        c[0] = y[i];
        c[1] = slopes[i];
        c[2] = (secant - slopes[i]) / h - excess;
        c[3] = excess / h;
    }
    /* spring_table.piece_energies: 0, then minus the running sum of the pieces' integrals */
    double total = 0.0;
    energies[0] = 0.0;
    for (long i = 0; i < n - 1; i++) {
        double h = step_of(x, i);
        const double *c = pieces + 4 * i;
        total += h * (c[0] + h * (c[1] / 2.0 + h * (c[2] / 3.0 + h * (c[3] / 4.0))));
        energies[i + 1] = -total;
    }
}

/* ------------------------------------------------------------ stability.spring_stiffness_peak */

double qzs_spring_stiffness_peak(const double *law, double low, double high) {
    if ((int)law[0] == QZS_SPRING_TABLE && law[QZS_TABLE_OUTSIDE] == 0.0) {
        long n = (long)law[QZS_TABLE_COUNT];
        low = fmax(low, law[QZS_TABLE_POSITIONS]);
        high = fmin(high, law[QZS_TABLE_POSITIONS + n - 1]);
    }
    QzsSpringValues values;
    double peak = -INFINITY;
    double step = (high - low) / (PEAK_SAMPLES - 1); /* np.linspace */
    for (long i = 0; i < PEAK_SAMPLES; i++) {
        double z = i == PEAK_SAMPLES - 1 ? high : (double)i * step + low;
        qzs_spring_evaluate(law, z, QZS_SPRING_STIFFNESS, &values);
        peak = fmax(peak, values.stiffness);
    }
    if ((int)law[0] == QZS_SPRING_TABLE) {
        long n = (long)law[QZS_TABLE_COUNT];
        for (long i = 0; i < n; i++) {
            double z = law[QZS_TABLE_POSITIONS + i];
            if (z >= low && z <= high) {
                qzs_spring_evaluate(law, z, QZS_SPRING_STIFFNESS, &values);
                peak = fmax(peak, values.stiffness);
            }
        }
    }
    return peak;
}
