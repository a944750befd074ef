/*
 * fault_zone: the quickstart zone with injected faults, for testing how a calibration survives
 * models that crash. The parameter `fault` (tune it like any other) selects a fault when it lies in
 * [<kind>_from, <kind>_to): segv (a real segmentation fault), abort (SIGABRT), hang (sleeps inside the
 * first doStep and never returns), nan (NaN outputs), slow (sleeps slow_s seconds in the first
 * doStep, then carries on). All regions are empty by default. Otherwise a copy of
 * quickstart_zone.c: the physics is unchanged.
 *
 * quickstart_zone: one heated zone, a water loop (radiators or floor heating) and an
 * air-to-water heat pump, as an FMI 2.0 FMU for co-simulation and model exchange.
 *
 *   P_el  = u_hp * P_el_nom * (1 + k_lift * (T_water - T_out - dT_lift_ref)),  P_el >= 0
 *   COP   = eta_carnot * T_water / max(T_water - T_out, dT_lift_min)
 *   Q_hp  = COP * P_el
 *   C_water dT_water/dt = Q_hp - UA_rad (T_water - T_zone)
 *   C_zone  dT_zone/dt  = UA_rad (T_water - T_zone) - UA_env (T_zone - T_out) + Q_int + Q_sol
 *
 * Q_sol (solar gains through the windows, an input) is a known absolute heat flow: without it,
 * scaling C_zone, UA_env, UA_rad and the heat pump output by one factor would leave the
 * temperatures almost unchanged, and the parameters could not be told apart from the data.
 *
 * Co-simulation integrates with explicit Euler at sub-steps of at most dt_internal inside each
 * doStep, deliberately: a calibration that tries a very small C_zone makes the integration
 * unstable, and the FMU then reports an error instead of returning nonsense.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <signal.h>
#include <unistd.h>

#include "fmi2Functions.h"

#define MODEL_GUID "{f4a1c2e0-3b7d-4e59-9a10-7c2d5e6f8b93}"

/* value references; the order matches modelDescription.xml (index = value reference + 1) */
enum {
    VR_T_OUT, VR_U_HP,
    VR_C_ZONE, VR_UA_ENV, VR_UA_RAD, VR_ETA_CARNOT,
    VR_P_EL_NOM, VR_K_LIFT, VR_C_WATER, VR_Q_INT, VR_T_ZONE_START, VR_T_WATER_START, VR_DT_INTERNAL,
    VR_DT_LIFT_REF, VR_DT_LIFT_MIN,
    VR_TAU_ZONE,
    VR_T_ZONE, VR_T_WATER, VR_P_EL, VR_Q_HP, VR_COP,
    VR_DER_T_ZONE, VR_DER_T_WATER,
    VR_Q_SOL,
    VR_FAULT, VR_SEGV_FROM, VR_SEGV_TO, VR_ABORT_FROM, VR_ABORT_TO, VR_HANG_FROM, VR_HANG_TO, VR_NAN_FROM, VR_NAN_TO, VR_SLOW_FROM, VR_SLOW_TO, VR_SLOW_S,
    N_REALS
};

static const double START_VALUES[N_REALS] = {
    [VR_T_OUT] = 273.15, [VR_U_HP] = 0.0,
    [VR_C_ZONE] = 1.5e7, [VR_UA_ENV] = 200.0, [VR_UA_RAD] = 300.0, [VR_ETA_CARNOT] = 0.4,
    [VR_P_EL_NOM] = 2500.0, [VR_K_LIFT] = 0.02, [VR_C_WATER] = 8e5, [VR_Q_INT] = 300.0,
    [VR_T_ZONE_START] = 292.65, [VR_T_WATER_START] = 298.15, [VR_DT_INTERNAL] = 60.0,
    [VR_DT_LIFT_REF] = 30.0, [VR_DT_LIFT_MIN] = 5.0,
    [VR_FAULT] = 0.0,
    [VR_SEGV_FROM] = 2.0,
    [VR_SEGV_TO] = 2.0,
    [VR_ABORT_FROM] = 2.0,
    [VR_ABORT_TO] = 2.0,
    [VR_HANG_FROM] = 2.0,
    [VR_HANG_TO] = 2.0,
    [VR_NAN_FROM] = 2.0,
    [VR_NAN_TO] = 2.0,
    [VR_SLOW_FROM] = 2.0,
    [VR_SLOW_TO] = 2.0,
    [VR_SLOW_S] = 0.0,
};

