/* Inverter air-source heat pump with a 46 l buffer tank, after paper A (see ../README.md).
 *
 * Hydraulics: tank bottom -> condenser (loading pump) -> tank top; the heating circuit draws
 * from the tank top through a flow pipe past the flow-temperature sensor and returns into the
 * tank bottom. Every water volume is updated with an implicit upwind step, so any internal
 * step is stable; the internal step is at most 1 s.
 */
#include <math.h>
#include <stddef.h>

#include "variables.h"

#define R(name) r[V_##name]
#define CP_WATER 4184.0
#define CP_AIR 1006.0
#define RHO_WATER 995.0
#define PI 3.14159265358979
#define MAX_INTERNAL_STEP 1.0
#define N_TANK 3

typedef struct {
    double TCon, TTank[N_TANK], TPipe, TSensor;
    double startUpFraction;   /* 0 right after a start, rising to 1 (start-up lag) */
    double QEvaLast;          /* evaporator heat flow of the last step, for the air-side drop */
    int compressorOn;
    double timeInState;       /* since the last compressor switch */
    double timeSinceStop;     /* for pump post-run */
    int thermostatAllows;     /* cycling effect thermostat */
    double frost;             /* 0..1, a defrost starts at 1 */
    double defrostLeft;
} State;

const size_t MODEL_STATE_BYTES = sizeof(State);

/* Performance map at full speed in the spirit of EN 14511 tables: rows outdoor air temperature,
 * columns condenser outlet temperature. Thermal and electric power in W. */
#define N_ODA 6
#define N_FLOW 3
static const double T_ODA_DEGC[N_ODA] = {-15.0, -7.0, 2.0, 7.0, 12.0, 20.0};
static const double T_FLOW_DEGC[N_FLOW] = {35.0, 45.0, 55.0};
static const double Q_TABLE[N_ODA][N_FLOW] = {
    {5600, 5200, 4800}, {6600, 6200, 5800}, {8000, 7600, 7200},
    {9000, 8600, 8200}, {10000, 9500, 9000}, {11200, 10600, 10000}};
static const double P_TABLE[N_ODA][N_FLOW] = {
    {2550, 2900, 3300}, {2450, 2800, 3200}, {2220, 2600, 3050},
    {2050, 2450, 2900}, {1920, 2300, 2750}, {1800, 2150, 2600}};

static void bracket(const double *grid, int n, double x, int *i, double *w) {
    if (x <= grid[0]) { *i = 0; *w = 0.0; return; }
    if (x >= grid[n - 1]) { *i = n - 2; *w = 1.0; return; }
    int k = 0;
    while (x > grid[k + 1]) k++;
    *i = k;
    *w = (x - grid[k]) / (grid[k + 1] - grid[k]);
}

static double bilinear(const double table[N_ODA][N_FLOW], int i, double wi, int j, double wj) {
    return (1 - wi) * ((1 - wj) * table[i][j] + wj * table[i][j + 1]) +
           wi * ((1 - wj) * table[i + 1][j] + wj * table[i + 1][j + 1]);
}

/* Factor of the outdoor-temperature band (cold <= 2 degC < med < 12 degC <= warm), blended
 * linearly over dTBandBlend around each border so an optimiser sees a continuous model. */
static double band_factor(double TOdaDegC, double cold, double med, double warm, double blend) {
    double half = 0.5 * (blend > 1e-6 ? blend : 1e-6);
    double wCold = fmin(fmax((2.0 + half - TOdaDegC) / (2 * half), 0.0), 1.0);
    double wWarm = fmin(fmax((TOdaDegC - (12.0 - half)) / (2 * half), 0.0), 1.0);
    return wCold * cold + wWarm * warm + (1.0 - wCold - wWarm) * med;
}

/* Frost growth, 0..1: strongest near +1 degC outdoor air, none below -12 or above +7 degC,
 * and only in humid air (relative humidity above 0.6). */
static double frost_rate(double TOdaDegC, double relHum) {
    double byTemperature = TOdaDegC > 1.0 ? (7.0 - TOdaDegC) / 6.0 : (TOdaDegC + 12.0) / 13.0;
    double byHumidity = (relHum - 0.6) / 0.3;
    return fmin(fmax(byTemperature, 0.0), 1.0) * fmin(fmax(byHumidity, 0.0), 1.0);
}

static double relax(double value, double target, double h, double tau) {
    return tau > 1e-9 ? target + (value - target) * exp(-h / tau) : target;
}

