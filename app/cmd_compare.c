/* cmd_compare.c - `partray compare REF TEST [--heatmap OUT.png] [--json] [--ldr|--hdr]`.
 *
 * Two PNGs are compared as displayed images: their encoded sRGB values, with
 * LDR-FLIP. Anything involving EXR or PFM is compared on linear values with
 * HDR-FLIP (exposure range from the reference). --ldr/--hdr force a mode; --ldr
 * on linear files encodes them with the sRGB curve (clamped) first. Both
 * print the mean Rec.709 luminance of the two images (of linear values) and
 * the test's relative to the reference's. */
#include "cmd_compare.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli.h"
#include "diag.h"
#include "framebuffer.h"
#include "img_io.h"
#include "img_metrics.h"
#include "stats_json.h"

static void encode_srgb(framebuffer *fb)
{
    size_t n = (size_t)fb->width * (size_t)fb->height * 3u;
    for (size_t i = 0; i < n; i++) {
        double v = fb->rgb[i];
        v = isfinite(v) ? fmin(1.0, fmax(0.0, v)) : 0.0;
        fb->rgb[i] = (float)img_srgb_encode(v);
    }
}

static const char compare_help[] =
    "usage: partray compare REF TEST [--heatmap OUT.png|.exr|.pfm] [--json] [--ldr|--hdr]\n"
    "Compares TEST with REF (same size; EXR, PNG or PFM): RMSE, relMSE, PSNR, SSIM,\n"
    "FLIP (mean and weighted median) and mean luminance of each.\n"
    "  --heatmap OUT   FLIP's per-pixel error as an image\n"
    "  --json          the figures as JSON on stdout\n"
    "  --ldr, --hdr    compare as display-referred (sRGB) or scene-linear values\n"
    "                  (default: LDR when both are PNG, else HDR)\n";

static int exit_for(pt_status st) { return cli_exit_status(st); }

void cmd_compare_metrics_json(stats_json *js, const img_compare_result *r, int hdr)
{
    stats_str(js, "mode", hdr ? "hdr" : "ldr");
    STATS_NUMS(js, r, rmse, relmse, psnr, ssim);
    stats_obj_begin(js, "flip");
    stats_num(js, "mean", r->flip_mean);
    stats_num(js, "weighted_median", r->flip_wmedian);
    if (hdr) {
        stats_num(js, "exposure_start", r->exp_start);
        stats_num(js, "exposure_stop", r->exp_stop);
        stats_int(js, "exposures", r->nexposures);
    }
    stats_obj_end(js);
}

