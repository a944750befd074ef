/* FMI 2.0 co-simulation interface shared by the simgap example models.
 *
 * The model file (model.c) holds the physics and exports a small table-driven interface:
 * every variable is a Real addressed by its value reference, which is its index into one
 * array. Each model folder's fmi2_glue.c includes this one file; simgap.build_fmu hashes every
 * file the compiler reads, so an edit here rebuilds every model.
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"

extern const char MODEL_GUID[];
extern const unsigned MODEL_N_REALS;
extern const double MODEL_START[];
/* 'p' parameter (settable before initialisation ends), 'i' input, 'o' output, 'l' local */
extern const char MODEL_CAUSALITY[];
extern const size_t MODEL_STATE_BYTES;
/* Both return NULL on success, else a static message naming the offending variable. */
extern const char *model_initialize(double *r, void *state);
extern const char *model_do_step(double *r, void *state, double time, double h);

enum phase { INSTANTIATED, INITIALIZATION, STEPPING, TERMINATED, FAILED };

typedef struct {
    double *r;
    void *state;
    double time;
    enum phase phase;
    fmi2CallbackFunctions cb;
    char *name;
    int logging;
} Component;

static void log_error(Component *c, const char *fmt, ...) {
    char message[512];
    va_list args;
    va_start(args, fmt);
    vsnprintf(message, sizeof message, fmt, args);
    va_end(args);
    if (c->cb.logger) c->cb.logger(c->cb.componentEnvironment, c->name, fmi2Error, "error", "%s", message);
}

static void restore_start(Component *c) {
    memcpy(c->r, MODEL_START, MODEL_N_REALS * sizeof(double));
    memset(c->state, 0, MODEL_STATE_BYTES);
    c->time = 0.0;
    c->phase = INSTANTIATED;
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component comp, fmi2Boolean on, size_t n, const fmi2String cats[]) {
    (void)n; (void)cats;
    ((Component *)comp)->logging = on;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String location,
                              const fmi2CallbackFunctions *cb, fmi2Boolean visible, fmi2Boolean logging) {
    (void)location; (void)visible;
    if (type != fmi2CoSimulation || !guid || strcmp(guid, MODEL_GUID) != 0) {
        if (cb && cb->logger)
            cb->logger(cb->componentEnvironment, name, fmi2Error, "error",
                       "only co-simulation with GUID %s is supported", MODEL_GUID);
        return NULL;
    }
    Component *c = calloc(1, sizeof(Component));
    if (!c) return NULL;
    c->r = calloc(MODEL_N_REALS, sizeof(double));
    c->state = calloc(1, MODEL_STATE_BYTES > 0 ? MODEL_STATE_BYTES : 1);
    c->name = strdup(name ? name : "instance");
    if (!c->r || !c->state || !c->name) {
        free(c->r); free(c->state); free(c->name); free(c);
        return NULL;
    }
    if (cb) c->cb = *cb;
    c->logging = logging;
    restore_start(c);
    return c;
}

void fmi2FreeInstance(fmi2Component comp) {
    Component *c = comp;
    if (!c) return;
    free(c->r); free(c->state); free(c->name); free(c);
}

