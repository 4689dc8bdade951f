/* qzs: the sampled PI + active damping controller of the isolator (docs/model.md §5).
 *
 * Position loop (PI on the relative position z, setpoint z_ref) plus active damping on the
 * measured absolute velocity (the charge amplifier's high-passed signal, a sensor of the
 * plant), summed and saturated at +-f_max, with anti-windup by conditional integration.
 * Sampled with zero-order hold: qzs_controller_step() is called once per sample period, it
 * returns the command held until the next call and advances the PI integral by
 * rate * period_steps * step_time (the operations of qzs.engine.kernels.sample_controller,
 * in the same order, so a sampled qzs run and this code give the same bits).
 *
 * Plain C99, no dependency beyond the language: the same text runs on a real-time target,
 * inside the qzs FMU and in qzs's C model of the isolator.
 */
#ifndef QZS_CONTROLLER_H
#define QZS_CONTROLLER_H

/* Parameters of the controller, SI units. */
typedef struct {
    double position_setpoint; /* z_ref [m] */
    double pi_kp;             /* proportional gain [N/m] */
    double pi_ki;             /* integral gain [N/(m*s)] */
    double damping_gain;      /* active damping gain [N*s/m] */
    double motor_force_max;   /* motor saturation [N] */
    double period_steps;      /* sample period in integration steps [-] (1 on a target) */
    double step_time;         /* integration step [s] (the sample period on a target) */
} QzsControllerParameters;

/* One command: PI part, damping part, the saturated motor force [N], the integral's rate [m]. */
typedef struct {
    double pi;
    double damping;
    double motor;
    double integral_rate;
} QzsControllerOutput;

/* The controller: its parameters, the PI integral [m*s] and the command it holds [N]. */
typedef struct {
    QzsControllerParameters parameters;
    double integral;
    QzsControllerOutput output;
} QzsController;

/* The control law at (z [m], v_measured [m/s], integral [m*s]); no state is changed.
 * (qzs.engine.laws.controller_law, operation for operation.) */
static inline QzsControllerOutput qzs_controller_law(const QzsControllerParameters *p, double z,
                                                     double v_measured, double integral) {
    QzsControllerOutput out;
    double error = p->position_setpoint - z;
    double f_pi = p->pi_kp * error + p->pi_ki * integral;
    double f_damp = -p->damping_gain * v_measured;
    double command = f_pi + f_damp;
    double rate = error;
    if (command > p->motor_force_max) {
        command = p->motor_force_max;
        if (error * p->pi_ki > 0.0)
            rate = 0.0; /* anti-windup: do not integrate further into saturation */
    } else if (command < -p->motor_force_max) {
        command = -p->motor_force_max;
        if (error * p->pi_ki < 0.0)
            rate = 0.0;
    }
    out.pi = f_pi;
    out.damping = f_damp;
    out.motor = command;
    out.integral_rate = rate;
    return out;
}

/* Set the parameters and the PI integral [m*s] (qzs's preload, or 0); the held command is
 * the law's at (position_setpoint, 0). */
void qzs_controller_init(QzsController *controller, const QzsControllerParameters *parameters,
                         double integral);

/* One sample: the command for (z [m], v_measured [m/s]), held until the next call; the
 * integral advances by one sample period. */
QzsControllerOutput qzs_controller_step(QzsController *controller, double z, double v_measured);

#endif /* QZS_CONTROLLER_H */
