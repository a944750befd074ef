/* two_resistance_zone: a test model that is NOT identifiable by construction.
 *
 * A massless air node (the measured zone temperature) sits between the outdoor air (through
 * R1) and one capacity C (through R2):
 *
 *   T_zone = (R2 * T_out + R1 * T_core) / (R1 + R2)
 *   C dT_core/dt = (T_out - T_core) / (R1 + R2)
 *
 * Without an absolute heat flow, scaling R1 and R2 by k and C by 1/k leaves T_zone unchanged:
 * only the ratio R1/R2 and the time constant tau = C (R1 + R2) are determined by data; R1,
 * R2 and C each are not. simgap's identifiability report must say so.
 *
 * h_folded is read at initialisation (it must be positive) but changes nothing, like a
 * parameter a Modelica compiler folded at compile time: the inert-tuner probe must name it.
 *
 * The core temperature is updated exactly over each internal step with T_out held.
 */
#include <math.h>
#include <stddef.h>

#include "variables.h"

#define R(name) r[V_##name]
#define MAX_INTERNAL_STEP 60.0

typedef struct {
    double TCore;
    double folded;
} State;

const size_t MODEL_STATE_BYTES = sizeof(State);

static void outputs(double *r, const State *s) {
    R(T_core) = s->TCore;
    R(T_zone) = (R(R2) * R(T_out) + R(R1) * s->TCore) / (R(R1) + R(R2));
    R(tau) = R(C) * (R(R1) + R(R2));
}

const char *model_initialize(double *r, void *state) {
    State *s = state;
    if (!(R(R1) > 0) || !isfinite(R(R1))) return "parameter R1 must be > 0";
    if (!(R(R2) > 0) || !isfinite(R(R2))) return "parameter R2 must be > 0";
    if (!(R(C) > 0) || !isfinite(R(C))) return "parameter C must be > 0";
    if (!(R(h_folded) > 0)) return "parameter h_folded must be > 0";
    s->folded = R(h_folded); /* read, kept, never used: the output does not depend on it */
    s->TCore = R(T_core_start) > 0 ? R(T_core_start) : R(T_out);
    outputs(r, s);
    return NULL;
}

const char *model_do_step(double *r, void *state, double time, double h) {
    (void)time;
    State *s = state;
    int n = (int)ceil(h / MAX_INTERNAL_STEP - 1e-9);
    double hs = h / n, decay = exp(-hs / (R(C) * (R(R1) + R(R2))));
    for (int k = 0; k < n; k++) s->TCore = R(T_out) + (s->TCore - R(T_out)) * decay;
    outputs(r, s);
    if (!isfinite(s->TCore)) return "core temperature diverged";
    return NULL;
}