static const char *const NAMES[N_REALS] = {
    "T_out", "u_hp", "C_zone", "UA_env", "UA_rad", "eta_carnot", "P_el_nom", "k_lift",
    "C_water", "Q_int", "T_zone_start", "T_water_start", "dt_internal", "dT_lift_ref",
    "dT_lift_min", "tau_zone", "T_zone", "T_water", "P_el", "Q_hp", "COP", "der(T_zone)",
    "der(T_water)", "Q_sol",
    "fault", "segv_from", "segv_to", "abort_from", "abort_to", "hang_from", "hang_to", "nan_from", "nan_to", "slow_from", "slow_to", "slow_s",
};

#define T_MIN 200.0
#define T_MAX 400.0

typedef enum { MODE_INSTANTIATED, MODE_INITIALIZATION, MODE_STEP, MODE_TERMINATED, MODE_ERROR } Mode;

typedef struct {
    double r[N_REALS];
    double time;
    Mode mode;
    fmi2Type type;
    fmi2Boolean logging_on;
    int stepped; /* a doStep has run since the last reset */
    char *instance_name;
    const fmi2CallbackFunctions *callbacks;
} Instance;

__attribute__((format(printf, 4, 5)))
static void log_message(Instance *m, fmi2Status status, const char *category, const char *format, ...) {
    if (!m->callbacks || !m->callbacks->logger) return;
    if (status == fmi2OK && !m->logging_on) return;
    char buffer[512];
    va_list args;
    va_start(args, format);
    vsnprintf(buffer, sizeof buffer, format, args);
    va_end(args);
    m->callbacks->logger(m->callbacks->componentEnvironment, m->instance_name, status, category, "%s", buffer);
}

__attribute__((format(printf, 2, 3)))
static fmi2Status fail(Instance *m, const char *format, ...) {
    char buffer[512];
    va_list args;
    va_start(args, format);
    vsnprintf(buffer, sizeof buffer, format, args);
    va_end(args);
    log_message(m, fmi2Error, "logStatusError", "%s", buffer);
    m->mode = MODE_ERROR;
    return fmi2Error;
}

static void reset_values(Instance *m) {
    memcpy(m->r, START_VALUES, sizeof m->r);
    m->r[VR_T_ZONE] = m->r[VR_T_ZONE_START];
    m->r[VR_T_WATER] = m->r[VR_T_WATER_START];
    m->time = 0.0;
    m->stepped = 0;
    m->mode = MODE_INSTANTIATED;
}

static int in_region(const Instance *m, int from, int to);

/* Everything that follows from the states, inputs and parameters. */
static void compute(Instance *m) {
    double *r = m->r;
    if (m->mode == MODE_INSTANTIATED || m->mode == MODE_INITIALIZATION) {
        r[VR_T_ZONE] = r[VR_T_ZONE_START];
        r[VR_T_WATER] = r[VR_T_WATER_START];
    }
    const double t_water = r[VR_T_WATER], t_zone = r[VR_T_ZONE], t_out = r[VR_T_OUT];
    double u = r[VR_U_HP];
    u = u < 0.0 ? 0.0 : (u > 1.0 ? 1.0 : u);
    double p_el = u * r[VR_P_EL_NOM] * (1.0 + r[VR_K_LIFT] * (t_water - t_out - r[VR_DT_LIFT_REF]));
    if (p_el < 0.0) p_el = 0.0;
    double lift = t_water - t_out;
    if (lift < r[VR_DT_LIFT_MIN]) lift = r[VR_DT_LIFT_MIN];
    const double cop = r[VR_ETA_CARNOT] * t_water / lift;
    const double q_hp = cop * p_el;
    const double q_rad = r[VR_UA_RAD] * (t_water - t_zone);
    r[VR_P_EL] = p_el;
    r[VR_COP] = cop;
    r[VR_Q_HP] = q_hp;
    r[VR_TAU_ZONE] = r[VR_C_ZONE] / r[VR_UA_ENV];
    r[VR_DER_T_WATER] = (q_hp - q_rad) / r[VR_C_WATER];
    r[VR_DER_T_ZONE] = (q_rad - r[VR_UA_ENV] * (t_zone - t_out) + r[VR_Q_INT] + r[VR_Q_SOL]) / r[VR_C_ZONE];
    if (m->stepped && in_region(m, VR_NAN_FROM, VR_NAN_TO)) r[VR_P_EL] = NAN; /* an output only: the states stay finite */
}

