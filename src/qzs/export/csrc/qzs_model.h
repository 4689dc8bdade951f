/* qzs: the closed loop of plant and sampled controller, run as qzs runs it.
 *
 * qzs_model_run() is qzs.engine.lanes.run_single: the same packed inputs (parameters,
 * state with the held controller outputs, flags, excitation and table), the same loop (the
 * controller sampled at the start of every period, one grid step, the divergence test, the
 * excitation's phase rotated and made exact every QZS_PHASE_PERIOD steps, the contact
 * counters, a recorded row every `decimation` steps), the same outputs. The controller is
 * qzs_controller.c, called through qzs_controller_step() as on a target.
 */
#ifndef QZS_MODEL_H
#define QZS_MODEL_H

#include <stdint.h>

#include "qzs_plant.h"

/* Advance `n_steps` from flags[QZS_I_STEP]; rows go to out (QZS_N_CHANNELS doubles each) and
 * out_flags (2 bytes each) from row0. state (QZS_N_STATE) and flags (QZS_N_FLAGS) carry the
 * run between calls. Returns QZS_STATUS_OK or QZS_STATUS_DIVERGED; *rows the rows written. */
int qzs_model_run(int solver, int64_t n_steps, int64_t decimation, double *state,
                  int64_t *flags, const double *params, const double *excitation,
                  const double *table, int64_t table_columns, double *out,
                  unsigned char *out_flags, int64_t row0, int64_t *rows);

/* One recorded row of the persistent state at t (qzs.engine.kernels.evaluate). */
void qzs_model_evaluate(double t, const double *state, const int64_t *flags,
                        const double *params, const double *excitation, const double *table,
                        int64_t table_columns, double *row, unsigned char *row_flags);

#endif /* QZS_MODEL_H */
