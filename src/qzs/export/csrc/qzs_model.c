/* qzs: the closed loop of plant and sampled controller (see qzs_model.h). */
#include "qzs_model.h"

#include <math.h>

void qzs_run_start(QzsRun *run, int solver, const double *state, const int64_t *flags) {
    const double *P = run->plant.P;
    run->solver = solver;
    run->control_steps = (int64_t)P[QZS_P_CONTROL_STEPS];
    run->linear_steps = run->plant.blocks ? (int64_t)run->plant.M[QZS_M_LINEAR_STEPS] : 0;
    run->sampled = run->control_steps > 0;
    qzs_controller_init(&run->controller, &run->plant.control, state[QZS_S_INT]);
    for (int j = 0; j < QZS_N_ODE; j++)
        run->s.x[j] = state[j];
    for (int j = 0; j < QZS_N_X; j++)
        run->x.x[j] = state[QZS_A_X0 + j];
    run->held[QZS_H_PI] = state[QZS_A_F_PI];
    run->held[QZS_H_DAMP] = state[QZS_A_F_DAMP];
    run->held[QZS_H_MOTOR] = state[QZS_A_F_MOTOR];
    run->held[QZS_H_COMPENSATION] = state[QZS_A_F_COMPENSATION];
    run->held[QZS_H_DITHER] = state[QZS_A_F_DITHER];
    run->held[QZS_H_LINEAR] = state[QZS_A_F_LINEAR];
    run->margin = state[QZS_A_MARGIN];
    run->mode = (int)flags[QZS_I_MODE];
    run->direction = (int)flags[QZS_I_DIRECTION];
    run->contact = (int)flags[QZS_I_CONTACT];
    run->step = flags[QZS_I_STEP];
    run->sticks = flags[QZS_I_N_STICKS];
    run->contacts = flags[QZS_I_N_CONTACTS];
    QzsPhase start = {0.0, 0.0, 1.0};
    run->phase = qzs_advance_phase(&run->plant, (double)run->step * P[QZS_P_DT], start, 1);
}

/* One step of the run of length h from t, the excitation's phase at t given: the controller
 * sampled first where `at_grid_point` and a sample is due; `completes`: the step ends on the
 * next grid point (the step count and the grid's phase advance). One grid step of
 * qzs.engine.lanes.run_single when h is the grid step; part of one otherwise. */
static int run_one(QzsRun *run, double t, double h, QzsPhase phase, int at_grid_point,
                   int completes) {
    const QzsPlant *plant = &run->plant;
    const double *P = plant->P;
    if (at_grid_point && run->sampled && run->step % run->control_steps == 0 &&
        plant->blocks) {
        qzs_sample_blocks(plant, t, &run->s, &run->x, run->mode, run->direction, run->held);
        run->controller.integral = run->s.x[QZS_S_INT];
        run->margin = NAN;
    } else if (at_grid_point && run->sampled && run->step % run->control_steps == 0) {
        double z, v_measured;
        qzs_measure(plant, t, &run->s, run->mode, &z, &v_measured);
        run->controller.integral = run->s.x[QZS_S_INT];
        QzsControllerOutput command = qzs_controller_step(&run->controller, z, v_measured);
        run->held[QZS_H_PI] = command.pi;
        run->held[QZS_H_DAMP] = command.damping;
        run->held[QZS_H_MOTOR] = command.motor;
        run->s.x[QZS_S_INT] = run->controller.integral;
        run->margin = NAN;
    }
    if (at_grid_point && run->linear_steps > 0 && run->step % run->linear_steps == 0) {
        qzs_sample_linear(plant, t, &run->s, &run->x, run->mode, run->direction, run->held);
        run->margin = NAN;
    }
    QzsStep next = qzs_grid_step(plant, run->solver, t, h, run->s, run->x, run->mode,
                                 run->direction, run->held, run->margin, phase);
    if (!qzs_finite(plant, &next.s) || (plant->blocks && !qzs_finite_blocks(&next.x)))
        return qzs_failure_status(plant);
    run->s = next.s;
    if (plant->blocks)
        run->x = next.x;
    run->mode = next.mode;
    run->direction = next.direction;
    run->margin = next.margin;
    if (completes) {
        run->step += 1;
        /* rotate the excitation's sine/cosine to the next step; exact every PHASE_PERIOD steps */
        run->phase = qzs_advance_phase(plant, (double)run->step * P[QZS_P_DT], run->phase,
                                       run->step % QZS_PHASE_PERIOD == 0);
    }
    run->sticks += next.sticks;
    run->contacts += next.impacts;
    int now = qzs_in_contact(plant, &run->s, run->mode);
    if (now && run->contact == 0 && P[QZS_P_PLASTIC] == 0.0)
        run->contacts += 1;
    run->contact = now ? 1 : 0;
    return QZS_STATUS_OK;
}

