/* cmd_sweep.h - `partray sweep`: render a scene with several settings (and
 * GI modes), compare each image with a reference, and write a CSV, an
 * error-against-time plot and an HTML page. */
#ifndef PT_CMD_SWEEP_H
#define PT_CMD_SWEEP_H
int cmd_sweep(int argc, char **argv);
#endif
