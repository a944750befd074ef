/*
 * quickstart_zone_fmi3: the quickstart zone (../quickstart_zone) as an FMI 3.0 FMU for
 * co-simulation and model exchange. Same physics, same parameters, same value references, same
 * explicit Euler sub-steps in doStep: for equal inputs and parameters it returns the FMI 2.0
 * twin's numbers exactly (tests/test_fmi3.py compares them).
 *
 *   P_el  = u_hp * P_el_nom * (1 + k_lift * (T_water - T_out - dT_lift_ref)),  P_el >= 0
 *   COP   = eta_carnot * T_water / max(T_water - T_out, dT_lift_min)
 *   Q_hp  = COP * P_el
 *   C_water dT_water/dt = Q_hp - UA_rad (T_water - T_zone)
 *   C_zone  dT_zone/dt  = UA_rad (T_water - T_zone) - UA_env (T_zone - T_out) + Q_int + Q_sol
 *
 * What FMI 3.0 changes here: Float64 instead of Real, an instantiation token instead of the
 * GUID, one Instantiate function per interface, the start time given to EnterInitializationMode,
 * a time variable of causality "independent", and doStep's extra results (event handling,
 * termination, early return, last successful time). Every FMI 3.0 function is exported; the
 * ones the model has no use for refuse with a message.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"

#define INSTANTIATION_TOKEN "{9e3f1c52-6a0b-4d8e-b7f4-2c5a8e1d6b93}"

/* value references; the same as the FMI 2.0 quickstart zone, plus the independent time */
enum {
    VR_T_OUT, VR_U_HP,
    VR_C_ZONE, VR_UA_ENV, VR_UA_RAD, VR_ETA_CARNOT,
    VR_P_EL_NOM, VR_K_LIFT, VR_C_WATER, VR_Q_INT, VR_T_ZONE_START, VR_T_WATER_START, VR_DT_INTERNAL,
    VR_DT_LIFT_REF, VR_DT_LIFT_MIN,
    VR_TAU_ZONE,
    VR_T_ZONE, VR_T_WATER, VR_P_EL, VR_Q_HP, VR_COP,
    VR_DER_T_ZONE, VR_DER_T_WATER,
    VR_Q_SOL,
    N_REALS
};
#define VR_TIME 100

static const double START_VALUES[N_REALS] = {
    [VR_T_OUT] = 273.15, [VR_U_HP] = 0.0,
    [VR_C_ZONE] = 1.5e7, [VR_UA_ENV] = 200.0, [VR_UA_RAD] = 300.0, [VR_ETA_CARNOT] = 0.4,
    [VR_P_EL_NOM] = 2500.0, [VR_K_LIFT] = 0.02, [VR_C_WATER] = 8e5, [VR_Q_INT] = 300.0,
    [VR_T_ZONE_START] = 292.65, [VR_T_WATER_START] = 298.15, [VR_DT_INTERNAL] = 60.0,
    [VR_DT_LIFT_REF] = 30.0, [VR_DT_LIFT_MIN] = 5.0,
};

static const char *const NAMES[N_REALS] = {
    "T_out", "u_hp", "C_zone", "UA_env", "UA_rad", "eta_carnot", "P_el_nom", "k_lift",
    "C_water", "Q_int", "T_zone_start", "T_water_start", "dt_internal", "dT_lift_ref",
    "dT_lift_min", "tau_zone", "T_zone", "T_water", "P_el", "Q_hp", "COP", "der(T_zone)",
    "der(T_water)", "Q_sol",
};

#define T_MIN 200.0
#define T_MAX 400.0
#define N_STATES 2

typedef enum {
    MODE_INSTANTIATED, MODE_INITIALIZATION, MODE_EVENT, MODE_CONTINUOUS_TIME, MODE_STEP, MODE_TERMINATED, MODE_ERROR
} Mode;

typedef struct {
    double r[N_REALS];
    double time;
    Mode mode;
    int co_simulation;
    fmi3Boolean logging_on;
    char *instance_name;
    fmi3InstanceEnvironment environment;
    fmi3LogMessageCallback log;
} Instance;

__attribute__((format(printf, 4, 5)))
static void log_message(Instance *m, fmi3Status status, const char *category, const char *format, ...) {
    if (!m->log) return;
    if (status == fmi3OK && !m->logging_on) return;
    char buffer[512];
    va_list args;
    va_start(args, format);
    vsnprintf(buffer, sizeof buffer, format, args);
    va_end(args);
    m->log(m->environment, status, category, buffer);
}

