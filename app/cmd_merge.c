/* cmd_merge.c - `partray merge OUT TILE...`.
 *
 * A tile is an EXR written by `partray render` with a render window: its
 * display window is the whole frame, its data window the tile, and its
 * header names the scene (partray:scene_hash), the frame and clock
 * (partray:frame) and the settings that change pixels (partray:settings).
 * Every pixel's random streams depend on the pixel only, so the tiles of a
 * frame put together equal the frame rendered in one process. */
#include "cmd_merge.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli.h"
#include "framebuffer.h"
#include "img_exr.h"
#include "img_io.h"

/* header keys every tile of one frame must share */
static const char *const same_keys[] = {"partray:scene_hash", "partray:frame", "partray:settings", "partray:gi",
                                        "partray:scene"};
#define NKEYS 5

pt_status merge_tiles(const char *out, const char *const *tiles, int ntiles, diag *d)
{
    if (ntiles < 1) {
        diag_error(d, "merge: no tiles given");
        return PT_ERR_USAGE;
    }
    if (img_format_from_path(out) == IMG_FMT_UNKNOWN) {
        diag_error(d, "merge: output '%s': unknown format (use .exr, .png or .pfm)", out);
        return PT_ERR_USAGE;
    }
    char *first[NKEYS] = {0};
    int W = 0, H = 0;
    unsigned char *cover = NULL;
    framebuffer *fb = NULL;
    pt_status st = PT_OK;
    for (int t = 0; t < ntiles && st == PT_OK; t++) {
        char *vals[NKEYS];
        int w, h, win[4];
        st = img_exr_info(tiles[t], &w, &h, win, same_keys, NKEYS, vals, d);
        if (st != PT_OK) break;
        if (t == 0) {
            W = w;
            H = h;
            if (!vals[0] || !vals[1] || !vals[2]) {
                diag_error(d, "merge: '%s' is not a partray tile (no partray:scene_hash, frame or settings in its header)",
                           tiles[t]);
                st = PT_ERR_USAGE;
            }
            memcpy(first, vals, sizeof first);
            cover = calloc((size_t)W * (size_t)H, 1);
            fb = fb_new(W, H);
            if (st == PT_OK && (!cover || !fb)) st = PT_ERR_NOMEM;
        } else {
            if (w != W || h != H) {
                diag_error(d, "merge: '%s' is a tile of a %dx%d image, '%s' of a %dx%d one", tiles[t], w, h, tiles[0], W, H);
                st = PT_ERR_USAGE;
            }
            for (int k = 0; k < NKEYS && st == PT_OK; k++) {
                const char *a = first[k] ? first[k] : "", *b = vals[k] ? vals[k] : "";
                if (strcmp(a, b) != 0) {
                    diag_error(d, "merge: '%s' and '%s' differ in %s ('%s' and '%s')", tiles[0], tiles[t], same_keys[k], a, b);
                    st = PT_ERR_USAGE;
                }
            }
            for (int k = 0; k < NKEYS; k++) free(vals[k]);
        }
        if (st != PT_OK) break;
        /* the data window inside the display window, no pixel twice */
        if (win[0] < 0 || win[1] < 0 || win[2] > W || win[3] > H || win[2] <= win[0] || win[3] <= win[1]) {
            diag_error(d, "merge: '%s': its data window is outside the %dx%d image", tiles[t], W, H);
            st = PT_ERR_USAGE;
            break;
        }
        for (int y = win[1]; y < win[3] && st == PT_OK; y++)
            for (int x = win[0]; x < win[2]; x++) {
                if (cover[(size_t)y * W + x]) {
                    diag_error(d, "merge: '%s' overlaps an earlier tile at pixel (%d, %d)", tiles[t], x, y);
                    st = PT_ERR_USAGE;
                    break;
                }
                cover[(size_t)y * W + x] = 1;
            }
        if (st != PT_OK) break;
        framebuffer *tf = NULL;
        st = img_read(tiles[t], 0, &tf, d);
        if (st != PT_OK) break;
        if (tf->width != win[2] - win[0] || tf->height != win[3] - win[1]) {
            diag_error(d, "merge: '%s': its pixels do not fill its data window", tiles[t]);
            st = PT_ERR_IO;
        } else {
            for (int y = 0; y < tf->height; y++)
                memcpy(fb_px(fb, win[0], win[1] + y), fb_px(tf, 0, y), sizeof(float) * 3 * (size_t)tf->width);
        }
        fb_free(tf);
    }
    if (st == PT_OK) {
        long gaps = 0;
        int gx = -1, gy = -1;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++)
                if (!cover[(size_t)y * W + x]) {
                    if (!gaps) { gx = x; gy = y; }
                    gaps++;
                }
        if (gaps) {
            diag_error(d, "merge: the tiles leave %ld pixels of the %dx%d image uncovered (the first at (%d, %d))", gaps, W, H,
                       gx, gy);
            st = PT_ERR_USAGE;
        }
    }
    if (st == PT_OK) {
        img_write_opts wo;
        img_default_write_opts(&wo);
        wo.exr_float = 1; /* the tiles' values, half or float, unchanged */
        const char *keys[NKEYS + 1], *vals[NKEYS + 1];
        int n = 0;
        for (int k = 0; k < NKEYS; k++)
            if (first[k]) { keys[n] = same_keys[k]; vals[n++] = first[k]; }
        char count[32];
        snprintf(count, sizeof count, "%d", ntiles);
        keys[n] = "partray:merged_tiles";
        vals[n++] = count;
        wo.meta_keys = keys;
        wo.meta_values = vals;
        wo.nmeta = n;
        st = img_write(out, fb, &wo, d);
    }
    for (int k = 0; k < NKEYS; k++) free(first[k]);
    free(cover);
    fb_free(fb);
    return st;
}

static const char merge_help[] =
    "usage: partray merge OUT.exr|.png|.pfm TILE.exr...\n"
    "Puts the EXR tiles of one frame (renders with +SC/+EC/+SR/+ER) into OUT, after\n"
    "checking that they come from the same scene, frame and settings and cover the\n"
    "frame once. docs/farm.md describes tiles, merging and the farm.\n";

int cmd_merge(int argc, char **argv)
{
    if (cli_wants_help(argc, argv)) {
        fputs(merge_help, stdout);
        fputs(cli_exit_codes, stdout);
        return CLI_EXIT_OK;
    }
    if (argc < 2) {
        fputs(merge_help, stderr);
        return CLI_EXIT_USAGE;
    }
    char err[512];
    if (img_format_from_path(argv[0]) != IMG_FMT_UNKNOWN && cli_check_output(argv[0], err, sizeof err)) {
        fprintf(stderr, "partray merge: %s\n", err);
        return CLI_EXIT_IO;
    }
    diag *d = diag_new();
    pt_status st = merge_tiles(argv[0], (const char *const *)(argv + 1), argc - 1, d);
    cli_print_diags(d, 0, 0);
    diag_free(d);
    return st == PT_OK ? 0 : st == PT_ERR_IO ? 3 : st == PT_ERR_NOMEM ? 3 : 2;
}
