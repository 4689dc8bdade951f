/* qzs: the closed loop of plant and sampled controller (see qzs_model.h). */
#include "qzs_model.h"

#include <math.h>

int qzs_model_run(int solver, int64_t n_steps, int64_t decimation, double *state,
                  int64_t *flags, const double *params, const double *excitation,
                  const double *table, int64_t table_columns, double *out,
                  unsigned char *out_flags, int64_t row0, int64_t *rows) {
    QzsPlant plant;
    qzs_plant_init(&plant, params, excitation, table, (long)table_columns);
    const double *P = plant.P;
    const double h = P[QZS_P_DT];
    const int64_t control_steps = (int64_t)P[QZS_P_CONTROL_STEPS];
    QzsController controller;
    qzs_controller_init(&controller, &plant.control, state[QZS_S_INT]);
    QzsOde s;
    for (int j = 0; j < QZS_N_ODE; j++)
        s.x[j] = state[j];
    double held[3] = {state[QZS_A_F_PI], state[QZS_A_F_DAMP], state[QZS_A_F_MOTOR]};
    int mode = (int)flags[QZS_I_MODE];
    int direction = (int)flags[QZS_I_DIRECTION];
    int contact = (int)flags[QZS_I_CONTACT];
    int64_t step = flags[QZS_I_STEP];
    int status = QZS_STATUS_OK;
    int64_t row = row0;
    double margin = state[QZS_A_MARGIN];
    QzsPhase start = {0.0, 0.0, 1.0};
    QzsPhase phase = qzs_advance_phase(&plant, (double)step * h, start, 1);
    for (int64_t i = 0; i < n_steps; i++) {
        double t = (double)step * h;
        if (control_steps > 0 && step % control_steps == 0) {
            double z, v_measured;
            qzs_measure(&plant, t, &s, mode, &z, &v_measured);
            controller.integral = s.x[QZS_S_INT];
            QzsControllerOutput command = qzs_controller_step(&controller, z, v_measured);
            held[0] = command.pi;
            held[1] = command.damping;
            held[2] = command.motor;
            s.x[QZS_S_INT] = controller.integral;
            margin = NAN;
        }
        QzsStep next = qzs_grid_step(&plant, solver, t, h, s, mode, direction, held, margin,
                                     phase);
        if (!qzs_finite(&plant, &next.s)) {
            status = QZS_STATUS_DIVERGED;
            break;
        }
        s = next.s;
        mode = next.mode;
        direction = next.direction;
        margin = next.margin;
        step += 1;
        /* rotate the excitation's sine/cosine to the next step; exact every PHASE_PERIOD steps */
        phase = qzs_advance_phase(&plant, (double)step * h, phase, step % QZS_PHASE_PERIOD == 0);
        flags[QZS_I_N_STICKS] += next.sticks;
        flags[QZS_I_N_CONTACTS] += next.impacts;
        int now = qzs_in_contact(&plant, &s, mode);
        if (now && contact == 0 && P[QZS_P_PLASTIC] == 0.0)
            flags[QZS_I_N_CONTACTS] += 1;
        contact = now ? 1 : 0;
        if (step % decimation == 0) {
            qzs_record(&plant, (double)step * h, &s, mode, direction, held,
                       out + row * QZS_N_CHANNELS, out_flags + row * QZS_N_OUTPUT_FLAGS, phase);
            row += 1;
        }
    }
    for (int j = 0; j < QZS_N_ODE; j++)
        state[j] = s.x[j];
    state[QZS_A_F_PI] = held[0];
    state[QZS_A_F_DAMP] = held[1];
    state[QZS_A_F_MOTOR] = held[2];
    state[QZS_A_MARGIN] = margin;
    flags[QZS_I_MODE] = mode;
    flags[QZS_I_DIRECTION] = direction;
    flags[QZS_I_CONTACT] = contact;
    flags[QZS_I_STEP] = step;
    *rows = row - row0;
    return status;
}

void qzs_model_evaluate(double t, const double *state, const int64_t *flags,
                        const double *params, const double *excitation, const double *table,
                        int64_t table_columns, double *row, unsigned char *row_flags) {
    QzsPlant plant;
    qzs_plant_init(&plant, params, excitation, table, (long)table_columns);
    QzsOde s;
    for (int j = 0; j < QZS_N_ODE; j++)
        s.x[j] = state[j];
    double held[3] = {state[QZS_A_F_PI], state[QZS_A_F_DAMP], state[QZS_A_F_MOTOR]};
    QzsPhase start = {0.0, 0.0, 1.0};
    QzsPhase phase = qzs_advance_phase(&plant, t, start, 1);
    qzs_record(&plant, t, &s, (int)flags[QZS_I_MODE], (int)flags[QZS_I_DIRECTION], held, row,
               row_flags, phase);
}