__attribute__((format(printf, 2, 3)))
static fmi3Status fail(Instance *m, const char *format, ...) {
    char buffer[512];
    va_list args;
    va_start(args, format);
    vsnprintf(buffer, sizeof buffer, format, args);
    va_end(args);
    log_message(m, fmi3Error, "logStatusError", "%s", buffer);
    m->mode = MODE_ERROR;
    return fmi3Error;
}

static void reset_values(Instance *m) {
    memcpy(m->r, START_VALUES, sizeof m->r);
    m->r[VR_T_ZONE] = m->r[VR_T_ZONE_START];
    m->r[VR_T_WATER] = m->r[VR_T_WATER_START];
    m->time = 0.0;
    m->mode = MODE_INSTANTIATED;
}

/* Everything that follows from the states, inputs and parameters (as in quickstart_zone.c). */
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
}

static fmi3Status check_parameters(Instance *m) {
    static const int positive[] = {VR_C_ZONE, VR_UA_ENV, VR_UA_RAD, VR_ETA_CARNOT, VR_C_WATER, VR_DT_INTERNAL};
    for (size_t i = 0; i < sizeof positive / sizeof positive[0]; i++) {
        const int vr = positive[i];
        if (!(m->r[vr] > 0.0) || !isfinite(m->r[vr]))
            return fail(m, "parameter %s must be positive and finite, got %g", NAMES[vr], m->r[vr]);
    }
    if (!(m->r[VR_P_EL_NOM] >= 0.0)) return fail(m, "parameter P_el_nom must not be negative, got %g", m->r[VR_P_EL_NOM]);
    return fmi3OK;
}

static fmi3Status check_states(Instance *m) {
    const double t_zone = m->r[VR_T_ZONE], t_water = m->r[VR_T_WATER];
    if (!(t_zone >= T_MIN && t_zone <= T_MAX)) {
        log_message(m, fmi3Error, "logStatusError",
                    "zone temperature left the physical range [%g K, %g K] (T_zone = %g K at t = %g s): "
                    "explicit integration unstable, C_zone too small for dt_internal "
                    "(stable needs dt_internal <= 2*C_zone/(UA_env+UA_rad) = %g s, dt_internal = %g s)",
                    T_MIN, T_MAX, t_zone, m->time,
                    2.0 * m->r[VR_C_ZONE] / (m->r[VR_UA_ENV] + m->r[VR_UA_RAD]), m->r[VR_DT_INTERNAL]);
        m->mode = MODE_ERROR;
        return fmi3Error;
    }
    if (!(t_water >= T_MIN && t_water <= T_MAX)) {
        log_message(m, fmi3Error, "logStatusError",
                    "water temperature left the physical range [%g K, %g K] (T_water = %g K at t = %g s): "
                    "explicit integration unstable, C_water too small for dt_internal",
                    T_MIN, T_MAX, t_water, m->time);
        m->mode = MODE_ERROR;
        return fmi3Error;
    }
    return fmi3OK;
}

/* inputs and the tunable Q_int always; fixed parameters before initialisation ends */
static int is_settable(const Instance *m, fmi3ValueReference vr) {
    if (vr == VR_T_OUT || vr == VR_U_HP || vr == VR_Q_INT || vr == VR_Q_SOL) return 1;
    if (vr >= VR_C_ZONE && vr <= VR_DT_INTERNAL)
        return m->mode == MODE_INSTANTIATED || m->mode == MODE_INITIALIZATION;
    return 0;
}

static Instance *new_instance(fmi3String name, fmi3String token, fmi3Boolean logging_on,
                              fmi3InstanceEnvironment environment, fmi3LogMessageCallback log, int co_simulation) {
    if (!token || strcmp(token, INSTANTIATION_TOKEN) != 0) {
        if (log) {
            char message[256];
            snprintf(message, sizeof message, "wrong instantiation token %s, expected %s", token ? token : "(null)", INSTANTIATION_TOKEN);
            log(environment, fmi3Error, "logStatusError", message);
        }
        return NULL;
    }
    Instance *m = calloc(1, sizeof(Instance));
    if (!m) return NULL;
    m->instance_name = strdup(name ? name : "instance");
    if (!m->instance_name) {
        free(m);
        return NULL;
    }
    m->environment = environment;
    m->log = log;
    m->logging_on = logging_on;
    m->co_simulation = co_simulation;
    reset_values(m);
    return m;
}

