/* qzs: the isolator as an FMU, independent of the FMI version (see qzs_fmu.h). */
#include "qzs_fmu.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "qzs_stability.h"

#define V(name) (fmu->values[QZS_VR_##name])

void qzs_fmu_log(QzsFmu *fmu, int status, const char *format, ...) {
    char message[1024];
    va_list args;
    va_start(args, format);
    vsnprintf(message, sizeof message, format, args);
    va_end(args);
    if (fmu->log)
        fmu->log(fmu->environment, status,
                 status == QZS_FMU_ERROR ? "logStatusError"
                                         : (status == QZS_FMU_WARNING ? "logStatusWarning"
                                                                      : "logEvents"),
                 message);
}

void qzs_fmu_reset(QzsFmu *fmu, double start_time) {
    for (int i = 0; i < QZS_FMU_N_VARIABLES; i++)
        fmu->values[i] = QZS_FMU_START[i];
    fmu->initialized = 0;
    fmu->failed = 0;
    fmu->start_time = start_time;
    fmu->time = start_time;
    fmu->offset = 0.0;
    fmu->stop_defined = 0;
    fmu->stop_time = 0.0;
    fmu->values[QZS_VR_TIME] = start_time;
    memset(fmu->table, 0, sizeof fmu->table);
    fmu->has_previous = 0;
    fmu->previous_time = 0.0;
    fmu->previous_acceleration = 0.0;
}

void qzs_fmu_setup(QzsFmu *fmu, double start_time, int stop_defined, double stop_time) {
    fmu->start_time = start_time;
    fmu->time = start_time;
    fmu->stop_defined = stop_defined;
    fmu->stop_time = stop_defined ? stop_time : 0.0;
}

static const char *type_name(char type) {
    return type == 'F' ? "Float64 (Real)" : (type == 'I' ? "integer" : "Boolean");
}

static int check_reference(QzsFmu *fmu, unsigned int reference, char type, const char *verb) {
    if (reference >= QZS_FMU_N_VARIABLES) {
        qzs_fmu_log(fmu, QZS_FMU_ERROR, "%s: no variable has value reference %u (0 to %d)",
                    verb, reference, QZS_FMU_N_VARIABLES - 1);
        return QZS_FMU_ERROR;
    }
    if (QZS_FMU_TYPES[reference] != type) {
        qzs_fmu_log(fmu, QZS_FMU_ERROR, "%s: `%s` (value reference %u) is a %s variable, not %s",
                    verb, QZS_FMU_NAMES[reference], reference,
                    type_name(QZS_FMU_TYPES[reference]), type_name(type));
        return QZS_FMU_ERROR;
    }
    return QZS_FMU_OK;
}

int qzs_fmu_set(QzsFmu *fmu, unsigned int reference, char type, double value) {
    if (check_reference(fmu, reference, type, "set") != QZS_FMU_OK)
        return QZS_FMU_ERROR;
    const char *name = QZS_FMU_NAMES[reference];
    char causality = QZS_FMU_CAUSALITY[reference];
    if (causality != 'p' && causality != 'i') {
        qzs_fmu_log(fmu, QZS_FMU_ERROR, "set: `%s` is an %s; only parameters and inputs are set",
                    name, causality == 'o' ? "output" : "independent variable");
        return QZS_FMU_ERROR;
    }
    if (causality == 'p' && fmu->initialized) {
        qzs_fmu_log(fmu, QZS_FMU_ERROR,
                    "set: `%s` is a fixed parameter; set it before initialisation ends "
                    "(or reset the FMU)", name);
        return QZS_FMU_ERROR;
    }
    if (!isfinite(value)) {
        qzs_fmu_log(fmu, QZS_FMU_ERROR, "set: `%s` = %g is not a finite number", name, value);
        return QZS_FMU_ERROR;
    }
    fmu->values[reference] = value;
    return QZS_FMU_OK;
}

int qzs_fmu_get(QzsFmu *fmu, unsigned int reference, char type, double *value) {
    if (check_reference(fmu, reference, type, "get") != QZS_FMU_OK)
        return QZS_FMU_ERROR;
    *value = reference == QZS_VR_TIME ? fmu->time : fmu->values[reference];
    return QZS_FMU_OK;
}

int qzs_fmu_size(QzsFmu *fmu, unsigned int reference, size_t *size) {
    if (reference >= QZS_FMU_N_VARIABLES || QZS_FMU_SIZE[reference] == 0) {
        qzs_fmu_log(fmu, QZS_FMU_ERROR, "no variable has value reference %u", reference);
        return QZS_FMU_ERROR;
    }
    *size = (size_t)QZS_FMU_SIZE[reference];
    return QZS_FMU_OK;
}

/* A parameter outside its range: logged with its value and what it must be. */
static int refuse(QzsFmu *fmu, const char *name, double value, const char *rule) {
    qzs_fmu_log(fmu, QZS_FMU_ERROR, "`%s` = %.15g must be %s; set it so before initialisation "
                "ends", name, value, rule);
    return QZS_FMU_ERROR;
}

