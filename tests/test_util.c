/* test_util.c - see test_util.h. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include "img_io.h"
#include "test_util.h"

char tu_out[1 << 16];

static int exit_code(int status)
{
    if (status == -1) return -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

int tu_run(const char *cmd)
{
    return exit_code(system(cmd));
}

static int capture(const char *cmd)
{
    FILE *p = popen(cmd, "r");
    if (!p) return -1;
    size_t n = fread(tu_out, 1, sizeof tu_out - 1, p);
    tu_out[n] = 0;
    return exit_code(pclose(p));
}

int tu_run_capture(const char *cmd)
{
    char full[8192];
    snprintf(full, sizeof full, "%s 2>&1", cmd);
    return capture(full);
}

int tu_run_stdout(const char *cmd)
{
    return capture(cmd);
}

void tu_write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs(text, f);
    assert_int_equal(fclose(f), 0);
}

char *tu_read_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    static char buf[1 << 18];
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = 0;
    fclose(f);
    return buf;
}

int tu_exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0;
}

int tu_mkdtemp(char *dir, size_t size, const char *prefix)
{
    snprintf(dir, size, "/tmp/%s-XXXXXX", prefix);
    return mkdtemp(dir) ? 0 : -1;
}

void tu_rm_rf(const char *dir)
{
    DIR *dp = opendir(dir);
    if (dp) {
        struct dirent *e;
        char p[1024];
        while ((e = readdir(dp))) {
            if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
            snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
            unlink(p);
        }
        closedir(dp);
    }
    rmdir(dir);
}

int tu_finish(int rc, const char *dir)
{
    if (rc == 0)
        tu_rm_rf(dir);
    else
        printf("images kept in %s\n", dir);
    return rc;
}

/* Mean absolute difference over all channels of the `f`x`f`
 * box-downsampled images (same size, sRGB-encoded values in 0..1). */
double tu_downsampled_mad(const framebuffer *a, const framebuffer *b, int f)
{
    int w = a->width / f, h = a->height / f;
    double sum = 0.0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 3; c++) {
                double sa = 0, sb = 0;
                for (int j = 0; j < f; j++)
                    for (int i = 0; i < f; i++) {
                        size_t k = ((size_t)(y * f + j) * (size_t)a->width + (size_t)(x * f + i)) * 3 + (size_t)c;
                        sa += a->rgb[k];
                        sb += b->rgb[k];
                    }
                sum += fabs(sa - sb) / (double)(f * f);
            }
    return sum / (3.0 * w * h);
}

double tu_crosscheck(const char *partray_bin, const char *dir, const char *scene_path, const char *tag, int w, int h,
                     const char *decl)
{
    char cmd[4096], pov[512], pt[512];
    snprintf(pov, sizeof pov, "%s/%s_pov.png", dir, tag);
    snprintf(pt, sizeof pt, "%s/%s_pt.png", dir, tag);
    /* POV-Ray restricts file writes to the working directory: run both there. */
    char copy[512];
    snprintf(copy, sizeof copy, "%s/%s.pov", dir, tag);
    if (strcmp(copy, scene_path) != 0) {
        snprintf(cmd, sizeof cmd, "cp '%s' '%s'", scene_path, copy);
        assert_int_equal(tu_run(cmd), 0);
    }
    snprintf(cmd, sizeof cmd,
             "cd '%s' && povray +I%s.pov +O%s_pov.png +W%d +H%d +A0.3 +R3 -D -V -GA +WT2 +FN %s%s >povray_%s.log 2>&1", dir,
             tag, tag, w, h, decl ? "Declare=" : "", decl ? decl : "", tag);
    if (tu_run(cmd) != 0) fail_msg("povray failed on %s; see %s/povray_%s.log", scene_path, dir, tag);
    snprintf(cmd, sizeof cmd,
             "cd '%s' && '%s' render %s.pov -o '%s' +W%d +H%d +A0.3 +R3 --threads 2 --quiet %s%s 2>partray_%s.log", dir,
             partray_bin, tag, pt, w, h, decl ? "-D " : "", decl ? decl : "", tag);
    if (tu_run(cmd) != 0) fail_msg("partray failed on %s; see %s/partray_%s.log", scene_path, dir, tag);
    framebuffer *a = NULL, *b = NULL;
    assert_int_equal(img_read(pov, 1, &a, NULL), PT_OK);
    assert_int_equal(img_read(pt, 1, &b, NULL), PT_OK);
    assert_int_equal(a->width, b->width);
    assert_int_equal(a->height, b->height);
    double mad = tu_downsampled_mad(a, b, 4);
    fb_free(a);
    fb_free(b);
    return mad;
}

double tu_luminance_mean(const framebuffer *fb, const unsigned char *mask)
{
    double s = 0.0;
    long n = 0;
    for (int i = 0; i < fb->width * fb->height; i++) {
        if (mask && !mask[i]) continue;
        const float *p = fb->rgb + 3 * (size_t)i;
        s += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
        n++;
    }
    return n > 0 ? s / n : 0.0;
}
