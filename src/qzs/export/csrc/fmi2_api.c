/* qzs: the FMI 2.0 co-simulation interface of the isolator FMU, around qzs_fmu.c.
 *
 * Compiled against the FMI 2.0 headers of the standard's distribution (fmi2Functions.h and
 * the headers it includes; qzs takes them from FMPy's copy at export, an importer uses its
 * own). Only co-simulation is offered; model exchange, FMU states and derivatives are
 * refused with fmi2Error and a logged reason.
 */
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "qzs_fmu.h"

typedef struct {
    QzsFmu fmu;
    fmi2CallbackFunctions callbacks;
    int logging;
    char *name;
} Instance;

/* The FMI 2 logger takes a printf format: the message goes as one, its '%' doubled, so that
 * an importer that does not format (a Python callback) still reads it whole. */
static void logger(void *environment, int status, const char *category, const char *message) {
    Instance *instance = (Instance *)environment;
    char format[2048];
    size_t j = 0;
    if (!instance->callbacks.logger || (status == QZS_FMU_OK && !instance->logging))
        return;
    for (size_t i = 0; message[i] && j + 2 < sizeof format; i++) {
        if (message[i] == '%')
            format[j++] = '%';
        format[j++] = message[i];
    }
    format[j] = '\0';
    instance->callbacks.logger(instance->callbacks.componentEnvironment, instance->name,
                               (fmi2Status)status, category, format);
}

static fmi2Status refuse(fmi2Component c, const char *what) {
    if (c)
        qzs_fmu_log(&((Instance *)c)->fmu, QZS_FMU_ERROR, "%s is not supported by this FMU "
                    "(co-simulation only, no FMU states or derivatives)", what);
    return fmi2Error;
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }

const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
    (void)nCategories;
    (void)categories;
    ((Instance *)c)->logging = loggingOn;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                              fmi2Boolean loggingOn) {
    (void)fmuResourceLocation; (void)visible;
    const char *name = instanceName ? instanceName : "";
    if (!functions || !functions->logger)
        return NULL;
    if (fmuType != fmi2CoSimulation) {
        functions->logger(functions->componentEnvironment, name, fmi2Error, "logStatusError",
                          "model exchange is not supported by this FMU (co-simulation only)");
        return NULL;
    }
    if (!fmuGUID || strcmp(fmuGUID, QZS_FMU_TOKEN) != 0) {
        functions->logger(functions->componentEnvironment, name, fmi2Error, "logStatusError",
                          "the GUID is not this FMU's " QZS_FMU_TOKEN);
        return NULL;
    }
    Instance *instance = (Instance *)calloc(1, sizeof(Instance));
    if (!instance)
        return NULL;
    instance->callbacks = *functions;
    instance->logging = loggingOn;
    instance->name = (char *)malloc(strlen(name) + 1);
    if (instance->name)
        strcpy(instance->name, name);
    instance->fmu.log = logger;
    instance->fmu.environment = instance;
    qzs_fmu_reset(&instance->fmu, 0.0);
    return instance;
}

void fmi2FreeInstance(fmi2Component c) {
    if (!c)
        return;
    free(((Instance *)c)->name);
    free(c);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined,
                               fmi2Real stopTime) {
    (void)toleranceDefined; (void)tolerance;
    qzs_fmu_setup(&((Instance *)c)->fmu, startTime, stopTimeDefined, stopTime);
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) { (void)c; return fmi2OK; }

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    return (fmi2Status)qzs_fmu_initialize(&((Instance *)c)->fmu);
}

fmi2Status fmi2Terminate(fmi2Component c) { (void)c; return fmi2OK; }

fmi2Status fmi2Reset(fmi2Component c) {
    qzs_fmu_reset(&((Instance *)c)->fmu, 0.0);
    return fmi2OK;
}

static fmi2Status get_values(fmi2Component c, const fmi2ValueReference vr[], size_t n, char type,
                             double *values) {
    QzsFmu *fmu = &((Instance *)c)->fmu;
    for (size_t i = 0; i < n; i++)
        if (qzs_fmu_get(fmu, vr[i], type, &values[i]) != QZS_FMU_OK)
            return fmi2Error;
    return fmi2OK;
}

/* Set all or nothing: every value checked on a copy first. */
static fmi2Status set_values(fmi2Component c, const fmi2ValueReference vr[], size_t n, char type,
                             const double *values) {
    QzsFmu *fmu = &((Instance *)c)->fmu;
    double saved[QZS_FMU_N_VARIABLES];
    memcpy(saved, fmu->values, sizeof saved);
    for (size_t i = 0; i < n; i++) {
        if (qzs_fmu_set(fmu, vr[i], type, values[i]) != QZS_FMU_OK) {
            memcpy(fmu->values, saved, sizeof saved);
            return fmi2Error;
        }
    }
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       fmi2Real value[]) {
    return get_values(c, vr, nvr, 'F', value);
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Integer value[]) {
    for (size_t i = 0; i < nvr; i++) {
        double v;
        if (get_values(c, &vr[i], 1, 'I', &v) != fmi2OK)
            return fmi2Error;
        value[i] = (fmi2Integer)v;
    }
    return fmi2OK;
}

fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          fmi2Boolean value[]) {
    for (size_t i = 0; i < nvr; i++) {
        double v;
        if (get_values(c, &vr[i], 1, 'B', &v) != fmi2OK)
            return fmi2Error;
        value[i] = v != 0.0;
    }
    return fmi2OK;
}

fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         fmi2String value[]) {
    (void)vr; (void)nvr; (void)value;
    return refuse(c, "fmi2GetString (the FMU has no String variable)");
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[]) {
    return set_values(c, vr, nvr, 'F', value);
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Integer value[]) {
    double converted[QZS_FMU_N_VARIABLES];
    if (nvr > QZS_FMU_N_VARIABLES)
        return refuse(c, "setting more variables than the FMU has");
    for (size_t i = 0; i < nvr; i++)
        converted[i] = value[i];
    return set_values(c, vr, nvr, 'I', converted);
}

fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                          const fmi2Boolean value[]) {
    (void)vr; (void)nvr; (void)value;
    return refuse(c, "setting a Boolean (the FMU has Boolean outputs only)");
}

fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                         const fmi2String value[]) {
    (void)vr; (void)nvr; (void)value;
    return refuse(c, "fmi2SetString (the FMU has no String variable)");
}

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *state) {
    (void)state;
    return refuse(c, "fmi2GetFMUstate");
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) {
    (void)state;
    return refuse(c, "fmi2SetFMUstate");
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state) {
    (void)state;
    return refuse(c, "fmi2FreeFMUstate");
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t *size) {
    (void)state; (void)size;
    return refuse(c, "fmi2SerializedFMUstateSize");
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state, fmi2Byte bytes[],
                                 size_t size) {
    (void)state; (void)bytes; (void)size;
    return refuse(c, "fmi2SerializeFMUstate");
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size,
                                   fmi2FMUstate *state) {
    (void)bytes; (void)size; (void)state;
    return refuse(c, "fmi2DeSerializeFMUstate");
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference unknown[],
                                        size_t nUnknown, const fmi2ValueReference known[],
                                        size_t nKnown, const fmi2Real dvKnown[],
                                        fmi2Real dvUnknown[]) {
    (void)unknown; (void)nUnknown; (void)known; (void)nKnown; (void)dvKnown; (void)dvUnknown;
    return refuse(c, "fmi2GetDirectionalDerivative");
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                       size_t nvr, const fmi2Integer order[],
                                       const fmi2Real value[]) {
    (void)vr; (void)nvr; (void)order; (void)value;
    return refuse(c, "fmi2SetRealInputDerivatives (canInterpolateInputs = false)");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
                                        size_t nvr, const fmi2Integer order[],
                                        fmi2Real value[]) {
    (void)vr; (void)nvr; (void)order; (void)value;
    return refuse(c, "fmi2GetRealOutputDerivatives (maxOutputDerivativeOrder = 0)");
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                      fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    (void)noSetFMUStatePriorToCurrentPoint;
    return (fmi2Status)qzs_fmu_do_step(&((Instance *)c)->fmu, currentCommunicationPoint,
                                       communicationStepSize);
}

fmi2Status fmi2CancelStep(fmi2Component c) {
    return refuse(c, "fmi2CancelStep (doStep never returns pending)");
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    (void)s; (void)value;
    return refuse(c, "fmi2GetStatus (doStep never returns pending)");
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    if (s == fmi2LastSuccessfulTime) {
        *value = ((Instance *)c)->fmu.time;
        return fmi2OK;
    }
    return refuse(c, "fmi2GetRealStatus of this kind");
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    (void)s; (void)value;
    return refuse(c, "fmi2GetIntegerStatus");
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    if (s == fmi2Terminated) {
        *value = fmi2False;
        return fmi2OK;
    }
    return refuse(c, "fmi2GetBooleanStatus of this kind");
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    (void)s; (void)value;
    return refuse(c, "fmi2GetStringStatus");
}

/* Model exchange: declared by the standard's header, refused here. */
fmi2Status fmi2EnterEventMode(fmi2Component c) { return refuse(c, "model exchange"); }

fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *eventInfo) {
    (void)eventInfo;
    return refuse(c, "model exchange");
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) { return refuse(c, "model exchange"); }

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c,
                                       fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi2Boolean *enterEventMode,
                                       fmi2Boolean *terminateSimulation) {
    (void)noSetFMUStatePriorToCurrentPoint; (void)enterEventMode; (void)terminateSimulation;
    return refuse(c, "model exchange");
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time) {
    (void)time;
    return refuse(c, "model exchange");
}

#define UNSUPPORTED_STATES(Name, Const)                                                      \
    fmi2Status fmi2##Name(fmi2Component c, Const fmi2Real values[], size_t n) {              \
        (void)values; (void)n;                                                               \
        return refuse(c, "model exchange");                                                  \
    }

UNSUPPORTED_STATES(SetContinuousStates, const)
UNSUPPORTED_STATES(GetDerivatives, )
UNSUPPORTED_STATES(GetEventIndicators, )
UNSUPPORTED_STATES(GetContinuousStates, )
UNSUPPORTED_STATES(GetNominalsOfContinuousStates, )