int qzs_run_steps(QzsRun *run, int64_t n_steps, int64_t decimation, double *out,
                  unsigned char *out_flags, int64_t *rows) {
    const QzsPlant *plant = &run->plant;
    const double h = plant->P[QZS_P_DT];
    int status = QZS_STATUS_OK;
    int64_t row = 0;
    for (int64_t i = 0; i < n_steps; i++) {
        double t = (double)run->step * h;
        status = run_one(run, t, h, run->phase, 1, 1);
        if (status != QZS_STATUS_OK)
            break;
        if (decimation > 0 && run->step % decimation == 0) {
            qzs_record(plant, (double)run->step * h, &run->s, &run->x, run->mode,
                       run->direction,
                       run->held, out + row * QZS_N_CHANNELS,
                       out_flags + row * QZS_N_OUTPUT_FLAGS, run->phase);
            row += 1;
        }
    }
    if (rows)
        *rows = row;
    return status;
}

int qzs_run_part(QzsRun *run, double from, double to) {
    const QzsPlant *plant = &run->plant;
    const double dt = plant->P[QZS_P_DT];
    double grid = (double)run->step * dt;
    int completes = to >= dt;
    if (from == 0.0)
        return run_one(run, grid, completes ? dt : to, run->phase, 1, completes);
    double t = grid + from;
    double h = (completes ? (double)(run->step + 1) * dt : grid + to) - t;
    QzsPhase phase = qzs_advance_phase(plant, t, run->phase, 1);
    return run_one(run, t, h, phase, 0, completes);
}

void qzs_run_pack(const QzsRun *run, double *state, int64_t *flags) {
    for (int j = 0; j < QZS_N_ODE; j++)
        state[j] = run->s.x[j];
    if (run->plant.blocks)
        for (int j = 0; j < QZS_N_X; j++)
            state[QZS_A_X0 + j] = run->x.x[j];
    state[QZS_A_F_PI] = run->held[QZS_H_PI];
    state[QZS_A_F_DAMP] = run->held[QZS_H_DAMP];
    state[QZS_A_F_MOTOR] = run->held[QZS_H_MOTOR];
    state[QZS_A_F_COMPENSATION] = run->held[QZS_H_COMPENSATION];
    state[QZS_A_F_DITHER] = run->held[QZS_H_DITHER];
    state[QZS_A_F_LINEAR] = run->held[QZS_H_LINEAR];
    state[QZS_A_MARGIN] = run->margin;
    flags[QZS_I_MODE] = run->mode;
    flags[QZS_I_DIRECTION] = run->direction;
    flags[QZS_I_CONTACT] = run->contact;
    flags[QZS_I_STEP] = run->step;
    flags[QZS_I_N_STICKS] = run->sticks;
    flags[QZS_I_N_CONTACTS] = run->contacts;
}

int qzs_model_run(int solver, int64_t n_steps, int64_t decimation, double *state,
                  int64_t *flags, const double *params, const double *model,
                  const double *excitation, const double *table, int64_t table_columns,
                  double *out, unsigned char *out_flags, int64_t row0, int64_t *rows) {
    QzsRun run;
    qzs_plant_init(&run.plant, params, model, excitation, table, (long)table_columns);
    qzs_run_start(&run, solver, state, flags);
    int status = qzs_run_steps(&run, n_steps, decimation, out + row0 * QZS_N_CHANNELS,
                               out_flags + row0 * QZS_N_OUTPUT_FLAGS, rows);
    qzs_run_pack(&run, state, flags);
    return status;
}

void qzs_model_evaluate(double t, const double *state, const int64_t *flags,
                        const double *params, const double *model, const double *excitation,
                        const double *table, int64_t table_columns, double *row,
                        unsigned char *row_flags) {
    QzsPlant plant;
    qzs_plant_init(&plant, params, model, excitation, table, (long)table_columns);
    QzsOde s;
    for (int j = 0; j < QZS_N_ODE; j++)
        s.x[j] = state[j];
    QzsBlocks x;
    for (int j = 0; j < QZS_N_X; j++)
        x.x[j] = state[QZS_A_X0 + j];
    double held[QZS_N_HELD] = {state[QZS_A_F_PI], state[QZS_A_F_DAMP], state[QZS_A_F_MOTOR],
                               state[QZS_A_F_COMPENSATION], state[QZS_A_F_DITHER],
                               state[QZS_A_F_LINEAR]};
    QzsPhase start = {0.0, 0.0, 1.0};
    QzsPhase phase = qzs_advance_phase(&plant, t, start, 1);
    qzs_record(&plant, t, &s, &x, (int)flags[QZS_I_MODE], (int)flags[QZS_I_DIRECTION], held,
               row, row_flags, phase);
}
