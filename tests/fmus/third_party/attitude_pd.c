/* A third-party FMI 2.0 co-simulation FMU written in plain C (not made by pythonfmu), for the tests of
 * tests/fmus/test_third_party_fmu.py: the PD attitude law of docs/examples/pd_block.py,
 *
 *     u = sat(-k_p q_ev - k_d omega - f_hat),  q_e = q_d^-1 (x) q (paper 000 (4)),  omega_e = omega,
 *
 * with the variable names and units of paper 000's controllers (modelDescription.xml next to this file).
 * Built by a session fixture (tests/conftest.py: c_fmu) with gcc against fmpy's FMI headers. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fmi2Functions.h"

#define GUID "{6d1b4a2e-3c5f-4e8a-9b7d-0a1c2e3f4a5b}"
enum { Q0 = 0, OMEGA = 4, QD0 = 7, FHAT = 11, U = 14, QE0 = 17, OMEGA_E = 21, KP = 24, KD = 25, UMAX = 26, NVAR = 27 };

typedef struct {
    double v[NVAR];
    double t;
} State;

typedef struct {
    State s;
    fmi2CallbackFunctions cb;
    char name[64];
} Instance;

static void say(Instance *c, fmi2Status status, const char *msg) {
    if (c->cb.logger) c->cb.logger(c->cb.componentEnvironment, c->name, status, "logAll", "%s", msg);
}

static double clip(double x, double m) { return x > m ? m : (x < -m ? -m : x); }

static void outputs(State *s) {
    double *v = s->v;
    const double *q = v + Q0, *w = v + OMEGA, *d = v + QD0, *f = v + FHAT;
    double e[3];
    /* q_ev = q_d0 q_v - q_dv x q_v - q0 q_dv */
    e[0] = d[0] * q[1] - (d[2] * q[3] - d[3] * q[2]) - q[0] * d[1];
    e[1] = d[0] * q[2] - (d[3] * q[1] - d[1] * q[3]) - q[0] * d[2];
    e[2] = d[0] * q[3] - (d[1] * q[2] - d[2] * q[1]) - q[0] * d[3];
    v[QE0] = d[0] * q[0] + d[1] * q[1] + d[2] * q[2] + d[3] * q[3];
    for (int i = 0; i < 3; i++) {
        v[U + i] = clip(-v[KP] * e[i] - v[KD] * w[i] - f[i], v[UMAX]);
        v[QE0 + 1 + i] = e[i];
        v[OMEGA_E + i] = w[i];
    }
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }
fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cat[]) { return fmi2OK; }

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                              const fmi2CallbackFunctions *cb, fmi2Boolean visible, fmi2Boolean logging) {
    if (type != fmi2CoSimulation || !guid || strcmp(guid, GUID) != 0) return NULL;
    Instance *c = calloc(1, sizeof(Instance));
    if (!c) return NULL;
    if (cb) c->cb = *cb;
    snprintf(c->name, sizeof c->name, "%s", name ? name : "?");
    c->s.v[Q0] = 1.0;
    c->s.v[QD0] = 1.0;
    c->s.v[KP] = 20.0;
    c->s.v[KD] = 60.0;
    c->s.v[UMAX] = 5.0;
    return c;
}

void fmi2FreeInstance(fmi2Component c) { free(c); }
fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolDefined, fmi2Real tol, fmi2Real start,
                               fmi2Boolean stopDefined, fmi2Real stop) {
    ((Instance *)c)->s.t = start;
    return fmi2OK;
}
fmi2Status fmi2EnterInitializationMode(fmi2Component c) { return fmi2OK; }
fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    Instance *x = c;
    if (!(x->s.v[UMAX] > 0)) {
        say(x, fmi2Error, "u_max must be > 0 N.m");
        return fmi2Error;
    }
    return fmi2OK;
}
fmi2Status fmi2Terminate(fmi2Component c) { return fmi2OK; }
fmi2Status fmi2Reset(fmi2Component c) { return fmi2Error; }

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[]) {
    Instance *x = c;
    outputs(&x->s);
    for (size_t i = 0; i < n; i++) {
        if (vr[i] >= NVAR) return fmi2Error;
        value[i] = x->s.v[vr[i]];
    }
    return fmi2OK;
}
fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[]) {
    Instance *x = c;
    for (size_t i = 0; i < n; i++) {
        if (vr[i] >= NVAR || (vr[i] >= U && vr[i] < KP)) {
            say(x, fmi2Error, "only inputs and parameters can be set");
            return fmi2Error;
        }
        x->s.v[vr[i]] = value[i];
    }
    return fmi2OK;
}
fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior) {
    ((Instance *)c)->s.t = t + h; /* a static law: nothing to integrate */
    return fmi2OK;
}

/* FMU state: a copy of the variables and the time */
fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *state) {
    State *s = *state ? (State *)*state : malloc(sizeof(State));
    if (!s) return fmi2Error;
    *s = ((Instance *)c)->s;
    *state = s;
    return fmi2OK;
}
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) {
    ((Instance *)c)->s = *(State *)state;
    return fmi2OK;
}
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state) {
    free(*state);
    *state = NULL;
    return fmi2OK;
}
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t *size) {
    *size = sizeof(State);
    return fmi2OK;
}
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state, fmi2Byte bytes[], size_t size) {
    if (size < sizeof(State)) return fmi2Error;
    memcpy(bytes, state, sizeof(State));
    return fmi2OK;
}
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size, fmi2FMUstate *state) {
    if (size != sizeof(State)) return fmi2Error;
    State *s = malloc(sizeof(State));
    if (!s) return fmi2Error;
    memcpy(s, bytes, sizeof(State));
    *state = s;
    return fmi2OK;
}

/* not supported (declared false or not used in modelDescription.xml) */
fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]) { return n ? fmi2Error : fmi2OK; }
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[]) { return n ? fmi2Error : fmi2OK; }
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[]) { return n ? fmi2Error : fmi2OK; }
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]) { return n ? fmi2Error : fmi2OK; }
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[]) { return n ? fmi2Error : fmi2OK; }
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[]) { return n ? fmi2Error : fmi2OK; }
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu, const fmi2ValueReference z[],
                                        size_t nz, const fmi2Real dv[], fmi2Real dz[]) { return fmi2Error; }
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer order[],
                                       const fmi2Real value[]) { return fmi2Error; }
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer order[],
                                        fmi2Real value[]) { return fmi2Error; }
fmi2Status fmi2CancelStep(fmi2Component c) { return fmi2Error; }
fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) { return fmi2Discard; }
fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    if (s != fmi2LastSuccessfulTime) return fmi2Discard;
    *value = ((Instance *)c)->s.t;
    return fmi2OK;
}
fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) { return fmi2Discard; }
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) { return fmi2Discard; }
fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) { return fmi2Discard; }
