/* Value references of brine_water_hp: index into the Real array. Keep in step with modelDescription.xml
   (tests/test_models_interface.py checks that they agree). */
#ifndef VARIABLES_H
#define VARIABLES_H
#include <stddef.h>
#define V_TConIn_K 0
#define V_TEvaIn_K 1
#define V_yCompressor_1 2
#define V_yPumpCon_1 3
#define V_yPumpEva_1 4
#define V_TConOut_K 5
#define V_TEvaOut_K 6
#define V_PEl_W 7
#define V_QCon_W 8
#define V_QEva_W 9
#define V_COP 10
#define V_etaCarnot_nominal 11
#define V_PEle_nominal 12
#define V_mCon_flow_nominal 13
#define V_mEva_flow_nominal 14
#define V_VCon 15
#define V_VEva 16
#define V_useInertia 17
#define V_refIneFreConst 18
#define V_nthOrder 19
#define V_dTAppCon 20
#define V_dTAppEva 21
#define V_PPumpCon 22
#define V_PPumpEva 23
#define V_cpBrine 24
#define V_UALossCon 25
#define V_TAmb_K 26
#define V_TConStart_K 27
#define V_TEvaStart_K 28
#define N_REALS 29
const char MODEL_GUID[] = "{490da25e-ffd1-9430-30ef-9bc0bf703af8}";
const unsigned MODEL_N_REALS = N_REALS;
const double MODEL_START[N_REALS] = {
    303.15, /* TConIn_K */
    283.15, /* TEvaIn_K */
    0.0, /* yCompressor_1 */
    0.0, /* yPumpCon_1 */
    0.0, /* yPumpEva_1 */
    0.0, /* TConOut_K */
    0.0, /* TEvaOut_K */
    0.0, /* PEl_W */
    0.0, /* QCon_W */
    0.0, /* QEva_W */
    0.0, /* COP */
    0.4318, /* etaCarnot_nominal */
    1884.2, /* PEle_nominal */
    0.407396, /* mCon_flow_nominal */
    0.8, /* mEva_flow_nominal */
    0.0015972, /* VCon */
    0.0015972, /* VEva */
    1.0, /* useInertia */
    0.0132, /* refIneFreConst */
    3.0, /* nthOrder */
    0.0, /* dTAppCon */
    0.0, /* dTAppEva */
    60.0, /* PPumpCon */
    60.0, /* PPumpEva */
    3800.0, /* cpBrine */
    0.0, /* UALossCon */
    293.15, /* TAmb_K */
    -1.0, /* TConStart_K */
    -1.0, /* TEvaStart_K */
};
const char MODEL_CAUSALITY[N_REALS + 1] = "iiiiioooooopppppppppppppppppp";
#endif
