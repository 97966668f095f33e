/* fuzz_image.c - libFuzzer target for the image readers (io/img_io.h:
 * img_read on EXR, PNG and PFM). The bytes are put in an in-memory file
 * (memfd) and read through its /proc/self/fd path, exactly as a file on disk
 * would be: format by magic bytes, header checks, decoding. A successful
 * read must give a framebuffer inside the documented limits. */
#define _GNU_SOURCE
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>
#include "fuzz_common.h"
#include "img_io.h"

static int g_fd = -1;
static char g_path[64];

static void check_read(int png_raw)
{
    diag *d = diag_new();
    if (!d) return;
    framebuffer *fb = NULL;
    pt_status st = img_read(g_path, png_raw, &fb, d);
    if (st == PT_OK) {
        FUZZ_CHECK(fb && fb->rgb && fb->width > 0 && fb->height > 0);
        FUZZ_CHECK(fb->width <= IMG_MAX_SIDE && fb->height <= IMG_MAX_SIDE);
        FUZZ_CHECK((uint64_t)fb->width * (uint64_t)fb->height <= IMG_MAX_PIXELS);
        /* touch every value: a short buffer is an ASan error */
        size_t n = (size_t)fb->width * (size_t)fb->height * 3u;
        volatile float sink = 0;
        for (size_t i = 0; i < n; i++) sink += fb->rgb[i];
        (void)sink;
        FUZZ_CHECK(diag_errors(d) == 0);
        fb_free(fb);
    } else {
        FUZZ_CHECK(fb == NULL);
        FUZZ_CHECK(diag_errors(d) > 0);
    }
    diag_free(d);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 4 * FUZZ_MAX_INPUT) return 0;
    if (g_fd < 0) {
        g_fd = memfd_create("fuzz_image", MFD_CLOEXEC);
        if (g_fd < 0) abort();
        snprintf(g_path, sizeof g_path, "/proc/self/fd/%d", g_fd);
    }
    if (ftruncate(g_fd, 0) != 0) abort();
    size_t off = 0;
    while (off < size) {
        ssize_t w = pwrite(g_fd, data + off, size - off, (off_t)off);
        if (w <= 0) abort();
        off += (size_t)w;
    }
    check_read(0);
    if (size >= 8 && data[0] == 0x89 && data[1] == 'P') check_read(1);
    return 0;
}
