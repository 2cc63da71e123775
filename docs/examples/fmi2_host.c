/* Minimal FMI 2.0 co-simulation host (docs/external-tools.md): loads PDController.fmu's binary, sets q, reads u, steps. */
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <stdarg.h>
#include "fmi2Functions.h"

static void logger(fmi2ComponentEnvironment e, fmi2String name, fmi2Status s, fmi2String cat, fmi2String msg, ...) {
    va_list ap; va_start(ap, msg); printf("[%s] ", name); vprintf(msg, ap); printf("\n"); va_end(ap);
}

int main(int argc, char **argv) {
    if (argc < 4) { fprintf(stderr, "usage: host BINARY.so GUID RESOURCE_URI\n"); return 2; }
    void *h = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (!h) { fprintf(stderr, "dlopen: %s\n", dlerror()); return 1; }
#define LOAD(name) name##TYPE *name = (name##TYPE *)dlsym(h, #name)
    LOAD(fmi2Instantiate); LOAD(fmi2SetupExperiment); LOAD(fmi2EnterInitializationMode);
    LOAD(fmi2ExitInitializationMode); LOAD(fmi2GetReal); LOAD(fmi2SetReal); LOAD(fmi2DoStep);
    LOAD(fmi2Terminate); LOAD(fmi2FreeInstance);
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
    fmi2Component c = fmi2Instantiate("ctrl", fmi2CoSimulation, argv[2], argv[3], &cb, fmi2False, fmi2True);
    if (!c) { fprintf(stderr, "fmi2Instantiate failed\n"); return 1; }
    fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0);
    fmi2EnterInitializationMode(c);
    fmi2ExitInitializationMode(c);
    /* q = (0.9, 0.1, 0.2, 0.3) normalised-ish, omega = 0; desired attitude identity */
    fmi2ValueReference q_vr[4] = {0, 1, 2, 3};
    fmi2Real q[4] = {0.9273618495495703, 0.1, 0.2, 0.3};
    fmi2SetReal(c, q_vr, 4, q);
    double t = 0.0, dt = 0.01;
    for (int k = 0; k < 3; k++) {
        fmi2ValueReference u_vr[3] = {28, 29, 30};  /* u[1..3] */
        fmi2Real u[3];
        if (fmi2GetReal(c, u_vr, 3, u) != fmi2OK) { fprintf(stderr, "fmi2GetReal failed\n"); return 1; }
        printf("t=%.2f u=(%.6f, %.6f, %.6f)\n", t, u[0], u[1], u[2]);
        if (fmi2DoStep(c, t, dt, fmi2True) != fmi2OK) { fprintf(stderr, "fmi2DoStep failed\n"); return 1; }
        t += dt;
    }
    fmi2Terminate(c);
    fmi2FreeInstance(c);
    printf("ok\n");
    return 0;
}
