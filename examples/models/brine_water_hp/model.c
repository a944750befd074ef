/* Brine-to-water heat pump with a constant Carnot effectiveness, for the IBPSA test-bench
 * measurement (see ../README.md). The compressor draws PEle_nominal times its status at once;
 * the heat flows follow the status through a critically damped filter (refrigerant inertia),
 * as the measurement shows: electric power jumps at a start, the supply temperature lags.
 */
#include <math.h>
#include <stddef.h>

#include "variables.h"

#define R(name) r[V_##name]
#define CP_WATER 4184.0
#define RHO_WATER 995.0
#define RHO_BRINE 1030.0
#define PI 3.14159265358979
#define MAX_INTERNAL_STEP 0.5
#define MAX_ORDER 5

typedef struct {
    double TCon, TEva;
    double inertia[MAX_ORDER];
    double sumPEl, sumQCon, sumQEva;
} State;

const size_t MODEL_STATE_BYTES = sizeof(State);

const char *model_initialize(double *r, void *state) {
    State *s = state;
    if (!(R(etaCarnot_nominal) > 0)) return "parameter etaCarnot_nominal must be > 0";
    if (!(R(VCon) > 0) || !(R(VEva) > 0)) return "parameters VCon and VEva must be > 0";
    if (R(mCon_flow_nominal) < 0 || R(mEva_flow_nominal) < 0) return "nominal mass flows must be >= 0";
    if (R(UALossCon) < 0) return "parameter UALossCon must be >= 0";
    if (R(useInertia) > 0.5 && !(R(refIneFreConst) > 0)) return "parameter refIneFreConst must be > 0";
    if (!(R(nthOrder) >= 1 && R(nthOrder) <= MAX_ORDER)) return "parameter nthOrder must be within 1..5";
    s->TCon = R(TConStart_K) > 0 ? R(TConStart_K) : R(TConIn_K);
    s->TEva = R(TEvaStart_K) > 0 ? R(TEvaStart_K) : R(TEvaIn_K);
    double y0 = fmin(fmax(R(yCompressor_1), 0.0), 1.0);
    for (int k = 0; k < MAX_ORDER; k++) s->inertia[k] = y0;
    R(TConOut_K) = s->TCon;
    R(TEvaOut_K) = s->TEva;
    return NULL;
}

static void substep(double *r, State *s, double h) {
    double y = fmin(fmax(R(yCompressor_1), 0.0), 1.0);
    double yHeat = y;
    if (R(useInertia) > 0.5) {
        int n = (int)lround(R(nthOrder));
        /* critical damping: n equal first-order stages whose cascade has its -3 dB point at f */
        double w = 2 * PI * R(refIneFreConst) / sqrt(pow(2.0, 1.0 / n) - 1.0);
        double decay = exp(-w * h), input = y;
        for (int k = 0; k < n; k++) {
            s->inertia[k] = input + (s->inertia[k] - input) * decay;
            input = s->inertia[k];
        }
        yHeat = input;
    }
    double TCondensing = s->TCon + R(dTAppCon), TEvaporating = s->TEva - R(dTAppEva);
    double COP = fmin(R(etaCarnot_nominal) * TCondensing / fmax(TCondensing - TEvaporating, 1.0), 20.0);
    double PComp = y * R(PEle_nominal);
    double QCon = yHeat * R(PEle_nominal) * COP;
    double QEva = yHeat * R(PEle_nominal) * (COP - 1.0);

    double mCon = fmin(fmax(R(yPumpCon_1), 0.0), 1.0) * R(mCon_flow_nominal);
    double mEva = fmin(fmax(R(yPumpEva_1), 0.0), 1.0) * R(mEva_flow_nominal);
    double CCon = R(VCon) * RHO_WATER * CP_WATER, CEva = R(VEva) * RHO_BRINE * R(cpBrine);
    s->TCon = (CCon * s->TCon + h * (mCon * CP_WATER * R(TConIn_K) + QCon + R(UALossCon) * R(TAmb_K))) /
              (CCon + h * (mCon * CP_WATER + R(UALossCon)));
    s->TEva = (CEva * s->TEva + h * (mEva * R(cpBrine) * R(TEvaIn_K) - QEva)) / (CEva + h * mEva * R(cpBrine));

    double PEl = PComp + fmin(fmax(R(yPumpCon_1), 0.0), 1.0) * R(PPumpCon) + fmin(fmax(R(yPumpEva_1), 0.0), 1.0) * R(PPumpEva);
    s->sumPEl += h * PEl;
    s->sumQCon += h * QCon;
    s->sumQEva += h * QEva;
    R(COP) = COP;
}

const char *model_do_step(double *r, void *state, double time, double h) {
    (void)time;
    State *s = state;
    int n = (int)ceil(h / MAX_INTERNAL_STEP - 1e-9);
    double hs = h / n;
    s->sumPEl = s->sumQCon = s->sumQEva = 0.0;
    for (int k = 0; k < n; k++) substep(r, s, hs);
    R(PEl_W) = s->sumPEl / h;
    R(QCon_W) = s->sumQCon / h;
    R(QEva_W) = s->sumQEva / h;
    R(TConOut_K) = s->TCon;
    R(TEvaOut_K) = s->TEva;
    if (!isfinite(s->TCon) || !isfinite(s->TEva)) return "temperatures diverged";
    return NULL;
}
