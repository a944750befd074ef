/* The FMI 2.0 interface shared by the example models: one copy, in ../common. */
#include "../common/fmi2_glue.c"
