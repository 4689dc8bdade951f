/* qzs: the FMI 3.0 co-simulation interface of the isolator FMU, around qzs_fmu.c.
 *
 * Compiled against the FMI 3.0 headers of the standard's distribution (fmi3Functions.h and
 * the headers it includes; qzs takes them from FMPy's copy at export, an importer uses its
 * own). Only co-simulation is offered; the other interface types, clocks, FMU states and
 * derivatives are refused with fmi3Error and a logged reason.
 */
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"
#include "qzs_fmu.h"

typedef struct {
    QzsFmu fmu;
    fmi3LogMessageCallback log;
    fmi3InstanceEnvironment environment;
    int logging;
    int in_initialization;
    char *name;
} Instance;

static void logger(void *environment, int status, const char *category, const char *message) {
    Instance *instance = (Instance *)environment;
    if (instance->log && (status != QZS_FMU_OK || instance->logging))
        instance->log(instance->environment, (fmi3Status)status, category, message);
}

static fmi3Status refuse(fmi3Instance handle, const char *what) {
    Instance *instance = (Instance *)handle;
    if (instance)
        qzs_fmu_log(&instance->fmu, QZS_FMU_ERROR, "%s is not supported by this FMU "
                    "(co-simulation only, no clocks, FMU states or derivatives)", what);
    return fmi3Error;
}

const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[]) {
    (void)nCategories;
    (void)categories;
    ((Instance *)instance)->logging = loggingOn;
    return fmi3OK;
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String token,
                                          fmi3String resourcePath, fmi3Boolean visible,
                                          fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment environment,
                                          fmi3LogMessageCallback logMessage) {
    (void)instanceName; (void)token; (void)resourcePath; (void)visible; (void)loggingOn;
    if (logMessage)
        logMessage(environment, fmi3Error, "logStatusError",
                   "model exchange is not supported by this FMU (co-simulation only)");
    return NULL;
}

fmi3Instance fmi3InstantiateScheduledExecution(
    fmi3String instanceName, fmi3String token, fmi3String resourcePath, fmi3Boolean visible,
    fmi3Boolean loggingOn, fmi3InstanceEnvironment environment, fmi3LogMessageCallback logMessage,
    fmi3ClockUpdateCallback clockUpdate, fmi3LockPreemptionCallback lockPreemption,
    fmi3UnlockPreemptionCallback unlockPreemption) {
    (void)instanceName; (void)token; (void)resourcePath; (void)visible; (void)loggingOn;
    (void)clockUpdate; (void)lockPreemption; (void)unlockPreemption;
    if (logMessage)
        logMessage(environment, fmi3Error, "logStatusError",
                   "scheduled execution is not supported by this FMU (co-simulation only)");
    return NULL;
}

fmi3Instance fmi3InstantiateCoSimulation(
    fmi3String instanceName, fmi3String token, fmi3String resourcePath, fmi3Boolean visible,
    fmi3Boolean loggingOn, fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
    const fmi3ValueReference requiredIntermediateVariables[],
    size_t nRequiredIntermediateVariables, fmi3InstanceEnvironment environment,
    fmi3LogMessageCallback logMessage, fmi3IntermediateUpdateCallback intermediateUpdate) {
    (void)resourcePath; (void)visible; (void)earlyReturnAllowed;
    (void)requiredIntermediateVariables; (void)nRequiredIntermediateVariables;
    (void)intermediateUpdate;
    if (!token || strcmp(token, QZS_FMU_TOKEN) != 0) {
        if (logMessage)
            logMessage(environment, fmi3Error, "logStatusError",
                       "the instantiation token is not this FMU's " QZS_FMU_TOKEN);
        return NULL;
    }
    if (eventModeUsed) {
        if (logMessage)
            logMessage(environment, fmi3Error, "logStatusError",
                       "event mode is not supported (hasEventMode = false)");
        return NULL;
    }
    Instance *instance = (Instance *)calloc(1, sizeof(Instance));
    if (!instance)
        return NULL;
    instance->log = logMessage;
    instance->environment = environment;
    instance->logging = loggingOn;
    instance->name = (char *)malloc(strlen(instanceName ? instanceName : "") + 1);
    if (instance->name)
        strcpy(instance->name, instanceName ? instanceName : "");
    instance->fmu.log = logger;
    instance->fmu.environment = instance;
    qzs_fmu_reset(&instance->fmu, 0.0);
    return instance;
}

