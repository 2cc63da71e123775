/* ftcsim's export library, FMI 2.0 co-simulation front end (core.c does the work; fmus/native/README.md).
 *
 * Modes (FMI 2.0.4 section 4.2.4, table of allowed calls): instantiated -> (fmi2SetupExperiment) ->
 * fmi2EnterInitializationMode -> initialization mode -> fmi2ExitInitializationMode -> step mode ("slave
 * initialized") -> fmi2Terminate -> terminated. Getters are also served when instantiated (reading start
 * values is harmless). After fmi2Error only the calls of FS_RECOVERY_CALLS are served; after fmi2Fatal
 * none but fmi2FreeInstance. */
#include "core.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

const char *const FS_RECOVERY_CALLS =
    "fmi2Reset, fmi2SetFMUstate, fmi2FreeFMUstate, fmi2SetDebugLogging and fmi2FreeInstance";

#define LIVE_MODES (FS_INSTANTIATED | FS_INIT | FS_STEP | FS_TERMINATED)
#define GET_MODES (FS_INSTANTIATED | FS_INIT | FS_STEP | FS_TERMINATED)
#define SET_MODES (FS_INSTANTIATED | FS_INIT | FS_STEP)

/* FMI 2.0's logger formats the message like printf: every '%' of ours is doubled */
void fs_emit(fs_instance *c, int status, const char *category, const char *message)
{
    fmi2CallbackLogger logger = (fmi2CallbackLogger)c->host_logger;
    if (logger == NULL) {
        if (status >= FS_WARNING) fprintf(stderr, "[ftcsim FMU %s] %s\n", c->name ? c->name : "?", message);
        return;
    }
    size_t n = strlen(message), percents = 0;
    for (size_t i = 0; i < n; i++) percents += message[i] == '%';
    char *escaped = malloc(n + percents + 1);
    if (escaped == NULL) return;
    char *o = escaped;
    for (size_t i = 0; i < n; i++) {
        *o++ = message[i];
        if (message[i] == '%') *o++ = '%';
    }
    *o = '\0';
    logger(c->host_env, c->name ? c->name : "", (fmi2Status)status, category, escaped);
    free(escaped);
}

/* look the instance up and check its mode; returns from the calling function with the status on refusal */
#define ENTER(function, allowed)                                                                                \
    fs_instance *c = fs_live(handle, function);                                                                 \
    if (c == NULL) return fmi2Error;                                                                            \
    {                                                                                                           \
        int refused__ = fs_check(c, function, allowed);                                                         \
        if (refused__ != FS_OK) return (fmi2Status)refused__;                                                   \
    }

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }

const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn)
{
    /* the callbacks are copied (FMI 2.0.1: the struct need not outlive the call); only the logger is used */
    void *env = functions ? functions->componentEnvironment : NULL;
    void (*logger)(void) = functions ? (void (*)(void))functions->logger : NULL;
    if (fmuType != fmi2CoSimulation) {
        fs_instance stub = {0};
        stub.name = (char *)(instanceName ? instanceName : "");
        stub.host_env = env;
        stub.host_logger = logger;
        fs_emit(&stub, FS_ERROR, "logStatusError",
                "fmi2Instantiate: this FMU supports co-simulation only (fmuType fmi2CoSimulation)");
        return NULL;
    }
    return fs_instantiate(2, "fmi2Instantiate", instanceName, fmuGUID, fmuResourceLocation, visible, loggingOn, env,
                          logger);
}

void fmi2FreeInstance(fmi2Component handle) { fs_free_instance(handle, "fmi2FreeInstance"); }

fmi2Status fmi2SetDebugLogging(fmi2Component handle, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[])
{
    ENTER("fmi2SetDebugLogging", LIVE_MODES | FS_ERRORED);
    fs_set_debug_logging(c, loggingOn, nCategories, categories);
    return fmi2OK;
}

fmi2Status fmi2SetupExperiment(fmi2Component handle, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    ENTER("fmi2SetupExperiment", FS_INSTANTIATED);
    double args[3] = {startTime, stopTime, tolerance};
    return (fmi2Status)fs_call(c, "fmi2SetupExperiment", "setup_experiment", 3, args,
                               (stopTimeDefined ? 0u : 2u) | (toleranceDefined ? 0u : 4u));
}

fmi2Status fmi2EnterInitializationMode(fmi2Component handle)
{
    ENTER("fmi2EnterInitializationMode", FS_INSTANTIATED);
    int status = fs_call(c, "fmi2EnterInitializationMode", "enter_initialization_mode", 0, NULL, 0);
    if (status <= FS_WARNING) c->mode = FS_INIT;
    return (fmi2Status)status;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component handle)
{
    ENTER("fmi2ExitInitializationMode", FS_INIT);
    int status = fs_call(c, "fmi2ExitInitializationMode", "exit_initialization_mode", 0, NULL, 0);
    if (status <= FS_WARNING) c->mode = FS_STEP;
    return (fmi2Status)status;
}

