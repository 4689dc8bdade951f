/* qzs: the sampled controller, PI + active damping and its blocks (see qzs_controller.h). */
#include "qzs_controller.h"

void qzs_controller_init(QzsController *controller, const QzsControllerParameters *parameters,
                         double integral) {
    controller->parameters = *parameters;
    controller->integral = integral;
    controller->output = qzs_controller_law(parameters, parameters->position_setpoint, 0.0,
                                            integral);
}

QzsControllerOutput qzs_controller_step(QzsController *controller, double z, double v_measured) {
    const QzsControllerParameters *p = &controller->parameters;
    QzsControllerOutput out = qzs_controller_law(p, z, v_measured, controller->integral);
    controller->integral =
        controller->integral + out.integral_rate * p->period_steps * p->step_time;
    controller->output = out;
    return out;
}

void qzs_block_controller_init(QzsBlockController *controller,
                               const QzsBlockParameters *parameters, double integral,
                               const QzsBlocks *x, const QzsBlockOutput *held) {
    controller->parameters = *parameters;
    controller->integral = integral;
    controller->x = *x;
    controller->output = *held;
}

QzsBlockOutput qzs_block_controller_step(QzsBlockController *controller,
                                         const QzsSensors *sensors) {
    const QzsBlockParameters *p = &controller->parameters;
    const double *M = p->model;
    double v = sensors->relative_velocity;
    double direction = v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0);
    QzsBlockOutput out = qzs_sample_blocks_law(
        &p->control, M, p->velocity_regularisation, sensors->time, sensors->position,
        sensors->measured_velocity, v, direction, sensors->friction_force,
        controller->output.linear, controller->output.compensation, &controller->integral,
        &controller->x.x[QZS_X_OBSERVER]);
    if (M[QZS_M_LINEAR] != 0.0) { /* the PI and its blocks first, then the linear controller */
        double u[QZS_N_SENSORS] = {p->control.position_setpoint - sensors->position,
                                   sensors->measured_velocity, sensors->payload_acceleration,
                                   sensors->base_acceleration, v};
        out.linear = qzs_sample_linear_law(&p->control, M, sensors->position, u,
                                           out.pi + out.damping + out.compensation + out.dither,
                                           &controller->x, &out.motor);
    }
    controller->output = out;
    return out;
}