/* ---- common functions ------------------------------------------------------------------- */

const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories, const fmi3String categories[]) {
    (void)nCategories; (void)categories;
    ((Instance *)instance)->logging_on = loggingOn;
    return fmi3OK;
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
                                          fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment, fmi3LogMessageCallback logMessage) {
    (void)resourcePath; (void)visible;
    return new_instance(instanceName, instantiationToken, loggingOn, instanceEnvironment, logMessage, 0);
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
                                         fmi3Boolean visible, fmi3Boolean loggingOn, fmi3Boolean eventModeUsed,
                                         fmi3Boolean earlyReturnAllowed, const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables, fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage, fmi3IntermediateUpdateCallback intermediateUpdate) {
    (void)resourcePath; (void)visible; (void)earlyReturnAllowed; (void)requiredIntermediateVariables;
    (void)nRequiredIntermediateVariables; (void)intermediateUpdate;
    if (eventModeUsed) {
        if (logMessage) logMessage(instanceEnvironment, fmi3Error, "logStatusError", "event mode is not supported (hasEventMode is false)");
        return NULL;
    }
    return new_instance(instanceName, instantiationToken, loggingOn, instanceEnvironment, logMessage, 1);
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken, fmi3String resourcePath,
                                               fmi3Boolean visible, fmi3Boolean loggingOn, fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption, fmi3UnlockPreemptionCallback unlockPreemption) {
    (void)instanceName; (void)instantiationToken; (void)resourcePath; (void)visible; (void)loggingOn;
    (void)clockUpdate; (void)lockPreemption; (void)unlockPreemption;
    if (logMessage) logMessage(instanceEnvironment, fmi3Error, "logStatusError", "scheduled execution is not supported");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance instance) {
    Instance *m = instance;
    if (!m) return;
    free(m->instance_name);
    free(m);
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
    (void)toleranceDefined; (void)tolerance; (void)stopTimeDefined; (void)stopTime;
    Instance *m = instance;
    if (m->mode != MODE_INSTANTIATED) return fail(m, "fmi3EnterInitializationMode called outside the instantiated state (mode %d)", (int)m->mode);
    m->time = startTime;
    m->mode = MODE_INITIALIZATION;
    return fmi3OK;
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
    Instance *m = instance;
    if (m->mode != MODE_INITIALIZATION) return fail(m, "fmi3ExitInitializationMode outside initialization mode (mode %d)", (int)m->mode);
    fmi3Status status = check_parameters(m);
    if (status != fmi3OK) return status;
    compute(m); /* still in initialization mode: takes the states from their start parameters */
    m->mode = m->co_simulation ? MODE_STEP : MODE_EVENT;
    return check_states(m);
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
    Instance *m = instance;
    if (m->co_simulation) return fail(m, "fmi3EnterEventMode: co-simulation without event mode");
    m->mode = MODE_EVENT;
    return fmi3OK;
}

fmi3Status fmi3Terminate(fmi3Instance instance) {
    ((Instance *)instance)->mode = MODE_TERMINATED;
    return fmi3OK;
}

fmi3Status fmi3Reset(fmi3Instance instance) {
    reset_values(instance);
    return fmi3OK;
}

/* ---- getting and setting values: only Float64 variables -------------------------------- */

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          fmi3Float64 values[], size_t nValues) {
    Instance *m = instance;
    if (nValues != nValueReferences) return fail(m, "fmi3GetFloat64: %zu values for %zu scalar variables", nValues, nValueReferences);
    if (nValueReferences == 0) return fmi3OK;
    compute(m);
    for (size_t i = 0; i < nValueReferences; i++) {
        if (valueReferences[i] == VR_TIME) {
            values[i] = m->time;
            continue;
        }
        if (valueReferences[i] >= N_REALS) return fail(m, "fmi3GetFloat64: unknown value reference %u", (unsigned)valueReferences[i]);
        values[i] = m->r[valueReferences[i]];
    }
    return fmi3OK;
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          const fmi3Float64 values[], size_t nValues) {
    Instance *m = instance;
    if (nValues != nValueReferences) return fail(m, "fmi3SetFloat64: %zu values for %zu scalar variables", nValues, nValueReferences);
    for (size_t i = 0; i < nValueReferences; i++) {
        if (valueReferences[i] >= N_REALS) return fail(m, "fmi3SetFloat64: unknown or read-only value reference %u", (unsigned)valueReferences[i]);
        if (!is_settable(m, valueReferences[i])) {
            log_message(m, fmi3Error, "logStatusError", "variable %s cannot be set now", NAMES[valueReferences[i]]);
            return fmi3Error;
        }
        m->r[valueReferences[i]] = values[i];
    }
    return fmi3OK;
}

