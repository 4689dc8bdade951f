/* qzs: the closed loop of plant and sampled controller, run as qzs runs it.
 *
 * qzs_run_steps() is the loop of qzs.engine.lanes.run_single: the controller sampled at the
 * start of every period (through qzs_controller_step(), as on a target), one grid step, the
 * divergence test, the excitation's phase rotated and made exact every QZS_PHASE_PERIOD
 * steps, the contact counters, a recorded row every `decimation` steps. qzs_model_run() wraps
 * it with the kernels' packed arrays (parameters, state with the held controller outputs,
 * flags, excitation and table); the FMU (qzs_fmu.c) steps the same QzsRun.
 */
#ifndef QZS_MODEL_H
#define QZS_MODEL_H

#include <stdint.h>

#include "qzs_plant.h"

/* A run under way: the plant, its controller and everything carried from step to step. */
typedef struct {
    QzsPlant plant;
    QzsController controller;
    int sampled;          /* the controller is called (closed loop, controller_rate > 0) */
    int64_t control_steps;
    int solver;
    int64_t linear_steps; /* a discrete linear controller's period in grid steps (0: none) */
    QzsOde s;
    QzsBlocks x;          /* the controller blocks' states */
    double held[QZS_N_HELD]; /* the commands held: PI, damping, motor, blocks [N] */
    double margin;        /* the holding margin at the step's start (NaN: not known) */
    int mode, direction, contact;
    int64_t step, sticks, contacts;
    QzsPhase phase;
} QzsRun;

/* Start `run` from the packed state (QZS_N_STATE) and flags (QZS_N_FLAGS); plant must be
 * initialised. */
void qzs_run_start(QzsRun *run, int solver, const double *state, const int64_t *flags);
/* Advance n_steps; a row to out/out_flags every `decimation` steps (decimation 0: none).
 * Returns QZS_STATUS_OK, or QZS_STATUS_DIVERGED or QZS_STATUS_OUTSIDE (the run then holds its
 * last finite state: qzs_failure_status); *rows the rows written. */
int qzs_run_steps(QzsRun *run, int64_t n_steps, int64_t decimation, double *out,
                  unsigned char *out_flags, int64_t *rows);
/* Part of the grid step that starts at the grid point run->step * dt: from `from` to `to` [s]
 * past it (0 <= from < to <= dt). The controller is sampled only at the grid point itself
 * (from = 0), so that its timing stays the grid's; `to` = dt completes the grid step. What a
 * communication point inside a grid step needs (qzs_fmu.c). Returns as qzs_run_steps. */
int qzs_run_part(QzsRun *run, double from, double to);
/* The packed state and flags of the run (qzs_run_start's inverse). */
void qzs_run_pack(const QzsRun *run, double *state, int64_t *flags);

/* Advance `n_steps` from flags[QZS_I_STEP]; rows go to out (QZS_N_CHANNELS doubles each) and
 * out_flags (2 bytes each) from row0. state (QZS_N_STATE) and flags (QZS_N_FLAGS) carry the
 * run between calls. model: the controller's blocks and the spring law (qzs.engine.prepare
 * .pack_model's row; NULL for PI + damping alone with the tanh). Returns as qzs_run_steps;
 * *rows the rows written. */
int qzs_model_run(int solver, int64_t n_steps, int64_t decimation, double *state,
                  int64_t *flags, const double *params, const double *model,
                  const double *excitation,
                  const double *table, int64_t table_columns, double *out,
                  unsigned char *out_flags, int64_t row0, int64_t *rows);

/* One recorded row of the persistent state at t (qzs.engine.kernels.evaluate). */
void qzs_model_evaluate(double t, const double *state, const int64_t *flags,
                        const double *params, const double *model, const double *excitation,
                        const double *table,
                        int64_t table_columns, double *row, unsigned char *row_flags);

#endif /* QZS_MODEL_H */