void fmi3FreeInstance(fmi3Instance instance) {
    if (!instance)
        return;
    free(((Instance *)instance)->name);
    free(instance);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance handle, fmi3Boolean toleranceDefined,
                                       fmi3Float64 tolerance, fmi3Float64 startTime,
                                       fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    (void)toleranceDefined; (void)tolerance;
    Instance *instance = (Instance *)handle;
    qzs_fmu_setup(&instance->fmu, startTime, stopTimeDefined, stopTime);
    instance->in_initialization = 1;
    return fmi3OK;
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance handle) {
    Instance *instance = (Instance *)handle;
    instance->in_initialization = 0;
    return (fmi3Status)qzs_fmu_initialize(&instance->fmu);
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance) { return refuse(instance, "event mode"); }

fmi3Status fmi3Terminate(fmi3Instance instance) { (void)instance; return fmi3OK; }

fmi3Status fmi3Reset(fmi3Instance handle) {
    qzs_fmu_reset(&((Instance *)handle)->fmu, 0.0);
    return fmi3OK;
}

static fmi3Status get_values(fmi3Instance handle, const fmi3ValueReference refs[], size_t n,
                             char type, double *values) {
    QzsFmu *fmu = &((Instance *)handle)->fmu;
    for (size_t i = 0; i < n; i++)
        if (qzs_fmu_get(fmu, refs[i], type, &values[i]) != QZS_FMU_OK)
            return fmi3Error;
    return fmi3OK;
}

/* Set all or nothing: every value checked on a copy first. */
static fmi3Status set_values(fmi3Instance handle, const fmi3ValueReference refs[], size_t n,
                             char type, const double *values) {
    QzsFmu *fmu = &((Instance *)handle)->fmu;
    double saved[QZS_FMU_N_VARIABLES];
    memcpy(saved, fmu->values, sizeof saved);
    for (size_t i = 0; i < n; i++) {
        if (qzs_fmu_set(fmu, refs[i], type, values[i]) != QZS_FMU_OK) {
            memcpy(fmu->values, saved, sizeof saved);
            return fmi3Error;
        }
    }
    return fmi3OK;
}

/* The value references of a Float64 access, each array's elements after its own (an array
 * holds its elements at the references after its first: qzs_fmu_variables.h), into
 * `elements`; refused if they do not hold nValues values. */
static fmi3Status float64_elements(fmi3Instance handle, const fmi3ValueReference refs[],
                                   size_t n, size_t nValues, fmi3ValueReference *elements) {
    QzsFmu *fmu = &((Instance *)handle)->fmu;
    if (nValues > QZS_FMU_N_VARIABLES)
        return refuse(handle, "accessing more Float64 values than the FMU has");
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        size_t size;
        if (qzs_fmu_size(fmu, refs[i], &size) != QZS_FMU_OK)
            return fmi3Error;
        for (size_t j = 0; j < size; j++, k++)
            if (k < nValues)
                elements[k] = refs[i] + (fmi3ValueReference)j;
    }
    if (k != nValues) {
        qzs_fmu_log(fmu, QZS_FMU_ERROR, "the %zu value references hold %zu Float64 values, "
                    "not the %zu given", n, k, nValues);
        return fmi3Error;
    }
    return fmi3OK;
}

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference refs[], size_t n,
                          fmi3Float64 values[], size_t nValues) {
    fmi3ValueReference elements[QZS_FMU_N_VARIABLES];
    if (float64_elements(instance, refs, n, nValues, elements) != fmi3OK)
        return fmi3Error;
    return get_values(instance, elements, nValues, 'F', values);
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference refs[], size_t n,
                          const fmi3Float64 values[], size_t nValues) {
    fmi3ValueReference elements[QZS_FMU_N_VARIABLES];
    if (float64_elements(instance, refs, n, nValues, elements) != fmi3OK)
        return fmi3Error;
    return set_values(instance, elements, nValues, 'F', values);
}

