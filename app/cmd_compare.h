/* cmd_compare.h - `partray compare REF TEST [--heatmap OUT.png] [--json]`. */
#ifndef PT_CMD_COMPARE_H
#define PT_CMD_COMPARE_H
int cmd_compare(int argc, char **argv);
#endif