static fmi2Status check_parameters(Instance *m) {
    static const int positive[] = {VR_C_ZONE, VR_UA_ENV, VR_UA_RAD, VR_ETA_CARNOT, VR_C_WATER, VR_DT_INTERNAL};
    for (size_t i = 0; i < sizeof positive / sizeof positive[0]; i++) {
        const int vr = positive[i];
        if (!(m->r[vr] > 0.0) || !isfinite(m->r[vr]))
            return fail(m, "parameter %s must be positive and finite, got %g", NAMES[vr], m->r[vr]);
    }
    if (!(m->r[VR_P_EL_NOM] >= 0.0)) return fail(m, "parameter P_el_nom must not be negative, got %g", m->r[VR_P_EL_NOM]);
    return fmi2OK;
}

static fmi2Status check_states(Instance *m) {
    const double t_zone = m->r[VR_T_ZONE], t_water = m->r[VR_T_WATER];
    if (!(t_zone >= T_MIN && t_zone <= T_MAX)) {
        log_message(m, fmi2Error, "logStatusError",
                    "zone temperature left the physical range [%g K, %g K] (T_zone = %g K at t = %g s): "
                    "explicit integration unstable, C_zone too small for dt_internal "
                    "(stable needs dt_internal <= 2*C_zone/(UA_env+UA_rad) = %g s, dt_internal = %g s)",
                    T_MIN, T_MAX, t_zone, m->time,
                    2.0 * m->r[VR_C_ZONE] / (m->r[VR_UA_ENV] + m->r[VR_UA_RAD]), m->r[VR_DT_INTERNAL]);
        m->mode = MODE_ERROR;
        return fmi2Error;
    }
    if (!(t_water >= T_MIN && t_water <= T_MAX)) {
        log_message(m, fmi2Error, "logStatusError",
                    "water temperature left the physical range [%g K, %g K] (T_water = %g K at t = %g s): "
                    "explicit integration unstable, C_water too small for dt_internal",
                    T_MIN, T_MAX, t_water, m->time);
        m->mode = MODE_ERROR;
        return fmi2Error;
    }
    return fmi2OK;
}

static int is_settable(const Instance *m, fmi2ValueReference vr) {
    if (vr == VR_T_OUT || vr == VR_U_HP || vr == VR_Q_INT || vr == VR_Q_SOL) return 1;
    if ((vr >= VR_C_ZONE && vr <= VR_DT_INTERNAL) || vr >= VR_FAULT)
        return m->mode == MODE_INSTANTIATED || m->mode == MODE_INITIALIZATION;
    return 0;
}

/* ---- common functions ------------------------------------------------------------------- */

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn) {
    (void)fmuResourceLocation;
    (void)visible;
    if (!functions || !functions->allocateMemory || !functions->freeMemory) return NULL;
    if (!instanceName || !fmuGUID || strcmp(fmuGUID, MODEL_GUID) != 0) {
        if (functions->logger)
            functions->logger(functions->componentEnvironment, instanceName ? instanceName : "?", fmi2Error,
                              "logStatusError", "wrong GUID %s, expected %s", fmuGUID ? fmuGUID : "(null)", MODEL_GUID);
        return NULL;
    }
    Instance *m = functions->allocateMemory(1, sizeof(Instance));
    if (!m) return NULL;
    m->instance_name = functions->allocateMemory(strlen(instanceName) + 1, 1);
    if (!m->instance_name) {
        functions->freeMemory(m);
        return NULL;
    }
    strcpy(m->instance_name, instanceName);
    m->callbacks = functions;
    m->type = fmuType;
    m->logging_on = loggingOn;
    reset_values(m);
    return m;
}

void fmi2FreeInstance(fmi2Component c) {
    Instance *m = c;
    if (!m) return;
    fmi2CallbackFreeMemory free_memory = m->callbacks->freeMemory;
    free_memory(m->instance_name);
    free_memory(m);
}

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[]) {
    (void)nCategories;
    (void)categories;
    ((Instance *)c)->logging_on = loggingOn;
    return fmi2OK;
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    (void)toleranceDefined;
    (void)tolerance;
    (void)stopTimeDefined;
    (void)stopTime;
    Instance *m = c;
    if (m->mode != MODE_INSTANTIATED) return fail(m, "fmi2SetupExperiment called outside the instantiated state (mode %d)", (int)m->mode);
    m->time = startTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    Instance *m = c;
    if (m->mode != MODE_INSTANTIATED) return fail(m, "fmi2EnterInitializationMode called twice (mode %d)", (int)m->mode);
    m->mode = MODE_INITIALIZATION;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    Instance *m = c;
    if (m->mode != MODE_INITIALIZATION) return fail(m, "fmi2ExitInitializationMode outside initialization mode (mode %d)", (int)m->mode);
    fmi2Status status = check_parameters(m);
    if (status != fmi2OK) return status;
    compute(m); /* still in initialization mode: takes the states from their start parameters */
    m->mode = MODE_STEP;
    return check_states(m);
}

