/* fuzz_sdl.h - the SDL targets' parser options (limits lowered so one input
 * runs in milliseconds) and the parse-and-check step they share. */
#ifndef PT_FUZZ_SDL_H
#define PT_FUZZ_SDL_H
#include <dirent.h>
#include <unistd.h>
#include "fuzz_common.h"
#include "sdl.h"

/* #fopen ... write/append of a fuzzed scene goes into a directory of our
 * own (never the working directory, where it could overwrite anything),
 * emptied after every input. */
static char fuzz_write_dir[64];

static inline void fuzz_empty_write_dir(void);

static void fuzz_remove_write_dir(void)
{
    fuzz_empty_write_dir();
    rmdir(fuzz_write_dir);
}

static inline const char *fuzz_write_dir_path(void)
{
    if (!fuzz_write_dir[0]) {
        snprintf(fuzz_write_dir, sizeof fuzz_write_dir, "/tmp/partray-fuzz-XXXXXX");
        if (!mkdtemp(fuzz_write_dir)) abort();
        atexit(fuzz_remove_write_dir);
    }
    return fuzz_write_dir;
}

static inline void fuzz_empty_write_dir(void)
{
    DIR *d = opendir(fuzz_write_dir_path());
    if (!d) return;
    struct dirent *e;
    char path[512];
    while ((e = readdir(d))) {
        if (e->d_name[0] == '.' && (!e->d_name[1] || (e->d_name[1] == '.' && !e->d_name[2]))) continue;
        snprintf(path, sizeof path, "%s/%s", fuzz_write_dir, e->d_name);
        unlink(path);
    }
    closedir(d);
}

static inline void fuzz_sdl_options(sdl_options *o)
{
    sdl_default_options(o);
    o->max_loop_iterations = 2000;
    o->max_include_depth = 4;
    o->max_macro_depth = 24;
    o->max_tokens = 300000;            /* bounds nested loops and macro recursion */
    o->max_memory = 256LL << 20;       /* well under -rss_limit_mb */
    o->max_string_length = 1 << 16;
    o->max_array_elements = 1 << 20;
    /* Not POV-Ray's include directory: reading its 36 KB textures.inc on
     * every run makes a target ~6x slower. tests/fuzz/include has small
     * stand-ins of our own (colors.inc, textures.inc) and files that
     * recurse and loop, so #include is still exercised. */
    static const char *const lib[] = {FUZZ_INCLUDE_DIR};
    o->no_default_lib = 1;
    o->lib_paths = lib;
    o->nlib_paths = 1;
    o->write_dir = fuzz_write_dir_path();
}

/* Parse `text` as a whole scene under the fuzzing limits and check the
 * parser's contract: a failure is reported in the diag with a status that
 * says why, a success has no error, and every message formats. */
static inline void fuzz_parse_text(const char *name, const char *text)
{
    sdl_options o;
    fuzz_sdl_options(&o);
    diag *d = diag_new();
    if (!d) return;
    scene *sc = NULL;
    pt_status st = sdl_parse_string(name, text, &o, &sc, d);
    if (st == PT_OK) {
        FUZZ_CHECK(sc != NULL);
        FUZZ_CHECK(diag_errors(d) == 0);
        scene_counts c = scene_count(sc);
        FUZZ_CHECK(c.objects >= 0 && c.lights >= 0 && c.triangles >= 0);
        scene_free(sc);
    } else {
        FUZZ_CHECK(sc == NULL);
        FUZZ_CHECK(diag_errors(d) > 0);
        FUZZ_CHECK(st == PT_ERR_SYNTAX || st == PT_ERR_LIMIT || st == PT_ERR_UNSUPPORTED || st == PT_ERR_IO ||
                   st == PT_ERR_NOMEM);
    }
    for (int i = 0; i < diag_count(d); i++) {
        char *m = diag_format(diag_get(d, i));
        FUZZ_CHECK(m != NULL);
        free(m);
    }
    diag_free(d);
    fuzz_empty_write_dir();
}

#endif