int cmd_compare(int argc, char **argv)
{
    const char *ref_path = NULL, *test_path = NULL, *heatmap = NULL;
    int json = 0, force = -1; /* -1 auto, 0 ldr, 1 hdr */
    if (cli_wants_help(argc, argv)) {
        fputs(compare_help, stdout);
        fputs(cli_exit_codes, stdout);
        return CLI_EXIT_OK;
    }
    for (int i = 0; i < argc; i++) {
        if (strcmp(argv[i], "--json") == 0) json = 1;
        else if (strcmp(argv[i], "--ldr") == 0) force = 0;
        else if (strcmp(argv[i], "--hdr") == 0) force = 1;
        else if (strcmp(argv[i], "--heatmap") == 0 && i + 1 < argc) heatmap = argv[++i];
        else if (argv[i][0] == '-' && argv[i][1]) {
            fprintf(stderr, "partray compare: unknown option '%s'\nusage: partray compare REF TEST [--heatmap OUT.png] [--json] [--ldr|--hdr]\n", argv[i]);
            return 2;
        } else if (!ref_path) ref_path = argv[i];
        else if (!test_path) test_path = argv[i];
        else {
            fprintf(stderr, "partray compare: unexpected argument '%s'\n", argv[i]);
            return 2;
        }
    }
    if (!ref_path || !test_path) {
        fprintf(stderr, "usage: partray compare REF TEST [--heatmap OUT.png] [--json] [--ldr|--hdr]\n");
        return 2;
    }
    if (heatmap && img_format_from_path(heatmap) == IMG_FMT_UNKNOWN) {
        fprintf(stderr, "partray compare: heat map '%s': unknown format (use .png, .exr or .pfm)\n", heatmap);
        return 2;
    }
    char werr[512];
    if (heatmap && cli_check_output(heatmap, werr, sizeof werr)) {
        fprintf(stderr, "partray compare: %s\n", werr);
        return CLI_EXIT_IO;
    }
    int both_png = img_format_from_path(ref_path) == IMG_FMT_PNG && img_format_from_path(test_path) == IMG_FMT_PNG;
    int hdr = force >= 0 ? force : !both_png;
    diag *d = diag_new();
    framebuffer *ref = NULL, *test = NULL, *map = NULL;
    /* PNGs compared as LDR keep their encoded values; everything else is linear. */
    int raw = !hdr;
    pt_status st = img_read(ref_path, raw, &ref, d);
    if (st == PT_OK) st = img_read(test_path, raw, &test, d);
    if (st == PT_OK && !hdr) {
        if (img_format_from_path(ref_path) != IMG_FMT_PNG) encode_srgb(ref);
        if (img_format_from_path(test_path) != IMG_FMT_PNG) encode_srgb(test);
    }
    img_compare_result r;
    memset(&r, 0, sizeof r);
    if (st == PT_OK) st = img_compare(ref, test, hdr, &r, heatmap ? &map : NULL, d);
    if (st == PT_OK && heatmap) {
        img_write_opts wo;
        img_default_write_opts(&wo);
        st = img_write(heatmap, map, &wo, d);
    }
    cli_print_diags(d, 0, 0);
    int rc = 0;
    if (st != PT_OK) {
        rc = exit_for(st);
    } else if (json) {
        stats_json js;
        stats_begin(&js);
        stats_str(&js, "reference", ref_path);
        stats_str(&js, "test", test_path);
        stats_int(&js, "width", ref->width);
        stats_int(&js, "height", ref->height);
        cmd_compare_metrics_json(&js, &r, hdr);
        stats_obj_begin(&js, "luminance");
        stats_num(&js, "reference", r.lum_ref);
        stats_num(&js, "test", r.lum_test);
        stats_num(&js, "relative", r.lum_ref > 0.0 ? r.lum_test / r.lum_ref - 1.0 : 0.0);
        stats_obj_end(&js);
        static const char *ch[3] = {"r", "g", "b"};
        stats_obj_begin(&js, "channels");
        for (int c = 0; c < 3; c++) {
            stats_obj_begin(&js, ch[c]);
            stats_num(&js, "rmse", r.rmse_ch[c]);
            stats_num(&js, "relmse", r.relmse_ch[c]);
            stats_num(&js, "ssim", r.ssim_ch[c]);
            stats_obj_end(&js);
        }
        stats_obj_end(&js);
        fputs(stats_end(&js), stdout);
        stats_free(&js);
    } else {
        printf("reference %s\ntest      %s\n%dx%d, %s\n", ref_path, test_path, ref->width, ref->height,
               hdr ? "linear values, HDR-FLIP" : "sRGB-encoded values, LDR-FLIP");
        printf("            all        R          G          B\n");
        printf("RMSE    %10.6f %10.6f %10.6f %10.6f\n", r.rmse, r.rmse_ch[0], r.rmse_ch[1], r.rmse_ch[2]);
        printf("relMSE  %10.6f %10.6f %10.6f %10.6f\n", r.relmse, r.relmse_ch[0], r.relmse_ch[1], r.relmse_ch[2]);
        printf("SSIM    %10.6f %10.6f %10.6f %10.6f\n", r.ssim, r.ssim_ch[0], r.ssim_ch[1], r.ssim_ch[2]);
        printf("PSNR    %10.3f dB\n", r.psnr);
        printf("FLIP    mean %.6f, weighted median %.6f", r.flip_mean, r.flip_wmedian);
        if (hdr) printf(" (exposures %.4f to %.4f, %d)", r.exp_start, r.exp_stop, r.nexposures);
        printf("\n");
        printf("mean luminance  reference %.6f, test %.6f", r.lum_ref, r.lum_test);
        if (r.lum_ref > 0.0) printf(" (%+.2f%%)", 100.0 * (r.lum_test / r.lum_ref - 1.0));
        printf("\n");
        if (heatmap) printf("heat map  %s\n", heatmap);
    }
    fb_free(ref);
    fb_free(test);
    fb_free(map);
    diag_free(d);
    return rc;
}
