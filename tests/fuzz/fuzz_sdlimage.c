/* fuzz_sdlimage.c - libFuzzer target for the parser's image readers: the
 * one decoder sdl_img_read (parser/sdl_imgread.c: PNG, GIF, TGA, PGM/PPM,
 * JPEG, TIFF) on the bytes in memory, and its two entry points as the
 * parser calls them on a file: sdl_image_load (image_map, image_pattern,
 * bump_map; gamma decoding into the scene arena) and sdl_hf_read
 * (height_field; POT is chosen by the file name, so GIF input is read again
 * through a symbolic link named *.pot). The file is an in-memory file
 * (memfd) read through its /proc/self/fd path. A successful read must give
 * an image within the readers' limits with every value finite; a failed one
 * a reason and nothing to free. */
#define _GNU_SOURCE
#include <fcntl.h>
#include <math.h>
#include <sys/mman.h>
#include <unistd.h>
#include "arena.h"
#include "fuzz_common.h"
#include "sdl_hfimage.h"
#include "sdl_image.h"
#include "sdl_imgread.h"

/* The pixel limit the readers are given here. The default limit
 * (SDL_IMG_MAX_PIXELS) is legal for a scene, but at 8 bytes a pixel of
 * decoded samples and 20 of RGBFT floats it is several GiB, past the 1 GiB
 * malloc limit fuzz_one.sh gives libFuzzer; a compressed header can declare
 * that much in a few bytes. The limit check itself is what is fuzzed. */
#define FUZZ_MAX_PIXELS (1ull << 22)

static int g_fd = -1;
static char g_path[64], g_dir[64], g_pot[96];

static void remove_link(void)
{
    unlink(g_pot);
    rmdir(g_dir);
}

static void setup(void)
{
    g_fd = memfd_create("fuzz_sdlimage", MFD_CLOEXEC);
    if (g_fd < 0) abort();
    snprintf(g_path, sizeof g_path, "/proc/self/fd/%d", g_fd);
    snprintf(g_dir, sizeof g_dir, "/tmp/partray-fuzz-img-XXXXXX");
    if (!mkdtemp(g_dir)) abort();
    snprintf(g_pot, sizeof g_pot, "%s/in.pot", g_dir);
    if (symlink(g_path, g_pot) != 0) abort();
    atexit(remove_link);
}

static void check_decoder(const uint8_t *data, size_t size)
{
    sdl_img img;
    char why[512] = "";
    int r = sdl_img_read(NULL, data, size, FUZZ_MAX_PIXELS, &img, why, sizeof why);
    if (r == SDL_IMG_OK) {
        FUZZ_CHECK(img.rgba && img.width > 0 && img.height > 0);
        FUZZ_CHECK(img.width <= SDL_IMG_MAX_SIDE && img.height <= SDL_IMG_MAX_SIDE);
        FUZZ_CHECK((uint64_t)img.width * (uint64_t)img.height <= FUZZ_MAX_PIXELS);
        volatile unsigned sink = 0;
        size_t n = (size_t)img.width * (size_t)img.height;
        for (size_t i = 0; i < n * 4; i++) sink += img.rgba[i]; /* a short buffer is an ASan error */
        if (img.index)
            for (size_t i = 0; i < n; i++) sink += img.index[i];
        (void)sink;
        sdl_img_free(&img);
    } else {
        FUZZ_CHECK(r == SDL_IMG_ERROR || r == SDL_IMG_UNSUPPORTED);
        FUZZ_CHECK(img.rgba == NULL && img.index == NULL);
        FUZZ_CHECK(why[0] != 0);
    }
}

static void check_map_image(double gamma, double working_gamma)
{
    arena *mem = arena_new();
    if (!mem) return;
    scene_image img;
    memset(&img, 0, sizeof img);
    img.path = g_path;
    img.gamma = gamma;
    char why[512] = "";
    if (sdl_image_load(&img, mem, working_gamma, FUZZ_MAX_PIXELS, why, sizeof why) == 0) {
        FUZZ_CHECK(img.pixels && img.width > 0 && img.height > 0);
        FUZZ_CHECK((uint64_t)img.width * (uint64_t)img.height <= FUZZ_MAX_PIXELS);
        size_t n = (size_t)img.width * (size_t)img.height * 5u; /* RGBFT */
        for (size_t i = 0; i < n; i++) FUZZ_CHECK(isfinite(img.pixels[i]));
    } else {
        FUZZ_CHECK(why[0] != 0);
    }
    arena_free(mem);
}

static void check_height_field(const char *path)
{
    sdl_hf_image hf;
    memset(&hf, 0, sizeof hf);
    char why[512] = "";
    int r = sdl_hf_read(path, FUZZ_MAX_PIXELS, &hf, why, sizeof why);
    if (r == SDL_HF_OK) {
        FUZZ_CHECK(hf.values && hf.width > 0 && hf.height > 0);
        FUZZ_CHECK((uint64_t)hf.width * (uint64_t)hf.height <= FUZZ_MAX_PIXELS);
        volatile unsigned sink = 0;
        for (size_t i = 0; i < (size_t)hf.width * (size_t)hf.height; i++) sink += hf.values[i];
        (void)sink;
        free(hf.values);
    } else {
        FUZZ_CHECK(r == SDL_HF_ERROR || r == SDL_HF_UNSUPPORTED);
        FUZZ_CHECK(hf.values == NULL);
        FUZZ_CHECK(why[0] != 0);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 4 * FUZZ_MAX_INPUT) return 0;
    if (g_fd < 0) setup();
    check_decoder(data, size);
    if (ftruncate(g_fd, 0) != 0) abort();
    size_t off = 0;
    while (off < size) {
        ssize_t w = pwrite(g_fd, data + off, size - off, (off_t)off);
        if (w <= 0) abort();
        off += (size_t)w;
    }
    /* image_map: the file's own curve into a linear working space, or the
     * scene's gamma 2.2 into gamma 2.2, or a data image (no gamma handling) */
    if (size > 0 && (data[size - 1] & 1)) check_map_image(2.2, 2.2);
    else check_map_image(0.0, size > 0 && (data[size - 1] & 2) ? 0.0 : 1.0);
    check_height_field(g_path);
    if (size >= 4 && memcmp(data, "GIF8", 4) == 0) check_height_field(g_pot);
    return 0;
}
