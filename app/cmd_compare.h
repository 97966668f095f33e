/* cmd_compare.h - `partray compare REF TEST [--heatmap OUT.png] [--json]`. */
#ifndef PT_CMD_COMPARE_H
#define PT_CMD_COMPARE_H
#include "img_metrics.h"
#include "stats_json.h"

int cmd_compare(int argc, char **argv);
/* The metrics of r as `compare --json` writes them: "mode" (hdr or ldr),
 * "rmse", "relmse", "psnr", "ssim" and "flip": {"mean", "weighted_median"
 * and, for hdr, the exposure range}. */
void cmd_compare_metrics_json(stats_json *js, const img_compare_result *r, int hdr);
#endif