const char *model_initialize(double *r, void *state) {
    State *s = state;
    if (!(R(mCon_flow_nominal) > 0)) return "parameter mCon_flow_nominal must be > 0";
    if (!(R(mHC_flow_nominal) > 0)) return "parameter mHC_flow_nominal must be > 0";
    if (!(R(tauVolCon) > 0)) return "parameter tauVolCon must be > 0";
    if (!(R(VTank) > 0) || !(R(dTank) > 0)) return "parameters VTank and dTank must be > 0";
    if (!(R(sIns) > 0) || R(lambdaIns) < 0) return "parameter sIns must be > 0 and lambdaIns >= 0";
    if (!(R(mPipe) > 0)) return "parameter mPipe must be > 0";
    if (R(useDefrost) > 0.5 && !(R(tDefrostInterval) > 0)) return "parameter tDefrostInterval must be > 0";
    double T0 = R(TStart_K) > 0 ? R(TStart_K) : R(THCRet_K);
    s->TCon = s->TPipe = s->TSensor = T0;
    for (int k = 0; k < N_TANK; k++) s->TTank[k] = T0;
    s->startUpFraction = 1.0;
    s->compressorOn = 0;
    s->timeInState = 1e9;
    s->timeSinceStop = 1e9;
    s->thermostatAllows = 1;
    s->frost = 0.0;
    s->defrostLeft = 0.0;
    s->QEvaLast = 0.0;
    R(THCFlow_K) = R(THCFlowTrue_K) = R(TCon_K) = T0;
    R(TTankTop_K) = R(TTankMid_K) = R(TTankBot_K) = T0;
    R(PEl_W) = R(PCtrl);
    return NULL;
}

/* Implicit upwind update of one mixed water volume: inflows (flow, temperature) and a
 * conductance to an ambient plus a heat source. */
static double mix_volume(double T, double mass, double h, const double *flow, const double *temp, int n,
                         double UA, double TAmb, double Q) {
    double num = mass * CP_WATER * T + h * (UA * TAmb + Q);
    double den = mass * CP_WATER + h * UA;
    for (int k = 0; k < n; k++) {
        num += h * flow[k] * CP_WATER * temp[k];
        den += h * flow[k] * CP_WATER;
    }
    return num / den;
}

