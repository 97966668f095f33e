/* pm.h - reference renderers: photon map + final gathering, path tracer (land with their issue). */
#ifndef PT_PM_H
#define PT_PM_H
int pm_available(void);
#endif
