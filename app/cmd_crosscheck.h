/* cmd_crosscheck.h - `partray crosscheck`: render a scene with POV-Ray 3.7
 * and with partray at the same size, antialiasing and gamma, and report the
 * comparison. */
#ifndef PT_CMD_CROSSCHECK_H
#define PT_CMD_CROSSCHECK_H
int cmd_crosscheck(int argc, char **argv);
#endif
