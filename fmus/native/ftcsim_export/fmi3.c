/* ftcsim's export library, FMI 3.0 co-simulation front end (core.c does the work; fmus/native/README.md).
 *
 * Modes (FMI 3.0 section 4.2, co-simulation state machine, without event mode: our FMUs declare
 * hasEventMode false): instantiated <-> configuration mode; instantiated -> fmi3EnterInitializationMode ->
 * initialization mode -> fmi3ExitInitializationMode -> step mode -> fmi3Terminate -> terminated. Getters are
 * also served when instantiated. After fmi3Error only the calls of FS_RECOVERY_CALLS are served; after
 * fmi3Fatal none but fmi3FreeInstance. Model exchange, scheduled execution, clocks and the types the
 * pythonfmu3 slave protocol has no method for (Float32, Int8/16, UInt8/16/32, Binary) are refused with
 * fmi3Error. */
#include "core.h"

#include <stdbool.h>
#include <stdio.h>

#include "fmi3Functions.h"

const char *const FS_RECOVERY_CALLS =
    "fmi3Reset, fmi3SetFMUState, fmi3FreeFMUState, fmi3SetDebugLogging and fmi3FreeInstance";

#define LIVE_MODES (FS_INSTANTIATED | FS_CONFIGURATION | FS_INIT | FS_STEP | FS_TERMINATED)
#define GET_MODES LIVE_MODES
#define SET_MODES (FS_INSTANTIATED | FS_CONFIGURATION | FS_INIT | FS_STEP)

/* FMI 3.0 allows a NULL logMessage; its message is not a format string */
void fs_emit(fs_instance *c, int status, const char *category, const char *message)
{
    fmi3LogMessageCallback logger = (fmi3LogMessageCallback)c->host_logger;
    if (logger == NULL) {
        if (status >= FS_WARNING) fprintf(stderr, "[ftcsim FMU %s] %s\n", c->name ? c->name : "?", message);
        return;
    }
    logger(c->host_env, (fmi3Status)status, category, message);
}

#define ENTER(function, allowed)                                                                                \
    fs_instance *c = fs_live(instance, function);                                                               \
    if (c == NULL) return fmi3Error;                                                                            \
    {                                                                                                           \
        int refused__ = fs_check(c, function, allowed);                                                         \
        if (refused__ != FS_OK) return (fmi3Status)refused__;                                                   \
    }

static fmi3Status unsupported(fmi3Instance instance, const char *function, const char *why)
{
    ENTER(function, LIVE_MODES);
    return (fmi3Status)fs_fail(c, FS_ERROR, "%s: not supported by this FMU (%s)", function, why);
}

#define NO_ME "a co-simulation FMU: no model exchange"
#define NO_CLOCKS "the FMU has no clocks"

const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[])
{
    ENTER("fmi3SetDebugLogging", LIVE_MODES | FS_ERRORED);
    fs_set_debug_logging(c, loggingOn, nCategories, categories);
    return fmi3OK;
}

