/* qzs: the sampled PI + active damping controller (see qzs_controller.h). */
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