#define REQUIRE(name, condition, rule) \
    if (!(condition)) return refuse(fmu, QZS_FMU_NAMES[QZS_VR_##name], V(name), rule)

/* The checks of qzs.model (IsolatorParameters, ControllerParameters, Chirp, Sine), on the
 * parameters this FMU uses: an excitation's parameter that its kind does not use (a sine's
 * sweep time) and, in plant mode, the controller's gains are neither required nor checked. */
static int check_parameters(QzsFmu *fmu) {
    REQUIRE(ISOLATOR_MASS, V(ISOLATOR_MASS) > 0.0, "positive [kg]");
    REQUIRE(ISOLATOR_GRAVITY, V(ISOLATOR_GRAVITY) >= 0.0, ">= 0 [m/s^2]");
    REQUIRE(ISOLATOR_SPRING_FORCE, V(ISOLATOR_SPRING_FORCE) >= 0.0, ">= 0 [N]");
    REQUIRE(ISOLATOR_SPRING_SHAPE, V(ISOLATOR_SPRING_SHAPE) > 0.0, "positive [1/m]");
    REQUIRE(ISOLATOR_STICTION_FORCE, V(ISOLATOR_STICTION_FORCE) >= 0.0, ">= 0 [N]");
    REQUIRE(ISOLATOR_COULOMB_FORCE, V(ISOLATOR_COULOMB_FORCE) >= 0.0 &&
            V(ISOLATOR_COULOMB_FORCE) <= V(ISOLATOR_STICTION_FORCE),
            "between 0 and isolator.stiction_force [N] (the breakaway force cannot be below "
            "the sliding friction)");
    REQUIRE(ISOLATOR_STRIBECK_DECAY, V(ISOLATOR_STRIBECK_DECAY) >= 0.0, ">= 0 [s/m]");
    REQUIRE(ISOLATOR_VISCOUS_DAMPING, V(ISOLATOR_VISCOUS_DAMPING) >= 0.0, ">= 0 [N*s/m]");
    REQUIRE(ISOLATOR_FRICTION_REGULARISATION, V(ISOLATOR_FRICTION_REGULARISATION) >= 0.0,
            ">= 0 [m/s]");
    REQUIRE(ISOLATOR_STROKE_HALF, V(ISOLATOR_STROKE_HALF) > 0.0, "positive [m]");
    REQUIRE(ISOLATOR_STOP_STIFFNESS, V(ISOLATOR_STOP_STIFFNESS) > 0.0, "positive [N/m]");
    REQUIRE(ISOLATOR_STOP_DAMPING, V(ISOLATOR_STOP_DAMPING) >= 0.0, ">= 0 [N*s/m]");
    REQUIRE(ISOLATOR_STOP_MODEL, V(ISOLATOR_STOP_MODEL) == 0.0 || V(ISOLATOR_STOP_MODEL) == 1.0,
            "0 (compliant) or 1 (plastic)");
    REQUIRE(ISOLATOR_FRICTION_REGULARISATION,
            !(V(ISOLATOR_FRICTION_REGULARISATION) > 0.0 && V(ISOLATOR_STOP_MODEL) == 1.0),
            "0 with plastic stops (a regularised slip never rests on a stop)");
    REQUIRE(CONTROLLER_VELOCITY_HIGHPASS, V(CONTROLLER_VELOCITY_HIGHPASS) >= 0.0, ">= 0 [Hz]");
#if !QZS_FMU_PLANT_MODE
    REQUIRE(ISOLATOR_MOTOR_FORCE_MAX, V(ISOLATOR_MOTOR_FORCE_MAX) >= 0.0, ">= 0 [N]");
    REQUIRE(CONTROLLER_PI_KP, V(CONTROLLER_PI_KP) >= 0.0, ">= 0 [N/m]");
    REQUIRE(CONTROLLER_PI_KI, V(CONTROLLER_PI_KI) >= 0.0, ">= 0 [N/(m*s)]");
    REQUIRE(CONTROLLER_DAMPING_GAIN, V(CONTROLLER_DAMPING_GAIN) >= 0.0, ">= 0 [N*s/m]");
    REQUIRE(CONTROLLER_CONTROLLER_RATE, V(CONTROLLER_CONTROLLER_RATE) >= 0.0, ">= 0 [Hz]");
#endif
    REQUIRE(STEP_SIZE, V(STEP_SIZE) > 0.0, "positive [s]");
    REQUIRE(SOLVER, V(SOLVER) == 0.0 || V(SOLVER) == 1.0 || V(SOLVER) == 2.0,
            "0 (euler), 1 (ode3) or 2 (rk4)");
#if !QZS_FMU_BASE_INPUT
    double kind = V(EXCITATION_KIND);
    REQUIRE(EXCITATION_KIND, kind == 0.0 || kind == 1.0 || kind == 2.0,
            "0 (linear chirp), 1 (logarithmic chirp) or 2 (sine)");
    REQUIRE(EXCITATION_AMPLITUDE, V(EXCITATION_AMPLITUDE) >= 0.0, ">= 0 [m]");
    REQUIRE(EXCITATION_FADE_IN, V(EXCITATION_FADE_IN) >= 0.0, ">= 0 [s]");
    if (kind == 2.0) {
        REQUIRE(EXCITATION_F0, V(EXCITATION_F0) > 0.0,
                "positive [Hz] for a sine (its frequency; a sine of 0 Hz does not move the "
                "base: set excitation.amplitude = 0 for a base at rest)");
    } else {
        REQUIRE(EXCITATION_F0, V(EXCITATION_F0) >= 0.0 && (kind == 0.0 || V(EXCITATION_F0) > 0.0),
                ">= 0 [Hz] (positive for a logarithmic chirp)");
        REQUIRE(EXCITATION_F1, V(EXCITATION_F1) >= 0.0 && (kind == 0.0 || V(EXCITATION_F1) > 0.0),
                ">= 0 [Hz] (positive for a logarithmic chirp)");
        REQUIRE(EXCITATION_DURATION, V(EXCITATION_DURATION) > 0.0,
                "positive [s] for a chirp (its sweep time)");
        REQUIRE(EXCITATION_FADE_IN, V(EXCITATION_FADE_IN) <= V(EXCITATION_DURATION),
                "at most the chirp's sweep time excitation.duration [s]");
    }
#endif
#if QZS_FMU_SPRING_LAW == QZS_SPRING_OBLIQUE /* qzs.model.springs.ObliqueSpringQZS */
    REQUIRE(SPRING_VERTICAL_STIFFNESS, V(SPRING_VERTICAL_STIFFNESS) >= 0.0, ">= 0 [N/m]");
    REQUIRE(SPRING_OBLIQUE_STIFFNESS, V(SPRING_OBLIQUE_STIFFNESS) >= 0.0, ">= 0 [N/m]");
    REQUIRE(SPRING_FREE_LENGTH, V(SPRING_FREE_LENGTH) > 0.0, "positive [m]");
    REQUIRE(SPRING_HORIZONTAL_DISTANCE, V(SPRING_HORIZONTAL_DISTANCE) > 0.0, "positive [m]");
#elif QZS_FMU_SPRING_LAW == QZS_SPRING_TABLE
    REQUIRE(SPRING_OUTSIDE, V(SPRING_OUTSIDE) == 0.0 || V(SPRING_OUTSIDE) == 1.0,
            "0 (refuse) or 1 (extend)");
#endif
    return QZS_FMU_OK;
}

#if QZS_FMU_SPRING_LAW != QZS_SPRING_TANH
/* The spring law from its parameters into law (QZS_FMU_SPRING_SIZE values): the exported one
 * with each parameter put in its place; a table packed from its points (qzs_spring_table: its
 * PCHIP pieces and energies, as qzs.model.springs.TabulatedSpring packs them), its positions
 * checked to increase strictly. */
static int pack_spring(QzsFmu *fmu, double *law) {
    memcpy(law, QZS_FMU_SPRING_BASE, sizeof(double) * QZS_FMU_SPRING_SIZE);
#if QZS_FMU_SPRING_LAW == QZS_SPRING_TABLE
    double x[QZS_FMU_SPRING_POINTS], y[QZS_FMU_SPRING_POINTS];
    int first = -1; /* the value reference of the first position */
    for (int i = 0; i < QZS_FMU_N_VARIABLES; i++) {
        int where = QZS_FMU_SPRING[i];
        if (where >= QZS_FMU_SPRING_FORCE) {
            y[where - QZS_FMU_SPRING_FORCE] = fmu->values[i];
        } else if (where >= QZS_FMU_SPRING_POSITION) {
            x[where - QZS_FMU_SPRING_POSITION] = fmu->values[i];
            if (first < 0)
                first = i;
        }
    }
    for (int k = 1; k < QZS_FMU_SPRING_POINTS; k++) {
        if (!(x[k] > x[k - 1])) {
            qzs_fmu_log(fmu, QZS_FMU_ERROR,
                        "`%s` = %.15g m must exceed `%s` = %.15g m: the table's positions must "
                        "increase strictly (sort the table by position); set them so before "
                        "initialisation ends", QZS_FMU_NAMES[first + k], x[k],
                        QZS_FMU_NAMES[first + k - 1], x[k - 1]);
            return QZS_FMU_ERROR;
        }
    }
    qzs_spring_table(law, QZS_FMU_SPRING_POINTS, x, y, V(SPRING_OUTSIDE) == 1.0);
#else
    for (int i = 0; i < QZS_FMU_N_VARIABLES; i++)
        if (QZS_FMU_SPRING[i] >= 0)
            law[QZS_FMU_SPRING[i]] = fmu->values[i];
#endif
    return QZS_FMU_OK;
}
#endif

/* The packed parameters, as qzs.engine.prepare._pack_parameters packs them. */
static int pack_parameters(QzsFmu *fmu, double *P) {
    memset(P, 0, sizeof(double) * QZS_N_PARAMS);
    double center = V(ISOLATOR_STOP_CENTER);
    P[QZS_P_MASS] = V(ISOLATOR_MASS);
    P[QZS_P_GRAVITY] = V(ISOLATOR_GRAVITY);
    P[QZS_P_SPRING_A] = V(ISOLATOR_SPRING_FORCE);
    P[QZS_P_SPRING_B] = V(ISOLATOR_SPRING_SHAPE);
    P[QZS_P_FS] = V(ISOLATOR_STICTION_FORCE);
    P[QZS_P_FC] = V(ISOLATOR_COULOMB_FORCE);
    P[QZS_P_CBC] = V(ISOLATOR_STRIBECK_DECAY);
    P[QZS_P_CV] = V(ISOLATOR_VISCOUS_DAMPING);
    P[QZS_P_Z_LOW] = center - V(ISOLATOR_STROKE_HALF);
    P[QZS_P_Z_HIGH] = center + V(ISOLATOR_STROKE_HALF);
    P[QZS_P_STOP_K] = V(ISOLATOR_STOP_STIFFNESS);
    P[QZS_P_STOP_C] = V(ISOLATOR_STOP_DAMPING);
    P[QZS_P_PLASTIC] = V(ISOLATOR_STOP_MODEL) == 1.0 ? 1.0 : 0.0;
    P[QZS_P_FMAX] = V(ISOLATOR_MOTOR_FORCE_MAX);
    P[QZS_P_ZREF] = V(CONTROLLER_POSITION_SETPOINT);
    P[QZS_P_KP] = V(CONTROLLER_PI_KP);
    P[QZS_P_KI] = V(CONTROLLER_PI_KI);
    P[QZS_P_KD] = V(CONTROLLER_DAMPING_GAIN);
    P[QZS_P_HP_OMEGA] = 2 * 3.141592653589793 * V(CONTROLLER_VELOCITY_HIGHPASS);
    P[QZS_P_DT] = V(STEP_SIZE);
    P[QZS_P_VREG] = V(ISOLATOR_FRICTION_REGULARISATION);
#if QZS_FMU_PLANT_MODE
    P[QZS_P_CONTROL_STEPS] = 1.0; /* the motor force is held from the input: never sampled */
#else
    if (V(CONTROLLER_CONTROLLER_RATE) > 0.0) { /* qzs.engine.prepare.steps_per_sample, "exact" */
        double ratio = 1.0 / (V(CONTROLLER_CONTROLLER_RATE) * V(STEP_SIZE));
        double steps = floor(ratio + 0.5);
        if (steps < 1.0 || fabs(ratio - steps) > 1e-6 * ratio) {
            qzs_fmu_log(fmu, QZS_FMU_ERROR,
                        "`controller_rate` = %g Hz must divide the integration rate 1/step_size "
                        "= %g Hz into a whole number of steps (got %g); e.g. controller_rate = %g",
                        V(CONTROLLER_CONTROLLER_RATE), 1.0 / V(STEP_SIZE), ratio,
                        1.0 / ((steps < 1.0 ? 1.0 : steps) * V(STEP_SIZE)));
            return QZS_FMU_ERROR;
        }
        P[QZS_P_CONTROL_STEPS] = steps;
    }
#endif
    return QZS_FMU_OK;
}

#if QZS_FMU_BLOCKS
/* The controller's blocks packed as qzs.engine.prepare.pack_model packs them: the exported
 * ones, each block parameter put in its place (a frequency as 2*pi times it, a discrete
 * period as whole steps, checked), and the linear controller's states at t = 0 into x0. */
static int pack_model(QzsFmu *fmu, double *M, double *x0) {
    memcpy(M, QZS_FMU_MODEL_BASE, sizeof(double) * QZS_N_MODEL);
    for (int i = 0; i < QZS_N_X; i++)
        x0[i] = 0.0;
    for (int i = 0; i < QZS_FMU_N_VARIABLES; i++) {
        int where = QZS_FMU_MODEL[i];
        double value = fmu->values[i];
        if (where < 0)
            continue;
        if (where < QZS_N_MODEL) {
            M[where] = value;
        } else if (where < QZS_FMU_MODEL_INITIAL_STATE) {
            M[where - QZS_FMU_MODEL_TWO_PI] = 2 * 3.141592653589793 * value;
        } else if (where < QZS_FMU_MODEL_SAMPLE_TIME) {
            x0[where - QZS_FMU_MODEL_INITIAL_STATE] = value;
        } else { /* qzs.engine.prepare.pack_model: a whole number of steps */
            double steps = value / V(STEP_SIZE);
            double whole = floor(steps + 0.5);
            if (fabs(steps - whole) > 1e-6 * steps || whole < 1.0) {
                qzs_fmu_log(fmu, QZS_FMU_ERROR,
                            "`%s` = %g s must be a whole number of integration steps "
                            "(step_size = %g s), got %g steps; e.g. %g s",
                            QZS_FMU_NAMES[i], value, V(STEP_SIZE), steps,
                            (whole < 1.0 ? 1.0 : whole) * V(STEP_SIZE));
                return QZS_FMU_ERROR;
            }
            M[QZS_M_LINEAR_STEPS] = whole;
        }
    }
    if (!(M[QZS_M_COMP_FRACTION] >= 0.0 && M[QZS_M_COMP_FRACTION] <= 1.5) ||
        !(M[QZS_M_COMP_DEADBAND] >= 0.0) || !(M[QZS_M_OBSERVER_RATE] >= 0.0) ||
        !(M[QZS_M_COMP_FS] >= 0.0) || !(M[QZS_M_COMP_FC] >= 0.0) ||
        !(M[QZS_M_COMP_CBC] >= 0.0) || !(M[QZS_M_DITHER_OMEGA] >= 0.0)) {
        qzs_fmu_log(fmu, QZS_FMU_ERROR,
                    "the controller's blocks: controller.compensation.fraction must lie in "
                    "[0, 1.5], its deadband, observer bandwidth and friction law and "
                    "controller.dither.frequency must be >= 0; set them so before "
                    "initialisation ends");
        return QZS_FMU_ERROR;
    }
    return QZS_FMU_OK;
}
#endif

#if !QZS_FMU_PLANT_MODE
/* qzs.engine.prepare._blocks_at_start: what the blocks put out at the run's own t = 0 (the
 * real base motion, the payload held, the linear controller's states x), each block by its
 * law (a sampled one's output at the initial state, the observer's estimate 0):
 * compensation, dither and the linear output, a discrete one's C x + D u. */
static void blocks_at_start(const QzsPlant *plant, const QzsOde *s, const QzsBlocks *x,
                            double *f_comp, double *f_dither, double *f_linear) {
    QzsPlant laws = *plant;
    laws.P[QZS_P_CONTROL_STEPS] = 0.0;
    const double none[QZS_N_HELD] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    QzsForces force;
    qzs_rhs_at(&laws, 0.0, s, x, QZS_MODE_STICK, 0.0, none, 0, &force);
    *f_comp = force.compensation;
    *f_dither = force.dither;
    *f_linear = force.linear;
    const double *M = plant->M;
    if (M[QZS_M_LINEAR_STEPS] > 0.0) {
        double u[QZS_N_SENSORS] = {plant->P[QZS_P_ZREF] - s->x[QZS_S_Z], force.v_measured,
                                   force.xdd, force.ydd, 0.0};
        double cx = 0.0, du = 0.0;
        for (int j = 0; j < QZS_NX_MAX; j++)
            cx += M[QZS_M_C + j] * x->x[j];
        for (int k = 0; k < QZS_N_SENSORS; k++)
            du += M[QZS_M_D + k] * u[k];
        *f_linear = cx + du;
    }
}
#endif

/* The initial state, as qzs.engine.prepare._initial_state makes it by default: at rest at the
 * setpoint, the high-pass settled, the linear controller's states x0 (linear.initial_state),
 * the PI preloaded with the static load (worked out with the base at rest) less the rest of
 * the command at the run's own t = 0, the blocks' output with x0 among it (docs/model.md §5,
 * §5.1), stuck if friction can hold the payload. */
static void initial_state(QzsFmu *fmu, const double *x0, double *state, int64_t *flags) {
    const QzsPlant *plant = &fmu->run.plant;
    const double *P = plant->P;
    memset(state, 0, sizeof(double) * QZS_N_STATE);
    memset(flags, 0, sizeof(int64_t) * QZS_N_FLAGS);
    state[QZS_A_MARGIN] = NAN;
    double z0 = V(CONTROLLER_POSITION_SETPOINT);
    QzsOde s;
    for (int j = 0; j < QZS_N_ODE; j++)
        s.x[j] = 0.0;
    s.x[QZS_S_Z] = z0;
    s.x[QZS_S_HP] = qzs_base_motion(plant, 0.0).yd + 0.0;
    double held[QZS_N_HELD] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    QzsBlocks x;
    for (int j = 0; j < QZS_N_X; j++)
        x.x[j] = 0.0;
    QzsForces force;
#if QZS_FMU_PLANT_MODE
    held[QZS_H_MOTOR] = V(MOTOR_FORCE);
    (void)x0;
#else
    qzs_rhs_at(plant, 0.0, &s, &x, QZS_MODE_STICK, 0.0, held, 0, &force);
    double measured = force.v_measured;
    double needed = 0.0;
    if (V(CONTROLLER_PI_KI) > 0.0) {
        QzsPlant at_rest = *plant; /* the base at rest: qzs.engine.prepare._AT_REST */
        double rest[QZS_N_EXCITATION] = {QZS_KIND_SINE, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0};
        memcpy(at_rest.E, rest, sizeof rest);
        qzs_rhs_at(&at_rest, 0.0, &s, &x, QZS_MODE_STICK, 0.0, held, 0, &force);
        double without_motor = force.hold + force.motor;
        double f_max = V(ISOLATOR_MOTOR_FORCE_MAX);
        needed = without_motor < -f_max ? -f_max : (without_motor > f_max ? f_max
                                                                          : without_motor);
    }
    /* linear.initial_state before the PI's preload, which nets its output (C x0 + D u0) */
    for (int j = 0; j < QZS_N_X; j++) /* prepare._preload_linear, as exported */
        x.x[j] = x0[j];
    if (V(CONTROLLER_PI_KI) > 0.0) {
        QzsControllerOutput c = qzs_controller_law(&plant->control, z0, measured, 0.0);
        if (QZS_FMU_BLOCKS) { /* the controller's blocks (not a law's general path) */
            double f_comp, f_dither, f_linear;
            blocks_at_start(plant, &s, &x, &f_comp, &f_dither, &f_linear);
            double blocks = f_comp + f_dither + f_linear;
            s.x[QZS_S_INT] = (needed - c.pi - c.damping - blocks) / V(CONTROLLER_PI_KI);
        } else {
            s.x[QZS_S_INT] = (needed - c.pi - c.damping) / V(CONTROLLER_PI_KI);
        }
    }
    QzsControllerOutput c = qzs_controller_law(&plant->control, z0, measured, s.x[QZS_S_INT]);
    held[QZS_H_PI] = c.pi;
    held[QZS_H_DAMP] = c.damping;
    held[QZS_H_MOTOR] = c.motor;
    if (QZS_FMU_BLOCKS) { /* prepare._hold_blocks: what the sampled blocks put out at t = 0 */
        double f_comp, f_dither, f_linear;
        blocks_at_start(plant, &s, &x, &f_comp, &f_dither, &f_linear);
        held[QZS_H_COMPENSATION] = f_comp;
        held[QZS_H_DITHER] = f_dither;
        if (plant->M[QZS_M_LINEAR_STEPS] > 0.0)
            held[QZS_H_LINEAR] = f_linear;
    }
#endif
    qzs_rhs_at(plant, 0.0, &s, &x, QZS_MODE_STICK, 0.0, held, 0, &force);
    int locked = P[QZS_P_VREG] == 0.0 && fabs(force.hold) <= P[QZS_P_FS];
    flags[QZS_I_MODE] = locked ? QZS_MODE_STICK : QZS_MODE_SLIP;
    flags[QZS_I_DIRECTION] = force.hold > 0.0 ? -1 : 1;
    for (int j = 0; j < QZS_N_ODE; j++)
        state[j] = s.x[j];
    for (int j = 0; j < QZS_N_X; j++)
        state[QZS_A_X0 + j] = x.x[j];
    state[QZS_A_F_PI] = held[QZS_H_PI];
    state[QZS_A_F_DAMP] = held[QZS_H_DAMP];
    state[QZS_A_F_MOTOR] = held[QZS_H_MOTOR];
    state[QZS_A_F_COMPENSATION] = held[QZS_H_COMPENSATION];
    state[QZS_A_F_DITHER] = held[QZS_H_DITHER];
    state[QZS_A_F_LINEAR] = held[QZS_H_LINEAR];
}

/* The outputs: the recorded channels of the run's state at fmu->time. */
static void update_outputs(QzsFmu *fmu) {
    double row[QZS_N_CHANNELS];
    unsigned char row_flags[QZS_N_OUTPUT_FLAGS];
    QzsRun *run = &fmu->run;
    double t = (double)run->step * run->plant.P[QZS_P_DT] + fmu->offset;
    qzs_record(&run->plant, t, &run->s, &run->x, run->mode, run->direction, run->held, row,
               row_flags, run->phase);
    for (int i = 0; i < QZS_FMU_N_VARIABLES; i++) {
        int channel = QZS_FMU_CHANNEL[i];
        if (channel >= 100)
            fmu->values[i] = row_flags[channel - 100] ? 1.0 : 0.0;
        else if (channel >= 0)
            fmu->values[i] = row[channel];
    }
}

#if QZS_FMU_BASE_INPUT
/* The base motion over [t0, t1] from the inputs at t0: displacement, velocity and acceleration
 * as given, the acceleration's slope (the jerk) from the last two acceleration inputs (0 at the
 * first step); one cubic segment of qzs's tabulated excitation. The acceleration is thus
 * extrapolated linearly over a step of h: off by at most h^2 max|d4y/dt4| (5/12 h^3 in velocity,
 * h^4/8 in displacement), and every communication point starts again from the inputs. */
static void hold_base_inputs(QzsFmu *fmu, double t0, double t1) {
    double *table = fmu->table; /* 5 rows of 2 columns: times, then c0..c3 */
    double jerk = 0.0;
    if (fmu->has_previous && t0 > fmu->previous_time)
        jerk = (V(BASE_ACCELERATION) - fmu->previous_acceleration) / (t0 - fmu->previous_time);
    table[0] = t0;
    table[1] = t1;
    table[2] = jerk / 6.0;
    table[4] = 0.5 * V(BASE_ACCELERATION);
    table[6] = V(BASE_VELOCITY);
    table[8] = V(BASE_DISPLACEMENT);
    table[3] = table[5] = table[7] = table[9] = 0.0;
    fmu->previous_time = t0;
    fmu->previous_acceleration = V(BASE_ACCELERATION);
    fmu->has_previous = 1;
}
#endif

static const char *solver_name(int solver) {
    return solver == QZS_SOLVER_EULER ? "euler" : (solver == QZS_SOLVER_RK4 ? "rk4" : "ode3");
}

#if !QZS_FMU_BASE_INPUT
/* The highest frequency [Hz] the internal excitation reaches by `until` [s]: a chirp cut short
 * only that of its end (qzs.model.excitation.highest_frequency). */
static double highest_frequency(QzsFmu *fmu, double until) {
    double f0 = V(EXCITATION_F0), f1 = V(EXCITATION_F1), kind = V(EXCITATION_KIND);
    if (kind == 2.0)
        return f0;
    double fraction = until / V(EXCITATION_DURATION);
    fraction = fraction < 0.0 ? 0.0 : (fraction > 1.0 ? 1.0 : fraction);
    double end = kind == 0.0 ? f0 + (f1 - f0) * fraction : f0 * pow(f1 / f0, fraction);
    return end > f0 ? end : f0;
}
#endif

/* The steps qzs refuses (unstable for this configuration, too coarse for the excitation, a
 * run past a chirp's end), refused; a step above the one the export chose for accuracy,
 * warned of. Returns QZS_FMU_OK, QZS_FMU_WARNING or QZS_FMU_ERROR. */
static int check_step(QzsFmu *fmu, const double *given, const double *law) {
    double dt = V(STEP_SIZE);
    /* qzs_stable_step reads the spring's stiffness as P[A] P[B] (the tanh's peak); another
     * law's peak over the stroke (qzs.engine.stability.spring_stiffness_peak) goes in as a */
    double P[QZS_N_PARAMS];
    memcpy(P, given, sizeof P);
    if (law) {
        P[QZS_P_SPRING_A] = qzs_spring_stiffness_peak(law, P[QZS_P_Z_LOW], P[QZS_P_Z_HIGH]);
        P[QZS_P_SPRING_B] = 1.0;
    }
    int solver = (int)V(SOLVER);
    int closed_loop = !QZS_FMU_PLANT_MODE;
    if (!qzs_stable_step(P, solver, closed_loop, dt)) {
        qzs_fmu_log(fmu, QZS_FMU_ERROR,
                    "`step_size` = %.12g s is too large for a stable %s integration of this "
                    "configuration (stiffest mode: the hard-stop contact or the spring%s loop); "
                    "the largest stable step is %.3g s: lower step_size (or soften "
                    "isolator.stop_stiffness) before initialisation ends",
                    dt, solver_name(solver), closed_loop ? "/PI/damping" : "",
                    qzs_largest_stable_step(P, solver, closed_loop));
        return QZS_FMU_ERROR;
    }
#if !QZS_FMU_BASE_INPUT
    int chirp = V(EXCITATION_KIND) != 2.0;
    double sweep = V(EXCITATION_DURATION);
    if (chirp && fmu->stop_defined && fmu->stop_time > sweep * (1.0 + 1e-12)) {
        qzs_fmu_log(fmu, QZS_FMU_ERROR,
                    "the stop time %.12g s is past the chirp's end, `excitation.duration` = "
                    "%.12g s (qzs runs no chirp past its sweep); stop at or before it, or "
                    "lengthen excitation.duration", fmu->stop_time, sweep);
        return QZS_FMU_ERROR;
    }
    double top = highest_frequency(fmu, fmu->stop_defined ? fmu->stop_time : sweep);
    if (top > 0.0 && dt > 1.0 / (QZS_FMU_MIN_STEPS_PER_PERIOD * top) * (1.0 + 1e-9)) {
        qzs_fmu_log(fmu, QZS_FMU_ERROR,
                    "`step_size` = %.12g s resolves the excitation's %g Hz with fewer than %d "
                    "steps per period; lower step_size to %.3g s or less",
                    dt, top, QZS_FMU_MIN_STEPS_PER_PERIOD,
                    1.0 / (QZS_FMU_MIN_STEPS_PER_PERIOD * top));
        return QZS_FMU_ERROR;
    }
#endif
    if (dt > QZS_FMU_EXPORTED_STEP * (1.0 + 1e-9)) {
        if (QZS_FMU_STEP_CHOSEN)
            qzs_fmu_log(fmu, QZS_FMU_WARNING,
                        "`step_size` = %.12g s is above the %.12g s qzs chose at export for "
                        "accuracy (%s) for the exported parameters: the results may be less "
                        "accurate than that; stable up to %.3g s", dt, QZS_FMU_EXPORTED_STEP,
                        QZS_FMU_STEP_HOW, qzs_largest_stable_step(P, solver, closed_loop));
        else
            qzs_fmu_log(fmu, QZS_FMU_WARNING,
                        "`step_size` = %.12g s is above the %.12g s given at export, and neither "
                        "was chosen for accuracy (export without a literal step to have one "
                        "chosen: qzs export fmu without --dt, qzs.export_fmu with step=chosen); "
                        "stable up to %.3g s",
                        dt, QZS_FMU_EXPORTED_STEP,
                        qzs_largest_stable_step(P, solver, closed_loop));
        return QZS_FMU_WARNING;
    }
    return QZS_FMU_OK;
}

int qzs_fmu_initialize(QzsFmu *fmu) {
    if (fmu->initialized)
        return QZS_FMU_OK;
    if (fmu->start_time != 0.0) {
        qzs_fmu_log(fmu, QZS_FMU_ERROR, "the start time must be 0 s (qzs runs start at t = 0), "
                    "got %g s", fmu->start_time);
        return QZS_FMU_ERROR;
    }
    if (fmu->stop_defined && !(fmu->stop_time > 0.0)) {
        qzs_fmu_log(fmu, QZS_FMU_ERROR, "the stop time must be after the start time 0 s, got "
                    "%g s", fmu->stop_time);
        return QZS_FMU_ERROR;
    }
    if (check_parameters(fmu) != QZS_FMU_OK)
        return QZS_FMU_ERROR;
    double P[QZS_N_PARAMS];
    if (pack_parameters(fmu, P) != QZS_FMU_OK)
        return QZS_FMU_ERROR;
    /* the model row: the blocks (below) and the spring law, the tanh's [0, a, b] by default */
    double *M = fmu->model, *law = fmu->model + QZS_N_MODEL;
    memset(M, 0, sizeof(double) * QZS_N_MODEL);
#if QZS_FMU_SPRING_LAW != QZS_SPRING_TANH
    if (pack_spring(fmu, law) != QZS_FMU_OK)
        return QZS_FMU_ERROR;
    int general = 1;
#else
    law[0] = QZS_SPRING_TANH;
    law[1] = P[QZS_P_SPRING_A];
    law[2] = P[QZS_P_SPRING_B];
    int general = QZS_FMU_BLOCKS;
#endif
    int status = check_step(fmu, P, law[0] != QZS_SPRING_TANH ? law : NULL);
    if (status == QZS_FMU_ERROR)
        return QZS_FMU_ERROR;
    double z0 = V(CONTROLLER_POSITION_SETPOINT);
    if (!(P[QZS_P_Z_LOW] <= z0 && z0 <= P[QZS_P_Z_HIGH])) {
        qzs_fmu_log(fmu, QZS_FMU_ERROR, "the initial position (position_setpoint = %g m) must "
                    "lie between the stops [%g, %g] m; move it or the stops (stop_center)", z0,
                    P[QZS_P_Z_LOW], P[QZS_P_Z_HIGH]);
        return QZS_FMU_ERROR;
    }
    double E[QZS_N_EXCITATION] = {0.0};
#if QZS_FMU_BASE_INPUT
    E[QZS_E_KIND] = QZS_KIND_TABLE;
    hold_base_inputs(fmu, 0.0, V(STEP_SIZE));
    fmu->has_previous = 0; /* initialisation is no communication point */
#else
    E[QZS_E_KIND] = V(EXCITATION_KIND);
    E[QZS_E_AMPLITUDE] = V(EXCITATION_AMPLITUDE);
    E[QZS_E_F0] = V(EXCITATION_F0);
    E[QZS_E_F1] = V(EXCITATION_F1);
    E[QZS_E_DURATION] = V(EXCITATION_DURATION);
    E[QZS_E_PHASE] = V(EXCITATION_PHASE);
    E[QZS_E_FADE] = V(EXCITATION_FADE_IN);
#endif
    double x0[QZS_N_X] = {0.0};
#if QZS_FMU_BLOCKS
    if (pack_model(fmu, M, x0) != QZS_FMU_OK)
        return QZS_FMU_ERROR;
#endif
    qzs_plant_init(&fmu->run.plant, P, general ? M : NULL, E, fmu->table, 2);
    double state[QZS_N_STATE];
    int64_t flags[QZS_N_FLAGS];
    initial_state(fmu, x0, state, flags);
    qzs_run_start(&fmu->run, (int)V(SOLVER), state, flags);
#if QZS_FMU_PLANT_MODE
    fmu->run.sampled = 0;
#endif
    fmu->offset = 0.0;
    fmu->initialized = 1;
    update_outputs(fmu);
    return status;
}

/* Where t [s] lies on the grid of internal steps: the grid point at or before it (*index) and
 * how far past it (*offset, in [0, dt)); a time within a millionth of a step of a grid point is
 * that point, as a whole number of steps summed in floating point lands there. */
static void on_grid(double t, double dt, int64_t *index, double *offset) {
    double cells = t / dt;
    double nearest = floor(cells + 0.5);
    if (fabs(cells - nearest) <= 1e-6 + 4.0 * DBL_EPSILON * cells) {
        *index = (int64_t)nearest;
        *offset = 0.0;
    } else {
        *index = (int64_t)floor(cells);
        *offset = t - (double)*index * dt;
    }
}

int qzs_fmu_do_step(QzsFmu *fmu, double current, double step) {
    if (!fmu->initialized) {
        qzs_fmu_log(fmu, QZS_FMU_ERROR, "doStep before initialisation ended");
        return QZS_FMU_ERROR;
    }
    if (fmu->failed) {
        qzs_fmu_log(fmu, QZS_FMU_ERROR, "doStep after a failed step; reset or free the FMU");
        return QZS_FMU_ERROR;
    }
    QzsRun *run = &fmu->run;
    double dt = run->plant.P[QZS_P_DT];
    if (!(step > 0.0) || !isfinite(step)) {
        qzs_fmu_log(fmu, QZS_FMU_ERROR, "the communication step %.12g s must be positive",
                    step);
        return QZS_FMU_ERROR;
    }
    if (fabs(current - fmu->time) > 1e-9 * (dt + fabs(current))) {
        qzs_fmu_log(fmu, QZS_FMU_ERROR, "the communication point %.17g s is not the FMU's "
                    "time %.17g s", current, fmu->time);
        return QZS_FMU_ERROR;
    }
    double end = current + step;
    if (fmu->stop_defined && end > fmu->stop_time + 1e-6 * dt) {
        qzs_fmu_log(fmu, QZS_FMU_ERROR, "doStep from %.12g s by %.12g s goes past the stop time "
                    "%.12g s the experiment set; step to the stop time at most", current, step,
                    fmu->stop_time);
        return QZS_FMU_ERROR;
    }
#if !QZS_FMU_BASE_INPUT
    double sweep = V(EXCITATION_DURATION);
    if (V(EXCITATION_KIND) != 2.0 && end > sweep * (1.0 + 1e-12) + 1e-6 * dt) {
        qzs_fmu_log(fmu, QZS_FMU_ERROR, "doStep from %.12g s by %.12g s goes past the chirp's "
                    "end, `excitation.duration` = %.12g s (qzs runs no chirp past its sweep)",
                    current, step, sweep);
        return QZS_FMU_ERROR;
    }
#endif
    int64_t end_index;
    double end_offset;
    on_grid(end, dt, &end_index, &end_offset);
#if QZS_FMU_PLANT_MODE
    run->held[2] = V(MOTOR_FORCE);
    run->margin = NAN; /* the held force may have changed: the holding margin too */
#endif
#if QZS_FMU_BASE_INPUT
    hold_base_inputs(fmu, (double)run->step * dt + fmu->offset,
                     (double)end_index * dt + end_offset);
    run->margin = NAN; /* the base motion is a new segment */
#endif
    int status = QZS_STATUS_OK;
    while (status == QZS_STATUS_OK &&
           (run->step < end_index || (run->step == end_index && fmu->offset < end_offset))) {
        if (fmu->offset > 0.0 || run->step == end_index) { /* part of a grid step */
            double to = run->step < end_index ? dt : end_offset;
            status = qzs_run_part(run, fmu->offset, to);
            fmu->offset = to < dt ? to : 0.0;
        } else { /* whole grid steps, as qzs takes them */
            status = qzs_run_steps(run, end_index - run->step, 0, NULL, NULL, NULL);
        }
    }
    if (status == QZS_STATUS_OUTSIDE) {
        const double *law = run->plant.spring;
        long n = (long)law[QZS_TABLE_COUNT];
        fmu->time = (double)run->step * dt + fmu->offset;
        fmu->failed = 1;
        qzs_fmu_log(fmu, QZS_FMU_ERROR, "the run stopped at t = %.12g s: the payload left the "
                    "spring table [%g, %g] m (last position inside z = %g m, moving at v = %g "
                    "m/s), and the table refuses positions outside it (spring.outside = 0); "
                    "measure the curve over the whole stroke and a margin for the stops' "
                    "penetration, or set spring.outside = 1 (linear beyond the ends)", fmu->time,
                    law[QZS_TABLE_POSITIONS], law[QZS_TABLE_POSITIONS + n - 1],
                    run->s.x[QZS_S_Z], run->s.x[QZS_S_V]);
        return QZS_FMU_ERROR;
    }
    if (status != QZS_STATUS_OK) {
        fmu->time = (double)run->step * dt + fmu->offset;
        fmu->failed = 1;
        qzs_fmu_log(fmu, QZS_FMU_ERROR, "the state diverged at t = %.12g s (z = %g m, v = %g "
                    "m/s); the step is too large for this configuration: lower step_size",
                    fmu->time, run->s.x[QZS_S_Z], run->s.x[QZS_S_V]);
        return QZS_FMU_ERROR;
    }
    fmu->time = end; /* the importer's time; the grid's is within a millionth of a step of it */
    update_outputs(fmu);
    return QZS_FMU_OK;
}