static void refuse_instantiation(const char *function, fmi3String instanceName, fmi3InstanceEnvironment env,
                                 fmi3LogMessageCallback logMessage, const char *why)
{
    fs_instance stub = {0};
    stub.name = (char *)(instanceName ? instanceName : "");
    stub.host_env = env;
    stub.host_logger = (void (*)(void))logMessage;
    fs_log(&stub, FS_ERROR, "logStatusError", "%s: %s", function, why);
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage)
{
    (void)instantiationToken, (void)resourcePath, (void)visible, (void)loggingOn;
    refuse_instantiation("fmi3InstantiateModelExchange", instanceName, instanceEnvironment, logMessage,
                         "this FMU supports co-simulation only");
    return NULL;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate)
{
    /* eventModeUsed, earlyReturnAllowed: the FMU has no event mode and never returns early; it has no
     * intermediate variables */
    (void)eventModeUsed, (void)earlyReturnAllowed, (void)requiredIntermediateVariables;
    (void)nRequiredIntermediateVariables, (void)intermediateUpdate;
    return fs_instantiate(3, "fmi3InstantiateCoSimulation", instanceName, instantiationToken, resourcePath, visible,
                          loggingOn, instanceEnvironment, (void (*)(void))logMessage);
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                               fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption)
{
    (void)instantiationToken, (void)resourcePath, (void)visible, (void)loggingOn, (void)clockUpdate;
    (void)lockPreemption, (void)unlockPreemption;
    refuse_instantiation("fmi3InstantiateScheduledExecution", instanceName, instanceEnvironment, logMessage,
                         "this FMU supports co-simulation only");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance instance) { fs_free_instance(instance, "fmi3FreeInstance"); }

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime)
{
    (void)toleranceDefined, (void)tolerance, (void)stopTimeDefined, (void)stopTime;
    ENTER("fmi3EnterInitializationMode", FS_INSTANTIATED);
    /* pythonfmu3's slaves take the start time through setup_experiment(start_time) */
    int status = fs_call(c, "fmi3EnterInitializationMode", "setup_experiment", 1, &startTime, 0);
    if (status <= FS_WARNING)
        status = fs_call(c, "fmi3EnterInitializationMode", "enter_initialization_mode", 0, NULL, 0);
    if (status <= FS_WARNING) c->mode = FS_INIT;
    return (fmi3Status)status;
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance)
{
    ENTER("fmi3ExitInitializationMode", FS_INIT);
    int status = fs_call(c, "fmi3ExitInitializationMode", "exit_initialization_mode", 0, NULL, 0);
    if (status <= FS_WARNING) c->mode = FS_STEP;
    return (fmi3Status)status;
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance)
{
    return unsupported(instance, "fmi3EnterEventMode", "hasEventMode is false");
}

fmi3Status fmi3Terminate(fmi3Instance instance)
{
    ENTER("fmi3Terminate", FS_STEP);
    int status = fs_call(c, "fmi3Terminate", "terminate", 0, NULL, 0);
    if (status <= FS_WARNING) c->mode = FS_TERMINATED;
    return (fmi3Status)status;
}

fmi3Status fmi3Reset(fmi3Instance instance)
{
    ENTER("fmi3Reset", LIVE_MODES | FS_ERRORED);
    return (fmi3Status)fs_reset(c, "fmi3Reset");
}