fmi3Status fmi3GetInt32(fmi3Instance instance, const fmi3ValueReference refs[], size_t n,
                        fmi3Int32 values[], size_t nValues) {
    (void)nValues;
    for (size_t i = 0; i < n; i++) {
        double value;
        if (get_values(instance, &refs[i], 1, 'I', &value) != fmi3OK)
            return fmi3Error;
        values[i] = (fmi3Int32)value;
    }
    return fmi3OK;
}

fmi3Status fmi3SetInt32(fmi3Instance instance, const fmi3ValueReference refs[], size_t n,
                        const fmi3Int32 values[], size_t nValues) {
    (void)nValues;
    double converted[QZS_FMU_N_VARIABLES];
    if (n > QZS_FMU_N_VARIABLES)
        return refuse(instance, "setting more variables than the FMU has");
    for (size_t i = 0; i < n; i++)
        converted[i] = values[i];
    return set_values(instance, refs, n, 'I', converted);
}

fmi3Status fmi3GetBoolean(fmi3Instance instance, const fmi3ValueReference refs[], size_t n,
                          fmi3Boolean values[], size_t nValues) {
    (void)nValues;
    for (size_t i = 0; i < n; i++) {
        double value;
        if (get_values(instance, &refs[i], 1, 'B', &value) != fmi3OK)
            return fmi3Error;
        values[i] = value != 0.0;
    }
    return fmi3OK;
}

fmi3Status fmi3SetBoolean(fmi3Instance instance, const fmi3ValueReference refs[], size_t n,
                          const fmi3Boolean values[], size_t nValues) {
    (void)refs; (void)n; (void)values; (void)nValues;
    return refuse(instance, "setting a Boolean (the FMU has Boolean outputs only)");
}

#define UNSUPPORTED_ACCESS(Name, Type, Const)                                                 \
    fmi3Status fmi3##Name(fmi3Instance instance, const fmi3ValueReference refs[], size_t n,  \
                          Const Type values[], size_t nValues) {                              \
        (void)refs; (void)n; (void)values; (void)nValues;                                     \
        return refuse(instance, "fmi3" #Name " (the FMU has Float64, Int32 and Boolean "     \
                                "variables only)");                                          \
    }

UNSUPPORTED_ACCESS(GetFloat32, fmi3Float32, )
UNSUPPORTED_ACCESS(GetInt8, fmi3Int8, )
UNSUPPORTED_ACCESS(GetUInt8, fmi3UInt8, )
UNSUPPORTED_ACCESS(GetInt16, fmi3Int16, )
UNSUPPORTED_ACCESS(GetUInt16, fmi3UInt16, )
UNSUPPORTED_ACCESS(GetUInt32, fmi3UInt32, )
UNSUPPORTED_ACCESS(GetInt64, fmi3Int64, )
UNSUPPORTED_ACCESS(GetUInt64, fmi3UInt64, )
UNSUPPORTED_ACCESS(GetString, fmi3String, )
UNSUPPORTED_ACCESS(SetFloat32, fmi3Float32, const)
UNSUPPORTED_ACCESS(SetInt8, fmi3Int8, const)
UNSUPPORTED_ACCESS(SetUInt8, fmi3UInt8, const)
UNSUPPORTED_ACCESS(SetInt16, fmi3Int16, const)
UNSUPPORTED_ACCESS(SetUInt16, fmi3UInt16, const)
UNSUPPORTED_ACCESS(SetUInt32, fmi3UInt32, const)
UNSUPPORTED_ACCESS(SetInt64, fmi3Int64, const)
UNSUPPORTED_ACCESS(SetUInt64, fmi3UInt64, const)
UNSUPPORTED_ACCESS(SetString, fmi3String, const)

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference refs[], size_t n,
                         size_t valueSizes[], fmi3Binary values[], size_t nValues) {
    (void)refs; (void)n; (void)valueSizes; (void)values; (void)nValues;
    return refuse(instance, "fmi3GetBinary");
}

fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference refs[], size_t n,
                         const size_t valueSizes[], const fmi3Binary values[], size_t nValues) {
    (void)refs; (void)n; (void)valueSizes; (void)values; (void)nValues;
    return refuse(instance, "fmi3SetBinary");
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference refs[], size_t n,
                        fmi3Clock values[]) {
    (void)refs; (void)n; (void)values;
    return refuse(instance, "fmi3GetClock");
}

fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference refs[], size_t n,
                        const fmi3Clock values[]) {
    (void)refs; (void)n; (void)values;
    return refuse(instance, "fmi3SetClock");
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference ref,
                                               size_t *n) {
    (void)ref; (void)n;
    return refuse(instance, "fmi3GetNumberOfVariableDependencies");
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[],
                                       fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[],
                                       fmi3DependencyKind dependencyKinds[], size_t n) {
    (void)dependent; (void)elementIndicesOfDependent; (void)independents;
    (void)elementIndicesOfIndependents; (void)dependencyKinds; (void)n;
    return refuse(instance, "fmi3GetVariableDependencies");
}

fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *state) {
    (void)state;
    return refuse(instance, "fmi3GetFMUState");
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState state) {
    (void)state;
    return refuse(instance, "fmi3SetFMUState");
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *state) {
    (void)state;
    return refuse(instance, "fmi3FreeFMUState");
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState state, size_t *size) {
    (void)state; (void)size;
    return refuse(instance, "fmi3SerializedFMUStateSize");
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState state,
                                 fmi3Byte serializedState[], size_t size) {
    (void)state; (void)serializedState; (void)size;
    return refuse(instance, "fmi3SerializeFMUState");
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[],
                                   size_t size, fmi3FMUState *state) {
    (void)serializedState; (void)size; (void)state;
    return refuse(instance, "fmi3DeserializeFMUState");
}

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference u[],
                                        size_t nu, const fmi3ValueReference k[], size_t nk,
                                        const fmi3Float64 seed[], size_t nSeed,
                                        fmi3Float64 sensitivity[], size_t nSensitivity) {
    (void)u; (void)nu; (void)k; (void)nk; (void)seed; (void)nSeed; (void)sensitivity;
    (void)nSensitivity;
    return refuse(instance, "fmi3GetDirectionalDerivative");
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference u[],
                                    size_t nu, const fmi3ValueReference k[], size_t nk,
                                    const fmi3Float64 seed[], size_t nSeed,
                                    fmi3Float64 sensitivity[], size_t nSensitivity) {
    (void)u; (void)nu; (void)k; (void)nk; (void)seed; (void)nSeed; (void)sensitivity;
    (void)nSensitivity;
    return refuse(instance, "fmi3GetAdjointDerivative");
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance) {
    return refuse(instance, "configuration mode (the FMU has no structural parameters)");
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance) {
    return refuse(instance, "configuration mode (the FMU has no structural parameters)");
}

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance) {
    return refuse(instance, "fmi3EvaluateDiscreteStates");
}

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation,
                                    fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged,
                                    fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime) {
    (void)discreteStatesNeedUpdate; (void)terminateSimulation;
    (void)nominalsOfContinuousStatesChanged; (void)valuesOfContinuousStatesChanged;
    (void)nextEventTimeDefined; (void)nextEventTime;
    return refuse(instance, "fmi3UpdateDiscreteStates");
}

fmi3Status fmi3EnterStepMode(fmi3Instance instance) { (void)instance; return fmi3OK; }

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference refs[],
                                    size_t n, const fmi3Int32 orders[], fmi3Float64 values[],
                                    size_t nValues) {
    (void)refs; (void)n; (void)orders; (void)values; (void)nValues;
    return refuse(instance, "fmi3GetOutputDerivatives");
}

