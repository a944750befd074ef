/* Value references of air_source_hp: index into the Real array. Keep in step with modelDescription.xml
   (tests/test_models_interface.py checks that they agree). */
#ifndef VARIABLES_H
#define VARIABLES_H
#include <stddef.h>
#define V_nSpeedFanEva_1_0 0
#define V_TEva_K 1
#define V_THCRet_K 2
#define V_nSpeedPumpCon_1_0 3
#define V_m_flowHC_kg_s 4
#define V_nSpeedHP_invCtrl0_1 5
#define V_relHumOda_1 6
#define V_THCFlow_K 7
#define V_PEl_W 8
#define V_QCon_W 9
#define V_COP 10
#define V_TCon_K 11
#define V_TTankTop_K 12
#define V_TTankMid_K 13
#define V_TTankBot_K 14
#define V_THCFlowTrue_K 15
#define V_PComp_W 16
#define V_QBackup_W 17
#define V_nSpeedHPAct_1 18
#define V_pumpConAct_1 19
#define V_defrosting_1 20
#define V_scaleHPQCon_nominal 21
#define V_scaleHPPEl_nominal 22
#define V_mCon_flow_nominal 23
#define V_mHC_flow_nominal 24
#define V_fQWarm 25
#define V_fQMed 26
#define V_fQCold 27
#define V_fPWarm 28
#define V_fPMed 29
#define V_fPCold 30
#define V_T_fixAmbTestHall 31
#define V_lambdaIns 32
#define V_tauVolCon 33
#define V_dTBandBlend 34
#define V_mEvaTable_flow 35
#define V_PFan_nominal 36
#define V_PPump_nominal 37
#define V_PCtrl 38
#define V_VTank 39
#define V_dTank 40
#define V_sIns 41
#define V_mPipe 42
#define V_TStart_K 43
#define V_nSpeedMin 44
#define V_useStartUpLag 45
#define V_tauStartUp 46
#define V_useCycling 47
#define V_TCycOff 48
#define V_dTCycHys 49
#define V_tCycMinRun 50
#define V_tCycMinOff 51
#define V_useHeatLoss 52
#define V_UALossCon 53
#define V_UALossPipe 54
#define V_useSensorLag 55
#define V_tauSensor 56
#define V_useDefrost 57
#define V_tDefrostInterval 58
#define V_tDefrost 59
#define V_fDefrostQ 60
#define V_relHumOdaFix 61
#define V_usePostRun 62
#define V_tPostRun 63
#define V_useBackupHeater 64
#define V_TOdaBackup 65
#define V_PBackup 66
#define V_defrostFromFan 67
#define N_REALS 68
const char MODEL_GUID[] = "{3f2b90ee-68c4-736c-aec5-449849c5f763}";
const unsigned MODEL_N_REALS = N_REALS;
const double MODEL_START[N_REALS] = {
    1.0, /* nSpeedFanEva_1_0 */
    275.15, /* TEva_K */
    303.15, /* THCRet_K */
    1.0, /* nSpeedPumpCon_1_0 */
    0.25, /* m_flowHC_kg_s */
    0.0, /* nSpeedHP_invCtrl0_1 */
    -1.0, /* relHumOda_1 */
    0.0, /* THCFlow_K */
    0.0, /* PEl_W */
    0.0, /* QCon_W */
    0.0, /* COP */
    0.0, /* TCon_K */
    0.0, /* TTankTop_K */
    0.0, /* TTankMid_K */
    0.0, /* TTankBot_K */
    0.0, /* THCFlowTrue_K */
    0.0, /* PComp_W */
    0.0, /* QBackup_W */
    0.0, /* nSpeedHPAct_1 */
    0.0, /* pumpConAct_1 */
    0.0, /* defrosting_1 */
    1.0, /* scaleHPQCon_nominal */
    1.0, /* scaleHPPEl_nominal */
    0.34, /* mCon_flow_nominal */
    0.49, /* mHC_flow_nominal */
    1.0, /* fQWarm */
    1.0, /* fQMed */
    1.0, /* fQCold */
    1.0, /* fPWarm */
    1.0, /* fPMed */
    1.0, /* fPCold */
    295.45, /* T_fixAmbTestHall */
    0.15, /* lambdaIns */
    150.0, /* tauVolCon */
    1.0, /* dTBandBlend */
    0.5, /* mEvaTable_flow */
    80.0, /* PFan_nominal */
    40.0, /* PPump_nominal */
    12.0, /* PCtrl */
    0.046, /* VTank */
    0.3, /* dTank */
    0.1, /* sIns */
    3.0, /* mPipe */
    303.15, /* TStart_K */
    0.25, /* nSpeedMin */
    0.0, /* useStartUpLag */
    90.0, /* tauStartUp */
    0.0, /* useCycling */
    318.15, /* TCycOff */
    5.0, /* dTCycHys */
    600.0, /* tCycMinRun */
    600.0, /* tCycMinOff */
    0.0, /* useHeatLoss */
    10.0, /* UALossCon */
    4.0, /* UALossPipe */
    0.0, /* useSensorLag */
    60.0, /* tauSensor */
    0.0, /* useDefrost */
    2400.0, /* tDefrostInterval */
    300.0, /* tDefrost */
    0.6, /* fDefrostQ */
    0.85, /* relHumOdaFix */
    0.0, /* usePostRun */
    180.0, /* tPostRun */
    0.0, /* useBackupHeater */
    271.15, /* TOdaBackup */
    3000.0, /* PBackup */
    0.0, /* defrostFromFan */
};
const char MODEL_CAUSALITY[N_REALS + 1] = "iiiiiiiooooooooooooooppppppppppppppppppppppppppppppppppppppppppppppp";
#endif
