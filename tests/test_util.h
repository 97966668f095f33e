/* test_util.h - helpers shared by the tests: shell commands with captured
 * output, small files, temporary directories, and the POV-Ray cross-check
 * (both renderers, 4x4-downsampled mean absolute sRGB difference). */
#ifndef PT_TEST_UTIL_H
#define PT_TEST_UTIL_H

#include <stddef.h>
#include "framebuffer.h"

/* Output of the last tu_run_capture / tu_run_stdout (NUL-terminated). */
extern char tu_out[1 << 16];

/* Run `cmd` through the shell; exit code, or 128 + signal when killed. */
int tu_run(const char *cmd);
/* Same, with stdout and stderr captured into tu_out. */
int tu_run_capture(const char *cmd);
/* Same, capturing stdout only (stderr goes to the terminal). */
int tu_run_stdout(const char *cmd);

/* Write `text` to `path` (fails the test when it cannot). */
void tu_write_file(const char *path, const char *text);
/* The text of `path` (its first 256 KiB) in a buffer of the test library,
 * valid until the next call; NULL when it cannot be read. */
char *tu_read_file(const char *path);
/* 1 when `path` exists. */
int tu_exists(const char *path);

/* Make a fresh directory /tmp/<prefix>-XXXXXX into dir (size >= 64);
 * returns 0 on success. tu_rm_rf removes it and its plain files. */
int tu_mkdtemp(char *dir, size_t size, const char *prefix);
void tu_rm_rf(const char *dir);
/* End of a test program: removes dir when rc is 0, else says where its
 * files were kept; returns rc. */
int tu_finish(int rc, const char *dir);

/* Mean Rec. 709 luminance (0.2126 R + 0.7152 G + 0.0722 B) of the linear
 * framebuffer over the pixels with mask[i] != 0 (mask NULL: all); 0 when
 * none. */
double tu_luminance_mean(const framebuffer *fb, const unsigned char *mask);

/* Mean absolute difference over all channels of a and b (same size) after
 * an f x f box downsample of each. */
double tu_downsampled_mad(const framebuffer *a, const framebuffer *b, int f);

/* Copy `scene_path` into `dir`, render it there with Debian's povray and
 * with `partray_bin` at w x h, +A0.3, both to sRGB PNG; `decl` is NAME=VALUE
 * (passed as Declare= / -D) or NULL. Returns the 4x4-downsampled mean
 * absolute difference; fails the test when either renderer fails. */
double tu_crosscheck(const char *partray_bin, const char *dir, const char *scene_path, const char *tag, int w, int h,
                     const char *decl);

#endif