fmi2Status fmi2Terminate(fmi2Component handle)
{
    ENTER("fmi2Terminate", FS_STEP);
    int status = fs_call(c, "fmi2Terminate", "terminate", 0, NULL, 0);
    if (status <= FS_WARNING) c->mode = FS_TERMINATED;
    return (fmi2Status)status;
}

fmi2Status fmi2Reset(fmi2Component handle)
{
    ENTER("fmi2Reset", LIVE_MODES | FS_ERRORED);
    return (fmi2Status)fs_reset(c, "fmi2Reset");
}

#define GETTER(name, method, kind, type)                                                                        \
    fmi2Status name(fmi2Component handle, const fmi2ValueReference vr[], size_t nvr, type value[])              \
    {                                                                                                           \
        ENTER(#name, GET_MODES);                                                                                \
        return (fmi2Status)fs_get(c, #name, method, kind, vr, nvr, value, nvr);                                 \
    }
#define SETTER(name, method, kind, type)                                                                        \
    fmi2Status name(fmi2Component handle, const fmi2ValueReference vr[], size_t nvr, const type value[])        \
    {                                                                                                           \
        ENTER(#name, SET_MODES);                                                                                \
        return (fmi2Status)fs_set(c, #name, method, kind, vr, nvr, value, nvr);                                 \
    }

GETTER(fmi2GetReal, "get_real", FS_REAL, fmi2Real)
GETTER(fmi2GetInteger, "get_integer", FS_INT32, fmi2Integer)
GETTER(fmi2GetBoolean, "get_boolean", FS_BOOL_INT, fmi2Boolean)
GETTER(fmi2GetString, "get_string", FS_STRING, fmi2String)
SETTER(fmi2SetReal, "set_real", FS_REAL, fmi2Real)
SETTER(fmi2SetInteger, "set_integer", FS_INT32, fmi2Integer)
SETTER(fmi2SetBoolean, "set_boolean", FS_BOOL_INT, fmi2Boolean)
SETTER(fmi2SetString, "set_string", FS_STRING, fmi2String)

fmi2Status fmi2GetFMUstate(fmi2Component handle, fmi2FMUstate *state)
{
    ENTER("fmi2GetFMUstate", LIVE_MODES);
    return (fmi2Status)fs_get_state(c, "fmi2GetFMUstate", state);
}

fmi2Status fmi2SetFMUstate(fmi2Component handle, fmi2FMUstate state)
{
    ENTER("fmi2SetFMUstate", LIVE_MODES | FS_ERRORED);
    return (fmi2Status)fs_set_state(c, "fmi2SetFMUstate", state);
}

fmi2Status fmi2FreeFMUstate(fmi2Component handle, fmi2FMUstate *state)
{
    ENTER("fmi2FreeFMUstate", LIVE_MODES | FS_ERRORED);
    return (fmi2Status)fs_free_state(c, "fmi2FreeFMUstate", state);
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component handle, fmi2FMUstate state, size_t *size)
{
    ENTER("fmi2SerializedFMUstateSize", LIVE_MODES);
    return (fmi2Status)fs_state_size(c, "fmi2SerializedFMUstateSize", state, size);
}

fmi2Status fmi2SerializeFMUstate(fmi2Component handle, fmi2FMUstate state, fmi2Byte bytes[], size_t size)
{
    ENTER("fmi2SerializeFMUstate", LIVE_MODES);
    return (fmi2Status)fs_serialize_state(c, "fmi2SerializeFMUstate", state, (unsigned char *)bytes, size);
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component handle, const fmi2Byte serializedState[], size_t size,
                                   fmi2FMUstate *state)
{
    ENTER("fmi2DeSerializeFMUstate", LIVE_MODES);
    return (fmi2Status)fs_deserialize_state(c, "fmi2DeSerializeFMUstate", (const unsigned char *)serializedState,
                                            size, state);
}

static fmi2Status unsupported(fmi2Component handle, const char *function, const char *why)
{
    ENTER(function, LIVE_MODES);
    return (fmi2Status)fs_fail(c, FS_ERROR, "%s: not supported by this FMU (%s)", function, why);
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component handle, const fmi2ValueReference vUnknown_ref[],
                                        size_t nUnknown, const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[])
{
    (void)vUnknown_ref, (void)nUnknown, (void)vKnown_ref, (void)nKnown, (void)dvKnown, (void)dvUnknown;
    return unsupported(handle, "fmi2GetDirectionalDerivative", "providesDirectionalDerivative is false");
}

fmi2Status fmi2SetRealInputDerivatives(fmi2Component handle, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[])
{
    (void)vr, (void)nvr, (void)order, (void)value;
    return unsupported(handle, "fmi2SetRealInputDerivatives", "canInterpolateInputs is false");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component handle, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[])
{
    (void)vr, (void)nvr, (void)order, (void)value;
    return unsupported(handle, "fmi2GetRealOutputDerivatives", "maxOutputDerivativeOrder is 0");
}

fmi2Status fmi2DoStep(fmi2Component handle, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    (void)noSetFMUStatePriorToCurrentPoint;
    ENTER("fmi2DoStep", FS_STEP);
    int terminate = 0;
    return (fmi2Status)fs_do_step(c, "fmi2DoStep", currentCommunicationPoint, communicationStepSize, &terminate);
}

fmi2Status fmi2CancelStep(fmi2Component handle)
{
    return unsupported(handle, "fmi2CancelStep", "steps are never asynchronous (fmi2DoStep never returns fmi2Pending)");
}

/* status inquiries: an unsupported kind is fmi2Discard (FMI 2.0.4 4.2.3) */
fmi2Status fmi2GetStatus(fmi2Component handle, const fmi2StatusKind s, fmi2Status *value)
{
    (void)s, (void)value;
    ENTER("fmi2GetStatus", FS_STEP | FS_TERMINATED);
    fs_log(c, FS_DISCARD, "logStatusDiscard", "fmi2GetStatus: no status of kind %d (steps are never asynchronous)",
           (int)s);
    return fmi2Discard;
}

fmi2Status fmi2GetRealStatus(fmi2Component handle, const fmi2StatusKind s, fmi2Real *value)
{
    ENTER("fmi2GetRealStatus", FS_STEP | FS_TERMINATED);
    if (s == fmi2LastSuccessfulTime && value != NULL) {
        *value = c->last_time;
        return fmi2OK;
    }
    fs_log(c, FS_DISCARD, "logStatusDiscard", "fmi2GetRealStatus: only fmi2LastSuccessfulTime is available");
    return fmi2Discard;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component handle, const fmi2StatusKind s, fmi2Integer *value)
{
    (void)s, (void)value;
    ENTER("fmi2GetIntegerStatus", FS_STEP | FS_TERMINATED);
    fs_log(c, FS_DISCARD, "logStatusDiscard", "fmi2GetIntegerStatus: no integer status is available");
    return fmi2Discard;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component handle, const fmi2StatusKind s, fmi2Boolean *value)
{
    ENTER("fmi2GetBooleanStatus", FS_STEP | FS_TERMINATED);
    if (s == fmi2Terminated && value != NULL) {
        *value = c->terminate_requested ? fmi2True : fmi2False;
        return fmi2OK;
    }
    fs_log(c, FS_DISCARD, "logStatusDiscard", "fmi2GetBooleanStatus: only fmi2Terminated is available");
    return fmi2Discard;
}

fmi2Status fmi2GetStringStatus(fmi2Component handle, const fmi2StatusKind s, fmi2String *value)
{
    (void)s, (void)value;
    ENTER("fmi2GetStringStatus", FS_STEP | FS_TERMINATED);
    fs_log(c, FS_DISCARD, "logStatusDiscard", "fmi2GetStringStatus: no string status is available");
    return fmi2Discard;
}

/* Model exchange: a co-simulation FMU need not provide these (FMI 2.0.4 4.1), but some hosts bind every
 * FMI 2.0 function when they load a library (fmuloader): present, and refused */
#define NO_ME "a co-simulation FMU: no model exchange"

fmi2Status fmi2EnterEventMode(fmi2Component handle) { return unsupported(handle, "fmi2EnterEventMode", NO_ME); }

fmi2Status fmi2NewDiscreteStates(fmi2Component handle, fmi2EventInfo *eventInfo)
{
    (void)eventInfo;
    return unsupported(handle, "fmi2NewDiscreteStates", NO_ME);
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component handle)
{
    return unsupported(handle, "fmi2EnterContinuousTimeMode", NO_ME);
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component handle, fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi2Boolean *enterEventMode, fmi2Boolean *terminateSimulation)
{
    (void)noSetFMUStatePriorToCurrentPoint, (void)enterEventMode, (void)terminateSimulation;
    return unsupported(handle, "fmi2CompletedIntegratorStep", NO_ME);
}

fmi2Status fmi2SetTime(fmi2Component handle, fmi2Real time)
{
    (void)time;
    return unsupported(handle, "fmi2SetTime", NO_ME);
}

fmi2Status fmi2SetContinuousStates(fmi2Component handle, const fmi2Real x[], size_t nx)
{
    (void)x, (void)nx;
    return unsupported(handle, "fmi2SetContinuousStates", NO_ME);
}

fmi2Status fmi2GetDerivatives(fmi2Component handle, fmi2Real derivatives[], size_t nx)
{
    (void)derivatives, (void)nx;
    return unsupported(handle, "fmi2GetDerivatives", NO_ME);
}

fmi2Status fmi2GetEventIndicators(fmi2Component handle, fmi2Real eventIndicators[], size_t ni)
{
    (void)eventIndicators, (void)ni;
    return unsupported(handle, "fmi2GetEventIndicators", NO_ME);
}

fmi2Status fmi2GetContinuousStates(fmi2Component handle, fmi2Real x[], size_t nx)
{
    (void)x, (void)nx;
    return unsupported(handle, "fmi2GetContinuousStates", NO_ME);
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component handle, fmi2Real x_nominal[], size_t nx)
{
    (void)x_nominal, (void)nx;
    return unsupported(handle, "fmi2GetNominalsOfContinuousStates", NO_ME);
}
