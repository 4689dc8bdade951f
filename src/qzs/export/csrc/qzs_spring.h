/* qzs: the spring laws in C, on the packed law qzs packs (docs/model.md §3, §3.1).
 *
 * A law is one array of doubles, qzs.model.springs.SpringLaw.pack()'s: its code, then its
 * numbers (the layouts in qzs/model/springs.py's docstring); qzs_spring_evaluate() is
 * qzs.model.springs.evaluate_packed and the kernels' qzs.engine.laws.spring_general /
 * spring_energy_general operation for operation (a table: binary search, then Horner; its
 * energies exact). qzs_spring_table() packs a table from its points as
 * qzs.model.spring_table does (PCHIP slopes, Hermite pieces, piece energies), so that an FMU
 * whose table is a parameter computes the same pieces from changed points. The tanh of the
 * default model is qzs_plant.c's, from the packed parameters: a law here is another one.
 */
#ifndef QZS_SPRING_H
#define QZS_SPRING_H

/* codes of the laws (qzs.model.springs TANH, OBLIQUE, POLYNOMIAL, TABLE); macros, for #if */
#define QZS_SPRING_TANH 0
#define QZS_SPRING_OBLIQUE 1
#define QZS_SPRING_POLYNOMIAL 2
#define QZS_SPRING_TABLE 3
/* offsets in a packed table (qzs.model.springs.TABLE_*) */
enum { QZS_TABLE_OUTSIDE = 1, QZS_TABLE_COUNT, QZS_TABLE_END_FORCE, QZS_TABLE_END_SLOPE,
       QZS_TABLE_POSITIONS };
/* the least number of points of a table (springs.TABLE_MIN_POINTS) */
#define QZS_TABLE_MIN_POINTS 3
/* what qzs_spring_evaluate computes (bits of `want`) */
enum { QZS_SPRING_FORCE = 1, QZS_SPRING_STIFFNESS = 2, QZS_SPRING_ENERGY = 4 };
/* qzs_spring_evaluate's status (springs.STATUS_OK, STATUS_OUTSIDE) */
enum { QZS_SPRING_OK, QZS_SPRING_OUTSIDE };

/* Force on the payload [N] (upward positive), tangent stiffness -dF/dz [N/m] and stored
 * energy [J] of a law. */
typedef struct { double force, stiffness, energy; } QzsSpringValues;

/* The values `want` asks for of the packed `law` at relative position z [m] into *out (the
 * others are not written). Returns QZS_SPRING_OK, or QZS_SPRING_OUTSIDE (and NaN values)
 * outside a table that refuses positions outside it. */
int qzs_spring_evaluate(const double *law, double z, int want, QzsSpringValues *out);
/* The packed size of a table of n points: code, outside, n, end force and slope, the n
 * positions, 4 (n - 1) piece coefficients, n energies. */
long qzs_spring_table_size(long n);
/* Pack the table of n >= 3 points (positions x [m], strictly increasing; forces y [N]) into
 * law (qzs_spring_table_size(n) values): the PCHIP slopes, pieces and energies of
 * qzs.model.spring_table, `outside` 0 refuse, 1 extend. */
void qzs_spring_table(double *law, long n, const double *x, const double *y, int outside);
/* The packed law's size (its code's layout). */
long qzs_spring_size(const double *law);
/* The law's largest stiffness [N/m] over [low, high] [m] (within a refusing table's range):
 * at 4097 evenly spaced positions and a table's breakpoints there, as
 * qzs.engine.stability.spring_stiffness_peak. */
double qzs_spring_stiffness_peak(const double *law, double low, double high);

#endif /* QZS_SPRING_H */