fmi2Status fmi2Terminate(fmi2Component c) {
    ((Instance *)c)->mode = MODE_TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c) {
    reset_values(c);
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[]) {
    Instance *m = c;
    if (nvr == 0) return fmi2OK;
    compute(m);
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] >= N_REALS) return fail(m, "fmi2GetReal: unknown value reference %u", (unsigned)vr[i]);
        value[i] = m->r[vr[i]];
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[]) {
    Instance *m = c;
    for (size_t i = 0; i < nvr; i++) {
        if (vr[i] >= N_REALS) return fail(m, "fmi2SetReal: unknown value reference %u", (unsigned)vr[i]);
        if (!is_settable(m, vr[i])) {
            log_message(m, fmi2Error, "logStatusError", "variable %s cannot be set now", NAMES[vr[i]]);
            return fmi2Error;
        }
        m->r[vr[i]] = value[i];
    }
    return fmi2OK;
}

/* the model has only Real variables */
fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[]) {
    (void)vr; (void)value;
    return nvr ? fail(c, "fmi2GetInteger: the model has no Integer variables (%g asked)", (double)nvr) : fmi2OK;
}
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[]) {
    (void)vr; (void)value;
    return nvr ? fail(c, "fmi2GetBoolean: the model has no Boolean variables (%g asked)", (double)nvr) : fmi2OK;
}
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2String value[]) {
    (void)vr; (void)value;
    return nvr ? fail(c, "fmi2GetString: the model has no String variables (%g asked)", (double)nvr) : fmi2OK;
}
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[]) {
    (void)vr; (void)value;
    return nvr ? fail(c, "fmi2SetInteger: the model has no Integer variables (%g given)", (double)nvr) : fmi2OK;
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[]) {
    (void)vr; (void)value;
    return nvr ? fail(c, "fmi2SetBoolean: the model has no Boolean variables (%g given)", (double)nvr) : fmi2OK;
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[]) {
    (void)vr; (void)value;
    return nvr ? fail(c, "fmi2SetString: the model has no String variables (%g given)", (double)nvr) : fmi2OK;
}

/* canGetAndSetFMUstate and providesDirectionalDerivative are false in modelDescription.xml */
fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *state) { (void)state; return fail(c, "fmi2GetFMUstate is not supported"); }
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) { (void)state; return fail(c, "fmi2SetFMUstate is not supported"); }
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state) { (void)state; return fail(c, "fmi2FreeFMUstate is not supported"); }
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t *size) { (void)state; (void)size; return fail(c, "fmi2SerializedFMUstateSize is not supported"); }
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state, fmi2Byte bytes[], size_t size) { (void)state; (void)bytes; (void)size; return fail(c, "fmi2SerializeFMUstate is not supported"); }
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size, fmi2FMUstate *state) { (void)bytes; (void)size; (void)state; return fail(c, "fmi2DeSerializeFMUstate is not supported"); }
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference vUnknown_ref[], size_t nUnknown,
                                        const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[]) {
    (void)vUnknown_ref; (void)nUnknown; (void)vKnown_ref; (void)nKnown; (void)dvKnown; (void)dvUnknown;
    return fail(c, "fmi2GetDirectionalDerivative is not supported");
}

/* ---- co-simulation ---------------------------------------------------------------------- */

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr; (void)order; (void)value;
    return nvr ? fail(c, "fmi2SetRealInputDerivatives is not supported (%g given)", (double)nvr) : fmi2OK;
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[]) {
    (void)vr; (void)order; (void)value;
    return nvr ? fail(c, "fmi2GetRealOutputDerivatives is not supported (%g asked)", (double)nvr) : fmi2OK;
}

static int in_region(const Instance *m, int from, int to) {
    return m->r[VR_FAULT] >= m->r[from] && m->r[VR_FAULT] < m->r[to];
}