/* The model has no variables of the other types: asking for any is an error, asking for none is fine. */
#define NO_VARIABLES_OF_TYPE(function, type, constness)                                                       \
    fmi3Status function(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, \
                        constness type values[], size_t nValues) {                                            \
        (void)valueReferences; (void)values; (void)nValues;                                                   \
        return nValueReferences ? fail(instance, #function ": the model has only Float64 variables") : fmi3OK; \
    }

NO_VARIABLES_OF_TYPE(fmi3GetFloat32, fmi3Float32, )
NO_VARIABLES_OF_TYPE(fmi3GetInt8, fmi3Int8, )
NO_VARIABLES_OF_TYPE(fmi3GetUInt8, fmi3UInt8, )
NO_VARIABLES_OF_TYPE(fmi3GetInt16, fmi3Int16, )
NO_VARIABLES_OF_TYPE(fmi3GetUInt16, fmi3UInt16, )
NO_VARIABLES_OF_TYPE(fmi3GetInt32, fmi3Int32, )
NO_VARIABLES_OF_TYPE(fmi3GetUInt32, fmi3UInt32, )
NO_VARIABLES_OF_TYPE(fmi3GetInt64, fmi3Int64, )
NO_VARIABLES_OF_TYPE(fmi3GetUInt64, fmi3UInt64, )
NO_VARIABLES_OF_TYPE(fmi3GetBoolean, fmi3Boolean, )
NO_VARIABLES_OF_TYPE(fmi3GetString, fmi3String, )
NO_VARIABLES_OF_TYPE(fmi3SetFloat32, fmi3Float32, const)
NO_VARIABLES_OF_TYPE(fmi3SetInt8, fmi3Int8, const)
NO_VARIABLES_OF_TYPE(fmi3SetUInt8, fmi3UInt8, const)
NO_VARIABLES_OF_TYPE(fmi3SetInt16, fmi3Int16, const)
NO_VARIABLES_OF_TYPE(fmi3SetUInt16, fmi3UInt16, const)
NO_VARIABLES_OF_TYPE(fmi3SetInt32, fmi3Int32, const)
NO_VARIABLES_OF_TYPE(fmi3SetUInt32, fmi3UInt32, const)
NO_VARIABLES_OF_TYPE(fmi3SetInt64, fmi3Int64, const)
NO_VARIABLES_OF_TYPE(fmi3SetUInt64, fmi3UInt64, const)
NO_VARIABLES_OF_TYPE(fmi3SetBoolean, fmi3Boolean, const)
NO_VARIABLES_OF_TYPE(fmi3SetString, fmi3String, const)

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         size_t valueSizes[], fmi3Binary values[], size_t nValues) {
    (void)valueReferences; (void)valueSizes; (void)values; (void)nValues;
    return nValueReferences ? fail(instance, "fmi3GetBinary: the model has only Float64 variables") : fmi3OK;
}
fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         const size_t valueSizes[], const fmi3Binary values[], size_t nValues) {
    (void)valueReferences; (void)valueSizes; (void)values; (void)nValues;
    return nValueReferences ? fail(instance, "fmi3SetBinary: the model has only Float64 variables") : fmi3OK;
}
fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Clock values[]) {
    (void)valueReferences; (void)values;
    return nValueReferences ? fail(instance, "fmi3GetClock: the model has no clocks") : fmi3OK;
}
fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, const fmi3Clock values[]) {
    (void)valueReferences; (void)values;
    return nValueReferences ? fail(instance, "fmi3SetClock: the model has no clocks") : fmi3OK;
}

