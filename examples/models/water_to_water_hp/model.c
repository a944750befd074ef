/* Water-to-water heat pump, 10-node buffer tank and one floor-heated zone, after paper B
 * (see ../README.md). Control structure "def" modulates the heat pump to the generation set
 * point; "ems" runs it on/off at full capacity with a two-node tank hysteresis.
 *
 * Hydraulics: tank bottom -> heat pump (charging pump) -> tank top; a mixing valve blends
 * tank-top water with floor-heating return water down to the heating-curve supply set point.
 * Water volumes are updated with implicit upwind steps; the internal step is at most 10 s.
 * Power outputs are means over the last communication step (what an energy meter logs).
 */
#include <math.h>
#include <stddef.h>

#include "variables.h"

#define R(name) r[V_##name]
#define CP_WATER 4184.0
#define RHO_WATER 995.0
#define PI 3.14159265358979
#define MAX_INTERNAL_STEP 10.0
#define N_TANK 10
#define K_EFF_TANK 1.5   /* W/(m.K): conduction plus mixing between tank nodes */
#define STOREY_HEIGHT 2.6

typedef struct {
    double TTank[N_TANK];  /* 0 = top */
    double TSlab, TZone, TRet, TSensor;
    int hpOn, emsCharging;
    double timeInState, timeSinceStop, startUpFraction;
    /* sums over the current communication step */
    double sumPEl, sumQHP, sumQFloor, sumQBackup, sumPComp, sumOn;
    double THPOut, TSupTrue, TSupSet;
} State;

const size_t MODEL_STATE_BYTES = sizeof(State);

static double clamp(double x, double lo, double hi) { return fmin(fmax(x, lo), hi); }

static double relax(double value, double target, double h, double tau) {
    return tau > 1e-9 ? target + (value - target) * exp(-h / tau) : target;
}

/* tank temperature at a relative height (0 bottom, 1 top), linear between node centres */
static double tank_at(const State *s, double height) {
    double x = clamp((1.0 - height) * N_TANK - 0.5, 0.0, N_TANK - 1.0);
    int k = (int)floor(x);
    if (k >= N_TANK - 1) return s->TTank[N_TANK - 1];
    double w = x - k;
    return (1 - w) * s->TTank[k] + w * s->TTank[k + 1];
}

static double supply_set_point(const double *r) {
    double x1 = R(THeaCurX1_K), x2 = R(THeaCurX2_K), y1 = R(THeaCurY1_K), y2 = R(THeaCurY2_K);
    double w = clamp((R(TOda_K) - x1) / (x2 - x1), 0.0, 1.0);
    /* the curve is drawn for a 20 degC room; a higher set point shifts it in parallel */
    return y1 + w * (y2 - y1) + (R(TZoneSet_K) + R(dTZoneSetShift_K) - 293.15);
}

const char *model_initialize(double *r, void *state) {
    State *s = state;
    if (!(R(THeaCurX2_K) > R(THeaCurX1_K))) return "parameter THeaCurX2_K must be above THeaCurX1_K";
    if (!(R(QHP_nominal) > 0)) return "parameter QHP_nominal must be > 0";
    if (!(R(flowRatioSrcDem) > 0)) return "parameter flowRatioSrcDem must be > 0";
    if (!(R(tankHD) > 0) || !(R(VTank) > 0)) return "parameters tankHD and VTank must be > 0";
    if (!(R(dTCtrlBand) > 0)) return "parameter dTCtrlBand must be > 0";
    if (!(R(CSlab) > 0) || !(R(CZone) > 0)) return "parameters CSlab and CZone must be > 0";
    if (!(R(etaCarnot) > 0)) return "parameter etaCarnot must be > 0";
    double TSupSet = supply_set_point(r);
    for (int k = 0; k < N_TANK; k++) s->TTank[k] = TSupSet;
    s->TZone = R(TStart_K);
    s->TSlab = R(TStart_K) + 2.0;
    s->TRet = s->TSlab;
    s->TSensor = s->TSupTrue = TSupSet;
    s->THPOut = TSupSet;
    s->TSupSet = TSupSet;
    s->hpOn = s->emsCharging = 0;
    s->timeInState = s->timeSinceStop = 1e9;
    s->startUpFraction = 1.0;
    R(TSup_K) = R(TSupTrue_K) = R(TTankTop_K) = R(TTankCutIn_K) = R(TTankBot_K) = R(THPOut_K) = TSupSet;
    R(TSupSet_K) = TSupSet;
    R(TZone_K) = s->TZone;
    R(TRet_K) = s->TRet;
    return NULL;
}