#define GETTER(name, method, kind, type)                                                                        \
    fmi3Status name(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, \
                    type values[], size_t nValues)                                                              \
    {                                                                                                           \
        ENTER(#name, GET_MODES);                                                                                \
        return (fmi3Status)fs_get(c, #name, method, kind, valueReferences, nValueReferences, values, nValues);   \
    }
#define SETTER(name, method, kind, type)                                                                        \
    fmi3Status name(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, \
                    const type values[], size_t nValues)                                                        \
    {                                                                                                           \
        ENTER(#name, SET_MODES);                                                                                \
        return (fmi3Status)fs_set(c, #name, method, kind, valueReferences, nValueReferences, values, nValues);   \
    }
/* types the pythonfmu3 slave protocol has no method for: no variable can be of them */
#define NO_TYPE_GETTER(name, type)                                                                              \
    fmi3Status name(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, \
                    type values[], size_t nValues)                                                              \
    {                                                                                                           \
        (void)valueReferences, (void)values, (void)nValues;                                                     \
        ENTER(#name, GET_MODES);                                                                                \
        if (nValueReferences == 0) return fmi3OK;                                                               \
        return (fmi3Status)fs_fail(c, FS_ERROR, "%s: this FMU has no variable of this type", #name);            \
    }
#define NO_TYPE_SETTER(name, type)                                                                              \
    fmi3Status name(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, \
                    const type values[], size_t nValues)                                                        \
    {                                                                                                           \
        (void)valueReferences, (void)values, (void)nValues;                                                     \
        ENTER(#name, SET_MODES);                                                                                \
        if (nValueReferences == 0) return fmi3OK;                                                               \
        return (fmi3Status)fs_fail(c, FS_ERROR, "%s: this FMU has no variable of this type", #name);            \
    }

GETTER(fmi3GetFloat64, "get_float64", FS_REAL, fmi3Float64)
GETTER(fmi3GetInt32, "get_int32", FS_INT32, fmi3Int32)
GETTER(fmi3GetInt64, "get_int64", FS_INT64, fmi3Int64)
GETTER(fmi3GetUInt64, "get_uint64", FS_UINT64, fmi3UInt64)
GETTER(fmi3GetBoolean, "get_boolean", FS_BOOL_BYTE, fmi3Boolean)
GETTER(fmi3GetString, "get_string", FS_STRING, fmi3String)
SETTER(fmi3SetFloat64, "set_float64", FS_REAL, fmi3Float64)
SETTER(fmi3SetInt32, "set_int32", FS_INT32, fmi3Int32)
SETTER(fmi3SetInt64, "set_int64", FS_INT64, fmi3Int64)
SETTER(fmi3SetUInt64, "set_uint64", FS_UINT64, fmi3UInt64)
SETTER(fmi3SetBoolean, "set_boolean", FS_BOOL_BYTE, fmi3Boolean)
SETTER(fmi3SetString, "set_string", FS_STRING, fmi3String)
NO_TYPE_GETTER(fmi3GetFloat32, fmi3Float32)
NO_TYPE_GETTER(fmi3GetInt8, fmi3Int8)
NO_TYPE_GETTER(fmi3GetUInt8, fmi3UInt8)
NO_TYPE_GETTER(fmi3GetInt16, fmi3Int16)
NO_TYPE_GETTER(fmi3GetUInt16, fmi3UInt16)
NO_TYPE_GETTER(fmi3GetUInt32, fmi3UInt32)
NO_TYPE_SETTER(fmi3SetFloat32, fmi3Float32)
NO_TYPE_SETTER(fmi3SetInt8, fmi3Int8)
NO_TYPE_SETTER(fmi3SetUInt8, fmi3UInt8)
NO_TYPE_SETTER(fmi3SetInt16, fmi3Int16)
NO_TYPE_SETTER(fmi3SetUInt16, fmi3UInt16)
NO_TYPE_SETTER(fmi3SetUInt32, fmi3UInt32)

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         size_t valueSizes[], fmi3Binary values[], size_t nValues)
{
    (void)valueReferences, (void)valueSizes, (void)values, (void)nValues;
    ENTER("fmi3GetBinary", GET_MODES);
    if (nValueReferences == 0) return fmi3OK;
    return (fmi3Status)fs_fail(c, FS_ERROR, "fmi3GetBinary: this FMU has no variable of this type");
}

fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         const size_t valueSizes[], const fmi3Binary values[], size_t nValues)
{
    (void)valueReferences, (void)valueSizes, (void)values, (void)nValues;
    ENTER("fmi3SetBinary", SET_MODES);
    if (nValueReferences == 0) return fmi3OK;
    return (fmi3Status)fs_fail(c, FS_ERROR, "fmi3SetBinary: this FMU has no variable of this type");
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        fmi3Clock values[])
{
    (void)valueReferences, (void)nValueReferences, (void)values;
    return unsupported(instance, "fmi3GetClock", NO_CLOCKS);
}

fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        const fmi3Clock values[])
{
    (void)valueReferences, (void)nValueReferences, (void)values;
    return unsupported(instance, "fmi3SetClock", NO_CLOCKS);
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference valueReference,
                                               size_t *nDependencies)
{
    (void)valueReference, (void)nDependencies;
    return unsupported(instance, "fmi3GetNumberOfVariableDependencies", "read the dependencies from modelDescription.xml");
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies)
{
    (void)dependent, (void)elementIndicesOfDependent, (void)independents, (void)elementIndicesOfIndependents;
    (void)dependencyKinds, (void)nDependencies;
    return unsupported(instance, "fmi3GetVariableDependencies", "read the dependencies from modelDescription.xml");
}

fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    ENTER("fmi3GetFMUState", LIVE_MODES);
    return (fmi3Status)fs_get_state(c, "fmi3GetFMUState", FMUState);
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState)
{
    ENTER("fmi3SetFMUState", LIVE_MODES | FS_ERRORED);
    return (fmi3Status)fs_set_state(c, "fmi3SetFMUState", FMUState);
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    ENTER("fmi3FreeFMUState", LIVE_MODES | FS_ERRORED);
    return (fmi3Status)fs_free_state(c, "fmi3FreeFMUState", FMUState);
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState, size_t *size)
{
    ENTER("fmi3SerializedFMUStateSize", LIVE_MODES);
    return (fmi3Status)fs_state_size(c, "fmi3SerializedFMUStateSize", FMUState, size);
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState, fmi3Byte serializedState[], size_t size)
{
    ENTER("fmi3SerializeFMUState", LIVE_MODES);
    return (fmi3Status)fs_serialize_state(c, "fmi3SerializeFMUState", FMUState, serializedState, size);
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[], size_t size,
                                   fmi3FMUState *FMUState)
{
    ENTER("fmi3DeserializeFMUState", LIVE_MODES);
    return (fmi3Status)fs_deserialize_state(c, "fmi3DeserializeFMUState", serializedState, size, FMUState);
}

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                        const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                        size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
{
    (void)unknowns, (void)nUnknowns, (void)knowns, (void)nKnowns, (void)seed, (void)nSeed, (void)sensitivity;
    (void)nSensitivity;
    return unsupported(instance, "fmi3GetDirectionalDerivative", "providesDirectionalDerivatives is false");
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                    size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
{
    (void)unknowns, (void)nUnknowns, (void)knowns, (void)nKnowns, (void)seed, (void)nSeed, (void)sensitivity;
    (void)nSensitivity;
    return unsupported(instance, "fmi3GetAdjointDerivative", "providesAdjointDerivatives is false");
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance)
{
    ENTER("fmi3EnterConfigurationMode", FS_INSTANTIATED);
    c->mode = FS_CONFIGURATION;
    return fmi3OK;
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance)
{
    ENTER("fmi3ExitConfigurationMode", FS_CONFIGURATION);
    c->mode = FS_INSTANTIATED;
    return fmi3OK;
}

fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[])
{
    (void)valueReferences, (void)nValueReferences, (void)intervals, (void)qualifiers;
    return unsupported(instance, "fmi3GetIntervalDecimal", NO_CLOCKS);
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[],
                                   fmi3IntervalQualifier qualifiers[])
{
    (void)valueReferences, (void)nValueReferences, (void)counters, (void)resolutions, (void)qualifiers;
    return unsupported(instance, "fmi3GetIntervalFraction", NO_CLOCKS);
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, fmi3Float64 shifts[])
{
    (void)valueReferences, (void)nValueReferences, (void)shifts;
    return unsupported(instance, "fmi3GetShiftDecimal", NO_CLOCKS);
}

fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[])
{
    (void)valueReferences, (void)nValueReferences, (void)counters, (void)resolutions;
    return unsupported(instance, "fmi3GetShiftFraction", NO_CLOCKS);
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, const fmi3Float64 intervals[])
{
    (void)valueReferences, (void)nValueReferences, (void)intervals;
    return unsupported(instance, "fmi3SetIntervalDecimal", NO_CLOCKS);
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
{
    (void)valueReferences, (void)nValueReferences, (void)counters, (void)resolutions;
    return unsupported(instance, "fmi3SetIntervalFraction", NO_CLOCKS);
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, const fmi3Float64 shifts[])
{
    (void)valueReferences, (void)nValueReferences, (void)shifts;
    return unsupported(instance, "fmi3SetShiftDecimal", NO_CLOCKS);
}

fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
{
    (void)valueReferences, (void)nValueReferences, (void)counters, (void)resolutions;
    return unsupported(instance, "fmi3SetShiftFraction", NO_CLOCKS);
}

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance)
{
    return unsupported(instance, "fmi3EvaluateDiscreteStates", "hasEventMode is false");
}

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime)
{
    (void)discreteStatesNeedUpdate, (void)terminateSimulation, (void)nominalsOfContinuousStatesChanged;
    (void)valuesOfContinuousStatesChanged, (void)nextEventTimeDefined, (void)nextEventTime;
    return unsupported(instance, "fmi3UpdateDiscreteStates", "hasEventMode is false");
}

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance)
{
    return unsupported(instance, "fmi3EnterContinuousTimeMode", NO_ME);
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation)
{
    (void)noSetFMUStatePriorToCurrentPoint, (void)enterEventMode, (void)terminateSimulation;
    return unsupported(instance, "fmi3CompletedIntegratorStep", NO_ME);
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time)
{
    (void)time;
    return unsupported(instance, "fmi3SetTime", NO_ME);
}

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 continuousStates[],
                                   size_t nContinuousStates)
{
    (void)continuousStates, (void)nContinuousStates;
    return unsupported(instance, "fmi3SetContinuousStates", NO_ME);
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[],
                                             size_t nContinuousStates)
{
    (void)derivatives, (void)nContinuousStates;
    return unsupported(instance, "fmi3GetContinuousStateDerivatives", NO_ME);
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 eventIndicators[], size_t nEventIndicators)
{
    (void)eventIndicators, (void)nEventIndicators;
    return unsupported(instance, "fmi3GetEventIndicators", NO_ME);
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 continuousStates[], size_t nContinuousStates)
{
    (void)continuousStates, (void)nContinuousStates;
    return unsupported(instance, "fmi3GetContinuousStates", NO_ME);
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[], size_t nContinuousStates)
{
    (void)nominals, (void)nContinuousStates;
    return unsupported(instance, "fmi3GetNominalsOfContinuousStates", NO_ME);
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *nEventIndicators)
{
    (void)nEventIndicators;
    return unsupported(instance, "fmi3GetNumberOfEventIndicators", NO_ME);
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *nContinuousStates)
{
    (void)nContinuousStates;
    return unsupported(instance, "fmi3GetNumberOfContinuousStates", NO_ME);
}