fmi3Status fmi3DoStep(fmi3Instance handle, fmi3Float64 currentCommunicationPoint,
                      fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                      fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation,
                      fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime) {
    (void)noSetFMUStatePriorToCurrentPoint;
    Instance *instance = (Instance *)handle;
    int status = qzs_fmu_do_step(&instance->fmu, currentCommunicationPoint,
                                 communicationStepSize);
    if (eventHandlingNeeded)
        *eventHandlingNeeded = fmi3False;
    if (terminateSimulation)
        *terminateSimulation = fmi3False;
    if (earlyReturn)
        *earlyReturn = fmi3False;
    if (lastSuccessfulTime)
        *lastSuccessfulTime = instance->fmu.time;
    return (fmi3Status)status;
}

/* Model exchange and scheduled execution: declared by the standard's header, refused here. */
fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
    return refuse(instance, "model exchange");
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance,
                                       fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode,
                                       fmi3Boolean *terminateSimulation) {
    (void)noSetFMUStatePriorToCurrentPoint; (void)enterEventMode; (void)terminateSimulation;
    return refuse(instance, "model exchange");
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    (void)time;
    return refuse(instance, "model exchange");
}

#define UNSUPPORTED_STATES(Name, Const)                                                      \
    fmi3Status fmi3##Name(fmi3Instance instance, Const fmi3Float64 values[], size_t n) {      \
        (void)values; (void)n;                                                               \
        return refuse(instance, "model exchange");                                           \
    }

UNSUPPORTED_STATES(SetContinuousStates, const)
UNSUPPORTED_STATES(GetContinuousStateDerivatives, )
UNSUPPORTED_STATES(GetEventIndicators, )
UNSUPPORTED_STATES(GetContinuousStates, )
UNSUPPORTED_STATES(GetNominalsOfContinuousStates, )

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *n) {
    (void)n;
    return refuse(instance, "model exchange");
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *n) {
    (void)n;
    return refuse(instance, "model exchange");
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime) {
    (void)clockReference; (void)activationTime;
    return refuse(instance, "scheduled execution");
}

fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference refs[],
                                  size_t n, fmi3Float64 intervals[],
                                  fmi3IntervalQualifier qualifiers[]) {
    (void)refs; (void)n; (void)intervals; (void)qualifiers;
    return refuse(instance, "clocks");
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference refs[],
                                   size_t n, fmi3UInt64 counters[], fmi3UInt64 resolutions[],
                                   fmi3IntervalQualifier qualifiers[]) {
    (void)refs; (void)n; (void)counters; (void)resolutions; (void)qualifiers;
    return refuse(instance, "clocks");
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference refs[], size_t n,
                               fmi3Float64 shifts[]) {
    (void)refs; (void)n; (void)shifts;
    return refuse(instance, "clocks");
}

fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference refs[],
                                size_t n, fmi3UInt64 counters[], fmi3UInt64 resolutions[]) {
    (void)refs; (void)n; (void)counters; (void)resolutions;
    return refuse(instance, "clocks");
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference refs[],
                                  size_t n, const fmi3Float64 intervals[]) {
    (void)refs; (void)n; (void)intervals;
    return refuse(instance, "clocks");
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference refs[],
                                   size_t n, const fmi3UInt64 counters[],
                                   const fmi3UInt64 resolutions[]) {
    (void)refs; (void)n; (void)counters; (void)resolutions;
    return refuse(instance, "clocks");
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference refs[], size_t n,
                               const fmi3Float64 shifts[]) {
    (void)refs; (void)n; (void)shifts;
    return refuse(instance, "clocks");
}

fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference refs[],
                                size_t n, const fmi3UInt64 counters[],
                                const fmi3UInt64 resolutions[]) {
    (void)refs; (void)n; (void)counters; (void)resolutions;
    return refuse(instance, "clocks");
}