/* The injected faults, checked at the first step of a run. */
static void inject_faults(Instance *m) {
    if (in_region(m, VR_SEGV_FROM, VR_SEGV_TO)) {
        volatile double *nowhere = NULL;
        *nowhere = m->r[VR_FAULT]; /* a real segmentation fault */
    }
    if (in_region(m, VR_ABORT_FROM, VR_ABORT_TO)) abort();
    if (in_region(m, VR_HANG_FROM, VR_HANG_TO))
        for (;;) sleep(1); /* stuck inside a step: never returns */
    if (in_region(m, VR_SLOW_FROM, VR_SLOW_TO) && m->r[VR_SLOW_S] > 0.0)
        usleep((useconds_t)(m->r[VR_SLOW_S] * 1e6));
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint, fmi2Real communicationStepSize,
                      fmi2Boolean noSetFMUStatePriorToCurrentCommunicationPoint) {
    (void)noSetFMUStatePriorToCurrentCommunicationPoint;
    Instance *m = c;
    if (m->mode != MODE_STEP) return fail(m, "fmi2DoStep called outside step mode (mode %d)", (int)m->mode);
    if (!(communicationStepSize > 0.0)) return fail(m, "fmi2DoStep: step size must be positive, got %g", communicationStepSize);
    const long n_sub = (long)ceil(communicationStepSize / m->r[VR_DT_INTERNAL] - 1e-9);
    const double h = communicationStepSize / (double)n_sub;
    if (!m->stepped) inject_faults(m);
    m->stepped = 1;
    m->time = currentCommunicationPoint;
    for (long i = 0; i < n_sub; i++) {
        compute(m);
        m->r[VR_T_ZONE] += h * m->r[VR_DER_T_ZONE];
        m->r[VR_T_WATER] += h * m->r[VR_DER_T_WATER];
        m->time = currentCommunicationPoint + (double)(i + 1) * h;
        if (check_states(m) != fmi2OK) return fmi2Error;
    }
    m->time = currentCommunicationPoint + communicationStepSize;
    return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component c) { return fail(c, "fmi2CancelStep: doStep never runs asynchronously"); }

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    (void)s; (void)value;
    return fail(c, "fmi2GetStatus: no asynchronous status to report");
}
fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    Instance *m = c;
    if (s == fmi2LastSuccessfulTime) {
        *value = m->time;
        return fmi2OK;
    }
    return fail(c, "fmi2GetRealStatus: unsupported status kind %d", (int)s);
}
fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value) {
    (void)value;
    return fail(c, "fmi2GetIntegerStatus: unsupported status kind %d", (int)s);
}
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value) {
    if (s == fmi2Terminated) {
        *value = fmi2False;
        return fmi2OK;
    }
    return fail(c, "fmi2GetBooleanStatus: unsupported status kind %d", (int)s);
}
fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value) {
    (void)value;
    return fail(c, "fmi2GetStringStatus: unsupported status kind %d", (int)s);
}

/* ---- model exchange ---------------------------------------------------------------------- */

fmi2Status fmi2EnterEventMode(fmi2Component c) { (void)c; return fmi2OK; }

fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *eventInfo) {
    (void)c;
    eventInfo->newDiscreteStatesNeeded = fmi2False;
    eventInfo->terminateSimulation = fmi2False;
    eventInfo->nominalsOfContinuousStatesChanged = fmi2False;
    eventInfo->valuesOfContinuousStatesChanged = fmi2False;
    eventInfo->nextEventTimeDefined = fmi2False;
    eventInfo->nextEventTime = 0.0;
    return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c) { (void)c; return fmi2OK; }

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi2Boolean *enterEventMode, fmi2Boolean *terminateSimulation) {
    (void)noSetFMUStatePriorToCurrentPoint;
    *enterEventMode = fmi2False;
    *terminateSimulation = fmi2False;
    return check_states(c);
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time) {
    ((Instance *)c)->time = time;
    return fmi2OK;
}

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx) {
    Instance *m = c;
    if (nx != 2) return fail(m, "fmi2SetContinuousStates: the model has 2 states, got %g", (double)nx);
    m->r[VR_T_ZONE] = x[0];
    m->r[VR_T_WATER] = x[1];
    return fmi2OK;
}

fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx) {
    Instance *m = c;
    if (nx != 2) return fail(m, "fmi2GetContinuousStates: the model has 2 states, got %g", (double)nx);
    compute(m);
    x[0] = m->r[VR_T_ZONE];
    x[1] = m->r[VR_T_WATER];
    return fmi2OK;
}

fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real derivatives[], size_t nx) {
    Instance *m = c;
    if (nx != 2) return fail(m, "fmi2GetDerivatives: the model has 2 states, got %g", (double)nx);
    compute(m);
    derivatives[0] = m->r[VR_DER_T_ZONE];
    derivatives[1] = m->r[VR_DER_T_WATER];
    return fmi2OK;
}

fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real eventIndicators[], size_t ni) {
    (void)eventIndicators;
    return ni ? fail(c, "fmi2GetEventIndicators: the model has no event indicators, %g asked", (double)ni) : fmi2OK;
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x_nominal[], size_t nx) {
    (void)c;
    for (size_t i = 0; i < nx; i++) x_nominal[i] = 300.0;
    return fmi2OK;
}
