/* cmd_farm.h - `partray farm`: an animation or a still split into frame x
 * tile tasks, each one idempotent `partray render` command, run by Slurm
 * (job arrays, a merge job that resubmits what is missing) or by GNU
 * parallel over ssh hosts, and merged frame by frame (docs/farm.md). */
#ifndef PT_CMD_FARM_H
#define PT_CMD_FARM_H
int cmd_farm(int argc, char **argv);
#endif
