/* Value references of water_to_water_hp: index into the Real array. Keep in step with modelDescription.xml
   (tests/test_models_interface.py checks that they agree). */
#ifndef VARIABLES_H
#define VARIABLES_H
#include <stddef.h>
#define V_TOda_K 0
#define V_HGloHor_W_m2 1
#define V_dTZoneSetShift_K 2
#define V_PEl_W 3
#define V_TSup_K 4
#define V_TSupTrue_K 5
#define V_TRet_K 6
#define V_TZone_K 7
#define V_TTankTop_K 8
#define V_TTankCutIn_K 9
#define V_TTankBot_K 10
#define V_THPOut_K 11
#define V_TSupSet_K 12
#define V_QHP_W 13
#define V_QFloor_W 14
#define V_QBackup_W 15
#define V_COP 16
#define V_hpOn_1 17
#define V_controlStructure 18
#define V_dTGenSto 19
#define V_dTCutInOut 20
#define V_THeaCurY2_K 21
#define V_TZoneSet_K 22
#define V_dTCtrlBand 23
#define V_nInf_1_h 24
#define V_hCutIn 25
#define V_flowRatioSrcDem 26
#define V_tankHD 27
#define V_QHP_nominal 28
#define V_etaCarnot 29
#define V_TSource_K 30
#define V_PPumpHP 31
#define V_THeaCurX1_K 32
#define V_THeaCurY1_K 33
#define V_THeaCurX2_K 34
#define V_QFloor_design 35
#define V_VTank 36
#define V_hCutOut 37
#define V_UTank 38
#define V_TRoomPlant_K 39
#define V_AFloor 40
#define V_UATrans 41
#define V_UAPipeSlab 42
#define V_UASlabZone 43
#define V_CSlab 44
#define V_CZone 45
#define V_AWinEff 46
#define V_QInt 47
#define V_TStart_K 48
#define V_useStartUpLag 49
#define V_tauStartUp 50
#define V_useCycling 51
#define V_tCycMinRun 52
#define V_tCycMinOff 53
#define V_plrCycMin 54
#define V_useHeatLoss 55
#define V_UALossGen 56
#define V_useSensorLag 57
#define V_tauSensor 58
#define V_usePostRun 59
#define V_tPostRun 60
#define V_useBackupHeater 61
#define V_TOdaBackup 62
#define V_PBackup 63
#define N_REALS 64
const char MODEL_GUID[] = "{6c064c62-dc75-5c3e-3935-6839a2e86f3c}";
const unsigned MODEL_N_REALS = N_REALS;
const double MODEL_START[N_REALS] = {
    273.15, /* TOda_K */
    0.0, /* HGloHor_W_m2 */
    0.0, /* dTZoneSetShift_K */
    0.0, /* PEl_W */
    0.0, /* TSup_K */
    0.0, /* TSupTrue_K */
    0.0, /* TRet_K */
    0.0, /* TZone_K */
    0.0, /* TTankTop_K */
    0.0, /* TTankCutIn_K */
    0.0, /* TTankBot_K */
    0.0, /* THPOut_K */
    0.0, /* TSupSet_K */
    0.0, /* QHP_W */
    0.0, /* QFloor_W */
    0.0, /* QBackup_W */
    0.0, /* COP */
    0.0, /* hpOn_1 */
    1.0, /* controlStructure */
    2.0, /* dTGenSto */
    0.0, /* dTCutInOut */
    301.15, /* THeaCurY2_K */
    294.15, /* TZoneSet_K */
    1.1, /* dTCtrlBand */
    0.12, /* nInf_1_h */
    0.75, /* hCutIn */
    1.4, /* flowRatioSrcDem */
    2.0, /* tankHD */
    43700.0, /* QHP_nominal */
    0.45, /* etaCarnot */
    283.15, /* TSource_K */
    400.0, /* PPumpHP */
    265.15, /* THeaCurX1_K */
    308.15, /* THeaCurY1_K */
    288.15, /* THeaCurX2_K */
    40000.0, /* QFloor_design */
    2.0, /* VTank */
    0.1, /* hCutOut */
    0.4, /* UTank */
    288.15, /* TRoomPlant_K */
    2760.0, /* AFloor */
    1150.0, /* UATrans */
    5550.0, /* UAPipeSlab */
    8000.0, /* UASlabZone */
    310000000.0, /* CSlab */
    280000000.0, /* CZone */
    40.0, /* AWinEff */
    5500.0, /* QInt */
    294.15, /* TStart_K */
    0.0, /* useStartUpLag */
    180.0, /* tauStartUp */
    0.0, /* useCycling */
    1200.0, /* tCycMinRun */
    1200.0, /* tCycMinOff */
    0.4, /* plrCycMin */
    0.0, /* useHeatLoss */
    150.0, /* UALossGen */
    0.0, /* useSensorLag */
    600.0, /* tauSensor */
    0.0, /* usePostRun */
    900.0, /* tPostRun */
    0.0, /* useBackupHeater */
    271.15, /* TOdaBackup */
    9000.0, /* PBackup */
};
const char MODEL_CAUSALITY[N_REALS + 1] = "iiiooooooooooooooopppppppppppppppppppppppppppppppppppppppppppppp";
#endif