fmi3Status fmi3EnterStepMode(fmi3Instance instance)
{
    /* FMI 3.0 leaves event mode with it; without event mode an instance already in step mode stays there */
    ENTER("fmi3EnterStepMode", FS_STEP);
    return fmi3OK;
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Int32 orders[], fmi3Float64 values[],
                                    size_t nValues)
{
    (void)valueReferences, (void)nValueReferences, (void)orders, (void)values, (void)nValues;
    return unsupported(instance, "fmi3GetOutputDerivatives", "maxOutputDerivativeOrder is 0");
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean *eventHandlingNeeded,
                      fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime)
{
    (void)noSetFMUStatePriorToCurrentPoint;
    ENTER("fmi3DoStep", FS_STEP);
    int terminate = 0;
    int status = fs_do_step(c, "fmi3DoStep", currentCommunicationPoint, communicationStepSize, &terminate);
    if (eventHandlingNeeded != NULL) *eventHandlingNeeded = false;
    if (earlyReturn != NULL) *earlyReturn = false;
    if (terminateSimulation != NULL) *terminateSimulation = terminate != 0;
    if (lastSuccessfulTime != NULL)
        *lastSuccessfulTime = status <= FS_WARNING ? currentCommunicationPoint + communicationStepSize
                                                   : currentCommunicationPoint;
    return (fmi3Status)status;
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime)
{
    (void)clockReference, (void)activationTime;
    return unsupported(instance, "fmi3ActivateModelPartition", "no scheduled execution");
}
