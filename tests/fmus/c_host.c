/* A hostile C host (tests/fmus/test_hostile_host.py): no Python in the process until the FMU starts one.
 *
 *   c_host 2|3 BINARY.so TOKEN RESOURCE_LOCATION OUTPUT_VR
 *
 * Calls on a NULL instance, instantiates (the FMU's library starts Python), refuses a wrong token, runs
 * two steps, a NaN step (error, logged), a get after it (refused), resets, steps again, takes and
 * restores an FMU state, frees twice, calls on the freed instance, and exits through main's return
 * (the library's destructor runs in the exit path). Logs through a printf-formatting logger, as real
 * FMI 2 hosts do. Prints "ok N" when every status is the one FMI requires, else "FAIL ..." and exits 1. */
#include <dlfcn.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "fmi3Functions.h"

static int checks, errors_logged;

static void logger2(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                    fmi2String message, ...)
{
    (void)env;
    va_list ap;
    va_start(ap, message);
    printf("[%s %d %s] ", name, (int)status, category ? category : "(null)");
    vprintf(message, ap); /* a '%' the FMU did not double would read arguments that are not there */
    printf("\n");
    va_end(ap);
    if (status >= fmi2Error) errors_logged++;
}

static void logger3(fmi3InstanceEnvironment env, fmi3Status status, fmi3String category, fmi3String message)
{
    (void)env;
    printf("[%d %s] %s\n", (int)status, category ? category : "(null)", message);
    if (status >= fmi3Error) errors_logged++;
}

#define CHECK(got, want, what)                                                                                  \
    do {                                                                                                        \
        checks++;                                                                                               \
        int got__ = (int)(got);                                                                                 \
        if (got__ != (int)(want)) {                                                                             \
            printf("FAIL %s: status %d, expected %d\n", what, got__, (int)(want));                              \
            return 1;                                                                                           \
        }                                                                                                       \
    } while (0)
#define LOGGED(what)                                                                                            \
    do {                                                                                                        \
        checks++;                                                                                               \
        if (errors_logged == before) {                                                                          \
            printf("FAIL %s: no error message logged\n", what);                                                 \
            return 1;                                                                                           \
        }                                                                                                       \
        before = errors_logged;                                                                                 \
    } while (0)

static int fmi2(void *h, const char *token, const char *location, fmi2ValueReference out)
{
#define LOAD(name) name##TYPE *name = (name##TYPE *)dlsym(h, #name)
    LOAD(fmi2Instantiate); LOAD(fmi2SetupExperiment); LOAD(fmi2EnterInitializationMode);
    LOAD(fmi2ExitInitializationMode); LOAD(fmi2GetReal); LOAD(fmi2DoStep); LOAD(fmi2Reset);
    LOAD(fmi2FreeInstance); LOAD(fmi2GetFMUstate); LOAD(fmi2SetFMUstate); LOAD(fmi2FreeFMUstate);
    fmi2CallbackFunctions cb = {logger2, calloc, free, NULL, NULL};
    int before = errors_logged;
    fmi2Real y;
    CHECK(fmi2DoStep(NULL, 0.0, 1e-3, fmi2True), fmi2Error, "a step of a NULL instance");
    CHECK(fmi2Instantiate("wrong", fmi2CoSimulation, "{not-this-fmu}", location, &cb, fmi2False, fmi2False) == NULL, 1,
          "a wrong GUID gives no instance");
    LOGGED("a wrong GUID");
    fmi2Component c = fmi2Instantiate("c", fmi2CoSimulation, token, location, &cb, fmi2False, fmi2False);
    CHECK(c != NULL, 1, "instantiate");
    CHECK(fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK, "setup");
    CHECK(fmi2EnterInitializationMode(c), fmi2OK, "enter initialisation");
    CHECK(fmi2ExitInitializationMode(c), fmi2OK, "exit initialisation");
    CHECK(fmi2DoStep(c, 0.0, 1e-3, fmi2True), fmi2OK, "a step");
    fmi2FMUstate s = NULL;
    CHECK(fmi2GetFMUstate(c, &s), fmi2OK, "get the state");
    CHECK(fmi2DoStep(c, 1e-3, NAN, fmi2True), fmi2Error, "a NaN step");
    LOGGED("a NaN step");
    CHECK(fmi2GetReal(c, &out, 1, &y), fmi2Error, "a get after the error");
    LOGGED("a get after the error");
    CHECK(fmi2SetFMUstate(c, s), fmi2OK, "set the state after the error");
    CHECK(fmi2DoStep(c, 1e-3, 1e-3, fmi2True), fmi2OK, "a step after the recovery");
    CHECK(fmi2FreeFMUstate(c, &s), fmi2OK, "free the state");
    CHECK(fmi2Reset(c), fmi2OK, "reset");
    CHECK(fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK, "setup after the reset");
    CHECK(fmi2EnterInitializationMode(c), fmi2OK, "enter initialisation after the reset");
    CHECK(fmi2ExitInitializationMode(c), fmi2OK, "exit initialisation after the reset");
    CHECK(fmi2DoStep(c, 0.0, 1e-3, fmi2True), fmi2OK, "a step after the reset");
    CHECK(fmi2GetReal(c, &out, 1, &y), fmi2OK, "a get");
    fmi2FreeInstance(c);
    fmi2FreeInstance(c); /* double free */
    CHECK(fmi2DoStep(c, 1e-3, 1e-3, fmi2True), fmi2Error, "a step of a freed instance");
    fmi2Component d = fmi2Instantiate("d", fmi2CoSimulation, token, location, &cb, fmi2False, fmi2False);
    CHECK(d != NULL, 1, "a second instance");
    fmi2FreeInstance(d);
    return 0;
}