static void substep(double *r, State *s, double h) {
    double TSupSet = supply_set_point(r);
    double TGenSet = TSupSet + R(dTGenSto);
    double mDemDesign = R(QFloor_design) / (CP_WATER * 5.0);
    double mSrc = R(flowRatioSrcDem) * mDemDesign;
    double QCap = R(QHP_nominal) * (1.0 + 0.02 * (R(TSource_K) - 283.15));
    double TCutIn = tank_at(s, R(hCutIn)), TBot = s->TTank[N_TANK - 1];
    int useCycling = R(useCycling) > 0.5;
    int ems = R(controlStructure) > 0.5;

    /* heat pump demand from the control structure */
    int want;
    double QWanted;
    if (ems) {
        /* two-node hysteresis: cut in on the upper node, cut out on the lower node once the
         * upper one is satisfied too (so a negative difference cannot make it chatter) */
        if (!s->emsCharging && TCutIn < TSupSet) s->emsCharging = 1;
        else if (s->emsCharging && tank_at(s, R(hCutOut)) > TSupSet + R(dTCutInOut) && TCutIn >= TSupSet)
            s->emsCharging = 0;
        want = s->emsCharging;
        QWanted = QCap;
    } else {
        QWanted = clamp(mSrc * CP_WATER * (TGenSet - TBot), 0.0, QCap);
        want = QWanted > 1e-3 * QCap;
        if (useCycling) QWanted = fmax(QWanted, R(plrCycMin) * QCap);
    }
    if (useCycling) {
        if (s->hpOn && !want && s->timeInState < R(tCycMinRun)) want = 1;
        if (!s->hpOn && want && s->timeInState < R(tCycMinOff)) want = 0;
        if (want && !ems) QWanted = fmax(QWanted, R(plrCycMin) * QCap);
    }
    if (want != s->hpOn) {
        s->hpOn = want;
        s->timeInState = 0.0;
        if (want) s->startUpFraction = R(useStartUpLag) > 0.5 ? 0.0 : 1.0;
        else s->timeSinceStop = 0.0;
    }
    s->timeInState += h;
    if (!s->hpOn) s->timeSinceStop += h;
    if (s->hpOn && R(useStartUpLag) > 0.5) s->startUpFraction = relax(s->startUpFraction, 1.0, h, R(tauStartUp));
    else s->startUpFraction = 1.0;

    int pump = s->hpOn || (R(usePostRun) > 0.5 && s->timeSinceStop < R(tPostRun));
    double mHP = pump ? mSrc : 0.0;
    double QFull = s->hpOn ? QWanted : 0.0;
    double QHP = QFull * s->startUpFraction;
    double THPOut = mHP > 0 ? TBot + QHP / (mHP * CP_WATER) : TBot;
    /* the compressor draws its full power at once; the refrigerant circuit lags (start-up lag) */
    double TCondensing = TBot + QFull / (mSrc * CP_WATER) + 2.0, TEvaporating = R(TSource_K) - 4.0;
    double COP = R(etaCarnot) * TCondensing / fmax(TCondensing - TEvaporating, 5.0);
    double PComp = s->hpOn ? QFull / COP : 0.0;
    if (mHP > 0 && R(useHeatLoss) > 0.5)
        THPOut -= R(UALossGen) * (THPOut - R(TRoomPlant_K)) / (mHP * CP_WATER + R(UALossGen));

    double QBackup = (R(useBackupHeater) > 0.5 && R(TOda_K) < R(TOdaBackup) && s->TTank[0] < TSupSet) ? R(PBackup) : 0.0;

    /* floor heating: valve from the zone controller, mixing valve down to the set point */
    double TZoneSet = R(TZoneSet_K) + R(dTZoneSetShift_K);
    double valve = clamp((TZoneSet + 0.5 * R(dTCtrlBand) - s->TZone) / R(dTCtrlBand), 0.0, 1.0);
    double mDem = valve * mDemDesign;
    double TTop = s->TTank[0];
    double share = TTop > TSupSet && TTop - s->TRet > 1e-6 ? clamp((TSupSet - s->TRet) / (TTop - s->TRet), 0.0, 1.0) : 1.0;
    double TSup = s->TRet + share * (TTop - s->TRet);
    double QFloor = 0.0;
    if (mDem > 1e-9) {
        double effectiveness = 1.0 - exp(-R(UAPipeSlab) / (mDem * CP_WATER));
        QFloor = mDem * CP_WATER * effectiveness * (TSup - s->TSlab);
        s->TRet = TSup - QFloor / (mDem * CP_WATER);
    } else {
        s->TRet = relax(s->TRet, s->TSlab, h, 1800.0);
    }
    double mTank = share * mDem;

    /* tank */
    double D = cbrt(4.0 * R(VTank) / (PI * R(tankHD))), dz = R(tankHD) * D / N_TANK;
    double G = K_EFF_TANK * PI * D * D / 4.0 / dz;
    double massNode = R(VTank) * RHO_WATER / N_TANK;
    double sideArea = PI * D * dz, endArea = PI * D * D / 4.0;
    double old[N_TANK];
    for (int k = 0; k < N_TANK; k++) old[k] = s->TTank[k];
    double down = mHP - mTank;
    for (int visit = 0; visit < N_TANK; visit++) {
        int k = down >= 0 ? visit : N_TANK - 1 - visit;
        double UA = R(UTank) * (sideArea + ((k == 0 || k == N_TANK - 1) ? endArea : 0.0));
        double Q = UA * R(TRoomPlant_K) + (k == 0 ? QBackup : 0.0);
        double num = massNode * CP_WATER * old[k] + h * Q, den = massNode * CP_WATER + h * UA;
        if (k > 0) Q = G * (old[k - 1] - old[k]), num += h * Q;
        if (k < N_TANK - 1) Q = G * (old[k + 1] - old[k]), num += h * Q;
        if (k == 0) { num += h * mHP * CP_WATER * THPOut; den += h * mHP * CP_WATER; }
        if (k == N_TANK - 1) { num += h * mTank * CP_WATER * s->TRet; den += h * mTank * CP_WATER; }
        if (k > 0 && down > 0) { num += h * down * CP_WATER * s->TTank[k - 1]; den += h * down * CP_WATER; }
        if (k < N_TANK - 1 && down < 0) { num -= h * down * CP_WATER * s->TTank[k + 1]; den -= h * down * CP_WATER; }
        s->TTank[k] = num / den;
    }

    /* slab and zone */
    double UAInf = R(nInf_1_h) / 3600.0 * R(AFloor) * STOREY_HEIGHT * 1.2 * 1006.0;
    s->TSlab = (R(CSlab) * s->TSlab + h * (QFloor + R(UASlabZone) * s->TZone)) / (R(CSlab) + h * R(UASlabZone));
    double gains = R(AWinEff) * fmax(R(HGloHor_W_m2), 0.0) + R(QInt);
    s->TZone = (R(CZone) * s->TZone + h * (R(UASlabZone) * s->TSlab + (R(UATrans) + UAInf) * R(TOda_K) + gains)) /
               (R(CZone) + h * (R(UASlabZone) + R(UATrans) + UAInf));

    s->TSupTrue = TSup;
    s->TSensor = R(useSensorLag) > 0.5 ? relax(s->TSensor, TSup, h, R(tauSensor)) : TSup;
    s->THPOut = THPOut;
    s->TSupSet = TSupSet;
    double PEl = PComp + (pump ? R(PPumpHP) : 0.0) + QBackup;
    s->sumPEl += h * PEl;
    s->sumPComp += h * PComp;
    s->sumQHP += h * QHP;
    s->sumQFloor += h * QFloor;
    s->sumQBackup += h * QBackup;
    s->sumOn += h * s->hpOn;
}