/* ---- optional capabilities the modelDescription does not declare ----------------------- */

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference valueReference, size_t *nDependencies) {
    (void)valueReference; (void)nDependencies;
    return fail(instance, "fmi3GetNumberOfVariableDependencies is not supported");
}
fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent, size_t elementIndicesOfDependent[],
                                       fmi3ValueReference independents[], size_t elementIndicesOfIndependents[],
                                       fmi3DependencyKind dependencyKinds[], size_t nDependencies) {
    (void)dependent; (void)elementIndicesOfDependent; (void)independents; (void)elementIndicesOfIndependents;
    (void)dependencyKinds; (void)nDependencies;
    return fail(instance, "fmi3GetVariableDependencies is not supported");
}
fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState) { (void)FMUState; return fail(instance, "fmi3GetFMUState is not supported"); }
fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState) { (void)FMUState; return fail(instance, "fmi3SetFMUState is not supported"); }
fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState) { (void)FMUState; return fail(instance, "fmi3FreeFMUState is not supported"); }
fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState, size_t *size) {
    (void)FMUState; (void)size;
    return fail(instance, "fmi3SerializedFMUStateSize is not supported");
}
fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState, fmi3Byte serializedState[], size_t size) {
    (void)FMUState; (void)serializedState; (void)size;
    return fail(instance, "fmi3SerializeFMUState is not supported");
}
fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[], size_t size, fmi3FMUState *FMUState) {
    (void)serializedState; (void)size; (void)FMUState;
    return fail(instance, "fmi3DeserializeFMUState is not supported");
}
fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                        const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[], size_t nSeed,
                                        fmi3Float64 sensitivity[], size_t nSensitivity) {
    (void)unknowns; (void)nUnknowns; (void)knowns; (void)nKnowns; (void)seed; (void)nSeed; (void)sensitivity; (void)nSensitivity;
    return fail(instance, "fmi3GetDirectionalDerivative is not supported");
}
fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[], size_t nSeed,
                                    fmi3Float64 sensitivity[], size_t nSensitivity) {
    (void)unknowns; (void)nUnknowns; (void)knowns; (void)nKnowns; (void)seed; (void)nSeed; (void)sensitivity; (void)nSensitivity;
    return fail(instance, "fmi3GetAdjointDerivative is not supported");
}
fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance) { return fail(instance, "fmi3EnterConfigurationMode: the model has no structural parameters"); }
fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance) { return fail(instance, "fmi3ExitConfigurationMode: the model has no structural parameters"); }
fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                                  fmi3Float64 intervals[], fmi3IntervalQualifier qualifiers[]) {
    (void)valueReferences; (void)nValueReferences; (void)intervals; (void)qualifiers;
    return fail(instance, "fmi3GetIntervalDecimal: the model has no clocks");
}
fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                                   fmi3UInt64 counters[], fmi3UInt64 resolutions[], fmi3IntervalQualifier qualifiers[]) {
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions; (void)qualifiers;
    return fail(instance, "fmi3GetIntervalFraction: the model has no clocks");
}
fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences, fmi3Float64 shifts[]) {
    (void)valueReferences; (void)nValueReferences; (void)shifts;
    return fail(instance, "fmi3GetShiftDecimal: the model has no clocks");
}
fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                                fmi3UInt64 counters[], fmi3UInt64 resolutions[]) {
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    return fail(instance, "fmi3GetShiftFraction: the model has no clocks");
}
fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                                  const fmi3Float64 intervals[]) {
    (void)valueReferences; (void)nValueReferences; (void)intervals;
    return fail(instance, "fmi3SetIntervalDecimal: the model has no clocks");
}
fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                                   const fmi3UInt64 counters[], const fmi3UInt64 resolutions[]) {
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    return fail(instance, "fmi3SetIntervalFraction: the model has no clocks");
}
fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                               const fmi3Float64 shifts[]) {
    (void)valueReferences; (void)nValueReferences; (void)shifts;
    return fail(instance, "fmi3SetShiftDecimal: the model has no clocks");
}
fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                                const fmi3UInt64 counters[], const fmi3UInt64 resolutions[]) {
    (void)valueReferences; (void)nValueReferences; (void)counters; (void)resolutions;
    return fail(instance, "fmi3SetShiftFraction: the model has no clocks");
}
fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance) { (void)instance; return fmi3OK; }

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate, fmi3Boolean *terminateSimulation,
                                    fmi3Boolean *nominalsOfContinuousStatesChanged, fmi3Boolean *valuesOfContinuousStatesChanged,
                                    fmi3Boolean *nextEventTimeDefined, fmi3Float64 *nextEventTime) {
    (void)instance;
    *discreteStatesNeedUpdate = fmi3False;
    *terminateSimulation = fmi3False;
    *nominalsOfContinuousStatesChanged = fmi3False;
    *valuesOfContinuousStatesChanged = fmi3False;
    *nextEventTimeDefined = fmi3False;
    *nextEventTime = 0.0;
    return fmi3OK;
}