static void substep(double *r, State *s, double h) {
    double TOdaDegC = R(TEva_K) - 273.15;
    double TAmb = R(T_fixAmbTestHall);
    int useCycling = R(useCycling) > 0.5;

    /* compressor on/off: command, then the cycling thermostat and its minimum times */
    double command = fmin(fmax(R(nSpeedHP_invCtrl0_1), 0.0), 1.0);
    int want = command > 1e-3;
    if (useCycling) {
        if (s->TCon >= R(TCycOff)) s->thermostatAllows = 0;
        else if (s->TCon <= R(TCycOff) - R(dTCycHys)) s->thermostatAllows = 1;
        want = want && s->thermostatAllows;
        if (s->compressorOn && !want && s->timeInState < R(tCycMinRun)) want = 1;
        if (!s->compressorOn && want && s->timeInState < R(tCycMinOff)) want = 0;
    }
    if (want != s->compressorOn) {
        s->compressorOn = want;
        s->timeInState = 0.0;
        if (want) s->startUpFraction = R(useStartUpLag) > 0.5 ? 0.0 : 1.0;
        else s->timeSinceStop = 0.0;
    }
    s->timeInState += h;
    if (!s->compressorOn) s->timeSinceStop += h;
    double speed = s->compressorOn ? fmax(command, R(nSpeedMin)) : 0.0;
    if (s->compressorOn && R(useStartUpLag) > 0.5)
        s->startUpFraction = relax(s->startUpFraction, 1.0, h, R(tauStartUp));
    else
        s->startUpFraction = 1.0;

    /* defrost: frost grows while running in cold humid air; a defrost reverses the cycle */
    double relHum = R(relHumOda_1) >= 0 ? R(relHumOda_1) : R(relHumOdaFix);
    int fanDriven = R(useDefrost) > 0.5 && R(defrostFromFan) > 0.5;
    if (fanDriven) {
        /* the logged fan stop marks each defrost: no hidden frost state to guess */
        s->defrostLeft = s->compressorOn && R(nSpeedFanEva_1_0) < 0.02 ? h : 0.0;
    } else if (R(useDefrost) > 0.5 && s->compressorOn) {
        if (s->defrostLeft <= 0) {
            s->frost += h * frost_rate(TOdaDegC, relHum) / R(tDefrostInterval);
            if (s->frost >= 1.0) { s->frost = 0.0; s->defrostLeft = R(tDefrost); }
        }
    }
    int defrosting = s->compressorOn && s->defrostLeft > 0;
    if (s->defrostLeft > 0) s->defrostLeft -= h;

    /* performance map at the evaporator's mean air temperature and the condenser outlet */
    double fan = defrosting ? 0.0 : fmin(fmax(R(nSpeedFanEva_1_0), 0.0), 1.0);
    double mAir = fmax(fan, 0.1) * R(mHC_flow_nominal);
    /* while defrosting the evaporator is the condenser: no air-side cooling */
    double airDrop = defrosting ? 0.0 : 0.5 * s->QEvaLast / CP_AIR * (1.0 / mAir - 1.0 / R(mEvaTable_flow));
    int i, j;
    double wi, wj;
    bracket(T_ODA_DEGC, N_ODA, TOdaDegC - airDrop, &i, &wi);
    bracket(T_FLOW_DEGC, N_FLOW, s->TCon - 273.15, &j, &wj);
    double blend = R(dTBandBlend);
    double QFull = R(scaleHPQCon_nominal) * band_factor(TOdaDegC, R(fQCold), R(fQMed), R(fQWarm), blend) *
                   bilinear(Q_TABLE, i, wi, j, wj);
    double PFull = R(scaleHPPEl_nominal) * band_factor(TOdaDegC, R(fPCold), R(fPMed), R(fPWarm), blend) *
                   bilinear(P_TABLE, i, wi, j, wj);
    /* thermal power scales with speed; electric power a little less at low speed (better part-load COP) */
    double PComp = PFull * speed * (0.7 + 0.3 * speed);
    double QCon = defrosting ? -R(fDefrostQ) * QFull * speed : QFull * speed * s->startUpFraction;
    s->QEvaLast = s->compressorOn && !defrosting ? fmax(QCon - PComp, 0.0) : 0.0;

    double QBackup = (R(useBackupHeater) > 0.5 && s->compressorOn && R(TEva_K) < R(TOdaBackup)) ? R(PBackup) : 0.0;

    double pump = fmin(fmax(R(nSpeedPumpCon_1_0), 0.0), 1.0);
    if (R(usePostRun) > 0.5 && !s->compressorOn && s->timeSinceStop < R(tPostRun)) pump = 1.0;
    double mCon = pump * R(mCon_flow_nominal);
    double mHC = fmax(R(m_flowHC_kg_s), 0.0);
    int heatLoss = R(useHeatLoss) > 0.5;

    /* condenser volume, fed from the tank bottom */
    double massCon = R(tauVolCon) * R(mCon_flow_nominal);
    s->TCon = mix_volume(s->TCon, massCon, h, &mCon, &s->TTank[N_TANK - 1], 1,
                         heatLoss ? R(UALossCon) : 0.0, TAmb, QCon + QBackup);

    /* tank: loading loop enters at the top, heating circuit returns at the bottom; the net flow
     * between neighbouring volumes is mCon - mHC (downwards if positive) */
    double massNode = R(VTank) * RHO_WATER / N_TANK;
    double height = R(VTank) / (PI * R(dTank) * R(dTank) / 4.0);
    double U = R(lambdaIns) / R(sIns);
    double endArea = PI * R(dTank) * R(dTank) / 4.0, sideArea = PI * R(dTank) * height / N_TANK;
    double down = mCon - mHC;
    double flow[2], temp[2];
    /* visit the volumes in the direction of the net flow so each sees its fresh upstream value */
    for (int visit = 0; visit < N_TANK; visit++) {
        int k = down >= 0 ? visit : N_TANK - 1 - visit;
        int n = 0;
        if (k == 0) { flow[n] = mCon; temp[n++] = s->TCon; }
        if (k == N_TANK - 1) { flow[n] = mHC; temp[n++] = R(THCRet_K); }
        if (k > 0 && down > 0) { flow[n] = down; temp[n++] = s->TTank[k - 1]; }
        if (k < N_TANK - 1 && down < 0) { flow[n] = -down; temp[n++] = s->TTank[k + 1]; }
        double area = sideArea + ((k == 0 || k == N_TANK - 1) ? endArea : 0.0);
        s->TTank[k] = mix_volume(s->TTank[k], massNode, h, flow, temp, n, U * area, TAmb, 0.0);
    }

    s->TPipe = mix_volume(s->TPipe, R(mPipe), h, &mHC, &s->TTank[0], 1,
                          heatLoss ? R(UALossPipe) : 0.0, TAmb, 0.0);
    s->TSensor = R(useSensorLag) > 0.5 ? relax(s->TSensor, s->TPipe, h, R(tauSensor)) : s->TPipe;

    R(QCon_W) = QCon;
    R(PComp_W) = PComp;
    R(QBackup_W) = QBackup;
    R(COP) = s->compressorOn && PComp > 0 ? QCon / PComp : 0.0;
    R(nSpeedHPAct_1) = speed;
    R(pumpConAct_1) = pump;
    R(defrosting_1) = defrosting;
    R(PEl_W) = R(PCtrl) + fan * R(PFan_nominal) + pump * R(PPump_nominal) + PComp + QBackup;
}

const char *model_do_step(double *r, void *state, double time, double h) {
    (void)time;
    State *s = state;
    int n = (int)ceil(h / MAX_INTERNAL_STEP - 1e-9);
    double hs = h / n;
    for (int k = 0; k < n; k++) substep(r, s, hs);
    R(THCFlow_K) = s->TSensor;
    R(THCFlowTrue_K) = s->TPipe;
    R(TCon_K) = s->TCon;
    R(TTankTop_K) = s->TTank[0];
    R(TTankMid_K) = s->TTank[1];
    R(TTankBot_K) = s->TTank[2];
    if (!isfinite(s->TCon) || !isfinite(s->TTank[0]) || !isfinite(s->TPipe)) return "temperatures diverged";
    return NULL;
}
