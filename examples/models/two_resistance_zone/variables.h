/* Value references of two_resistance_zone: index into the Real array. Keep in step with modelDescription.xml. */
#ifndef VARIABLES_H
#define VARIABLES_H
#include <stddef.h>
#define V_T_out 0
#define V_T_zone 1
#define V_T_core 2
#define V_tau 3
#define V_R1 4
#define V_R2 5
#define V_C 6
#define V_h_folded 7
#define V_T_core_start 8
#define N_REALS 9
const char MODEL_GUID[] = "{7c2e41a9-3b5d-4f0e-9a61-2d8c5e7b1f30}";
const unsigned MODEL_N_REALS = N_REALS;
const double MODEL_START[N_REALS] = {
    273.15, /* T_out */
    0.0, /* T_zone */
    0.0, /* T_core */
    0.0, /* tau */
    0.01, /* R1 */
    0.02, /* R2 */
    2.0e6, /* C */
    10.0, /* h_folded */
    -1.0, /* T_core_start */
};
const char MODEL_CAUSALITY[N_REALS + 1] = "ioooppppp";
#endif