const char *model_do_step(double *r, void *state, double time, double h) {
    (void)time;
    State *s = state;
    int n = (int)ceil(h / MAX_INTERNAL_STEP - 1e-9);
    double hs = h / n;
    s->sumPEl = s->sumPComp = s->sumQHP = s->sumQFloor = s->sumQBackup = s->sumOn = 0.0;
    for (int k = 0; k < n; k++) substep(r, s, hs);
    R(PEl_W) = s->sumPEl / h;
    R(QHP_W) = s->sumQHP / h;
    R(QFloor_W) = s->sumQFloor / h;
    R(QBackup_W) = s->sumQBackup / h;
    R(COP) = s->sumPComp > 0 ? s->sumQHP / s->sumPComp : 0.0;
    R(hpOn_1) = s->sumOn / h;
    R(TSup_K) = s->TSensor;
    R(TSupTrue_K) = s->TSupTrue;
    R(TRet_K) = s->TRet;
    R(TZone_K) = s->TZone;
    R(TTankTop_K) = s->TTank[0];
    R(TTankCutIn_K) = tank_at(s, R(hCutIn));
    R(TTankBot_K) = s->TTank[N_TANK - 1];
    R(THPOut_K) = s->THPOut;
    R(TSupSet_K) = s->TSupSet;
    if (!isfinite(s->TZone) || !isfinite(s->TTank[0]) || !isfinite(s->TSlab)) return "temperatures diverged";
    return NULL;
}
