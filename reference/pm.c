/* pm.c - placeholder until the reference renderers land: reports that they are not built. */
#include "pm.h"
int pm_available(void) { return 0; }
