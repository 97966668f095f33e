/* cmd_merge.h - `partray merge OUT TILE.exr...`: one image from the EXR
 * tiles of a frame (render windows, +SC/+EC/+SR/+ER). */
#ifndef PT_CMD_MERGE_H
#define PT_CMD_MERGE_H
#include "diag.h"
/* Checks that the tiles share one display window and the same scene hash,
 * frame and settings, and cover the image exactly (no gap, no overlap),
 * then writes OUT (32-bit float EXR, PNG or PFM; under a temporary name,
 * renamed) with their pixels and shared header. PT_ERR_USAGE (with the
 * reason in d) when they do not fit together, PT_ERR_IO when one cannot be
 * read or OUT cannot be written. */
pt_status merge_tiles(const char *out, const char *const *tiles, int ntiles, diag *d);
int cmd_merge(int argc, char **argv);
#endif