fmi2Status fmi2SetupExperiment(fmi2Component comp, fmi2Boolean tolDefined, fmi2Real tol, fmi2Real start,
                               fmi2Boolean stopDefined, fmi2Real stop) {
    (void)tolDefined; (void)tol; (void)stopDefined; (void)stop;
    ((Component *)comp)->time = start;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component comp) {
    ((Component *)comp)->phase = INITIALIZATION;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component comp) {
    Component *c = comp;
    const char *problem = model_initialize(c->r, c->state);
    if (problem) {
        log_error(c, "%s", problem);
        c->phase = FAILED;
        return fmi2Error;
    }
    c->phase = STEPPING;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component comp) {
    ((Component *)comp)->phase = TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component comp) {
    restore_start(comp);
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    Component *c = comp;
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] >= MODEL_N_REALS) {
            log_error(c, "no Real variable with value reference %u", vr[i]);
            return fmi2Error;
        }
        value[i] = c->r[vr[i]];
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    Component *c = comp;
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] >= MODEL_N_REALS) {
            log_error(c, "no Real variable with value reference %u", vr[i]);
            return fmi2Error;
        }
        char kind = MODEL_CAUSALITY[vr[i]];
        int settable = kind == 'i' || (kind == 'p' && (c->phase == INSTANTIATED || c->phase == INITIALIZATION));
        if (!settable) {
            log_error(c, "variable with value reference %u cannot be set now", vr[i]);
            return fmi2Error;
        }
        c->r[vr[i]] = value[i];
    }
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer v[]) {
    (void)vr; (void)v;
    return nvr == 0 ? fmi2OK : (log_error(c, "the model has no Integer variables"), fmi2Error);
}
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean v[]) {
    (void)vr; (void)v;
    return nvr == 0 ? fmi2OK : (log_error(c, "the model has no Boolean variables"), fmi2Error);
}
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String v[]) {
    (void)vr; (void)v;
    return nvr == 0 ? fmi2OK : (log_error(c, "the model has no String variables"), fmi2Error);
}
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer v[]) {
    (void)vr; (void)v;
    return nvr == 0 ? fmi2OK : (log_error(c, "the model has no Integer variables"), fmi2Error);
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean v[]) {
    (void)vr; (void)v;
    return nvr == 0 ? fmi2OK : (log_error(c, "the model has no Boolean variables"), fmi2Error);
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String v[]) {
    (void)vr; (void)v;
    return nvr == 0 ? fmi2OK : (log_error(c, "the model has no String variables"), fmi2Error);
}

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)c; (void)s; return fmi2Error; }
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) { (void)c; (void)s; return fmi2Error; }
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)c; (void)s; return fmi2Error; }
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *n) {
    (void)c; (void)s; (void)n; return fmi2Error;
}
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n) {
    (void)c; (void)s; (void)b; (void)n; return fmi2Error;
}
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *s) {
    (void)c; (void)b; (void)n; (void)s; return fmi2Error;
}
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                        const fmi2ValueReference z[], size_t nz, const fmi2Real dv[],
                                        fmi2Real dz[]) {
    (void)c; (void)u; (void)nu; (void)z; (void)nz; (void)dv; (void)dz; return fmi2Error;
}
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)c; (void)vr; (void)nvr; (void)order; (void)value; return fmi2Error;
}
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
    (void)c; (void)vr; (void)nvr; (void)order; (void)value; return fmi2Error;
}

fmi2Status fmi2DoStep(fmi2Component comp, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior) {
    (void)noSetPrior;
    Component *c = comp;
    if (c->phase != STEPPING) {
        log_error(c, "doStep called before initialisation finished or after an error");
        return fmi2Error;
    }
    if (!(h > 0.0)) {
        log_error(c, "communication step size must be positive, got %g", h);
        return fmi2Error;
    }
    const char *problem = model_do_step(c->r, c->state, t, h);
    if (problem) {
        log_error(c, "at t = %g s: %s", t, problem);
        c->phase = FAILED;
        return fmi2Error;
    }
    c->time = t + h;
    return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component c) { (void)c; return fmi2Error; }

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *v) {
    (void)c; (void)s; *v = fmi2OK; return fmi2OK;
}
fmi2Status fmi2GetRealStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Real *v) {
    if (s != fmi2LastSuccessfulTime) return fmi2Discard;
    *v = ((Component *)comp)->time;
    return fmi2OK;
}
fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *v) {
    (void)c; (void)s; (void)v; return fmi2Discard;
}
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *v) {
    (void)c; (void)s; (void)v; return fmi2Discard;
}
fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *v) {
    (void)c; (void)s; (void)v; return fmi2Discard;
}