/* ---- model exchange ---------------------------------------------------------------------- */

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
    ((Instance *)instance)->mode = MODE_CONTINUOUS_TIME;
    return fmi3OK;
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation) {
    (void)noSetFMUStatePriorToCurrentPoint;
    *enterEventMode = fmi3False;
    *terminateSimulation = fmi3False;
    return check_states(instance);
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
    ((Instance *)instance)->time = time;
    return fmi3OK;
}

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 continuousStates[], size_t nContinuousStates) {
    Instance *m = instance;
    if (nContinuousStates != N_STATES) return fail(m, "fmi3SetContinuousStates: the model has 2 states, got %zu", nContinuousStates);
    m->r[VR_T_ZONE] = continuousStates[0];
    m->r[VR_T_WATER] = continuousStates[1];
    return fmi3OK;
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[], size_t nContinuousStates) {
    Instance *m = instance;
    if (nContinuousStates != N_STATES) return fail(m, "fmi3GetContinuousStateDerivatives: the model has 2 states, got %zu", nContinuousStates);
    compute(m);
    derivatives[0] = m->r[VR_DER_T_ZONE];
    derivatives[1] = m->r[VR_DER_T_WATER];
    return fmi3OK;
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 eventIndicators[], size_t nEventIndicators) {
    (void)eventIndicators;
    return nEventIndicators ? fail(instance, "fmi3GetEventIndicators: the model has no event indicators, %zu asked", nEventIndicators) : fmi3OK;
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 continuousStates[], size_t nContinuousStates) {
    Instance *m = instance;
    if (nContinuousStates != N_STATES) return fail(m, "fmi3GetContinuousStates: the model has 2 states, got %zu", nContinuousStates);
    compute(m);
    continuousStates[0] = m->r[VR_T_ZONE];
    continuousStates[1] = m->r[VR_T_WATER];
    return fmi3OK;
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[], size_t nContinuousStates) {
    (void)instance;
    for (size_t i = 0; i < nContinuousStates; i++) nominals[i] = 300.0;
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *nEventIndicators) {
    (void)instance;
    *nEventIndicators = 0;
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *nContinuousStates) {
    (void)instance;
    *nContinuousStates = N_STATES;
    return fmi3OK;
}

/* ---- co-simulation ---------------------------------------------------------------------- */

fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
    Instance *m = instance;
    if (m->mode != MODE_STEP) return fail(m, "fmi3EnterStepMode: co-simulation without event mode is in step mode already");
    return fmi3OK;
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                                    const fmi3Int32 orders[], fmi3Float64 values[], size_t nValues) {
    (void)valueReferences; (void)orders; (void)values; (void)nValues;
    return nValueReferences ? fail(instance, "fmi3GetOutputDerivatives is not supported (maxOutputDerivativeOrder is 0)") : fmi3OK;
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean noSetFMUStatePriorToCurrentPoint, fmi3Boolean *eventHandlingNeeded,
                      fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn, fmi3Float64 *lastSuccessfulTime) {
    (void)noSetFMUStatePriorToCurrentPoint;
    Instance *m = instance;
    *eventHandlingNeeded = fmi3False;
    *terminateSimulation = fmi3False;
    *earlyReturn = fmi3False;
    *lastSuccessfulTime = currentCommunicationPoint;
    if (m->mode != MODE_STEP) return fail(m, "fmi3DoStep called outside step mode (mode %d)", (int)m->mode);
    if (!(communicationStepSize > 0.0)) return fail(m, "fmi3DoStep: step size must be positive, got %g", communicationStepSize);
    const long n_sub = (long)ceil(communicationStepSize / m->r[VR_DT_INTERNAL] - 1e-9);
    const double h = communicationStepSize / (double)n_sub;
    m->time = currentCommunicationPoint;
    for (long i = 0; i < n_sub; i++) {
        compute(m);
        m->r[VR_T_ZONE] += h * m->r[VR_DER_T_ZONE];
        m->r[VR_T_WATER] += h * m->r[VR_DER_T_WATER];
        m->time = currentCommunicationPoint + (double)(i + 1) * h;
        if (check_states(m) != fmi3OK) return fmi3Error;
        *lastSuccessfulTime = m->time;
    }
    m->time = currentCommunicationPoint + communicationStepSize;
    *lastSuccessfulTime = m->time;
    return fmi3OK;
}

/* ---- scheduled execution ---------------------------------------------------------------- */

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference, fmi3Float64 activationTime) {
    (void)clockReference; (void)activationTime;
    return fail(instance, "fmi3ActivateModelPartition: scheduled execution is not supported");
}