static int fmi3(void *h, const char *token, const char *location, fmi3ValueReference out)
{
    LOAD(fmi3InstantiateCoSimulation); LOAD(fmi3EnterInitializationMode); LOAD(fmi3ExitInitializationMode);
    LOAD(fmi3GetFloat64); LOAD(fmi3DoStep); LOAD(fmi3Reset); LOAD(fmi3FreeInstance); LOAD(fmi3GetFMUState);
    LOAD(fmi3SetFMUState); LOAD(fmi3FreeFMUState);
    int before = errors_logged;
    fmi3Float64 y, last;
    fmi3Boolean event, stop, early;
#define STEP(c, t, dt) fmi3DoStep(c, t, dt, fmi3True, &event, &stop, &early, &last)
    CHECK(STEP(NULL, 0.0, 1e-3), fmi3Error, "a step of a NULL instance");
    CHECK(fmi3InstantiateCoSimulation("wrong", "{not-this-fmu}", location, fmi3False, fmi3False, fmi3False, fmi3False,
                                      NULL, 0, NULL, logger3, NULL) == NULL, 1, "a wrong token gives no instance");
    LOGGED("a wrong token");
    fmi3Instance c = fmi3InstantiateCoSimulation("c", token, location, fmi3False, fmi3False, fmi3False, fmi3False,
                                                 NULL, 0, NULL, logger3, NULL);
    CHECK(c != NULL, 1, "instantiate");
    CHECK(fmi3EnterInitializationMode(c, fmi3False, 0.0, 0.0, fmi3False, 0.0), fmi3OK, "enter initialisation");
    CHECK(fmi3ExitInitializationMode(c), fmi3OK, "exit initialisation");
    CHECK(STEP(c, 0.0, 1e-3), fmi3OK, "a step");
    fmi3FMUState s = NULL;
    CHECK(fmi3GetFMUState(c, &s), fmi3OK, "get the state");
    CHECK(STEP(c, 1e-3, NAN), fmi3Error, "a NaN step");
    LOGGED("a NaN step");
    CHECK(fmi3GetFloat64(c, &out, 1, &y, 1), fmi3Error, "a get after the error");
    LOGGED("a get after the error");
    CHECK(fmi3SetFMUState(c, s), fmi3OK, "set the state after the error");
    CHECK(STEP(c, 1e-3, 1e-3), fmi3OK, "a step after the recovery");
    CHECK(fmi3FreeFMUState(c, &s), fmi3OK, "free the state");
    CHECK(fmi3Reset(c), fmi3OK, "reset");
    CHECK(fmi3EnterInitializationMode(c, fmi3False, 0.0, 0.0, fmi3False, 0.0), fmi3OK, "initialisation after reset");
    CHECK(fmi3ExitInitializationMode(c), fmi3OK, "exit initialisation after the reset");
    CHECK(STEP(c, 0.0, 1e-3), fmi3OK, "a step after the reset");
    CHECK(fmi3GetFloat64(c, &out, 1, &y, 1), fmi3OK, "a get");
    fmi3FreeInstance(c);
    fmi3FreeInstance(c); /* double free */
    CHECK(STEP(c, 1e-3, 1e-3), fmi3Error, "a step of a freed instance");
    fmi3Instance d = fmi3InstantiateCoSimulation("d", token, location, fmi3False, fmi3False, fmi3False, fmi3False,
                                                 NULL, 0, NULL, NULL, NULL); /* no logger: allowed */
    CHECK(d != NULL, 1, "a second instance without a logger");
    fmi3FreeInstance(d);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc != 6) {
        fprintf(stderr, "usage: c_host 2|3 BINARY.so TOKEN RESOURCE_LOCATION OUTPUT_VR\n");
        return 2;
    }
    void *h = dlopen(argv[2], RTLD_NOW | RTLD_LOCAL);
    if (h == NULL) {
        printf("FAIL dlopen: %s\n", dlerror());
        return 1;
    }
    unsigned vr = (unsigned)strtoul(argv[5], NULL, 10);
    int rc = strcmp(argv[1], "2") == 0 ? fmi2(h, argv[3], argv[4], vr) : fmi3(h, argv[3], argv[4], vr);
    if (rc == 0) printf("ok %d\n", checks);
    fflush(stdout);
    return rc;
}
