/* view_sdl.c - SDL2 loaded with dlopen (view_sdl.h). */
#include "view_sdl.h"
#include <dlfcn.h>
#include <stdio.h>
#include <string.h>

view_sdl_api view_sdl;

/* SDL2's runtime name (its soname since 2.0.0) */
#define VIEW_SDL_LIB "libSDL2-2.0.so.0"

int view_sdl_load(char *err, size_t n)
{
    static int state;      /* 0 not tried, 1 loaded, -1 failed */
    static char why[256];
    if (state == 0) {
        void *h = dlopen(VIEW_SDL_LIB, RTLD_NOW | RTLD_LOCAL);
        state = h ? 1 : -1;
        if (!h) snprintf(why, sizeof why, "cannot load %s: %s", VIEW_SDL_LIB, dlerror());
        /* a symbol's address is stored through the pointer's bytes: POSIX
         * gives dlsym's void * the function's address, ISO C has no cast
         * between the two */
#define VIEW_SDL_SYM(ret, name, params)                                                                               \
    if (state == 1) {                                                                                                 \
        void *f = dlsym(h, "SDL_" #name);                                                                             \
        if (f) memcpy(&view_sdl.name, &f, sizeof f);                                                                  \
        else {                                                                                                        \
            snprintf(why, sizeof why, "%s has no SDL_%s", VIEW_SDL_LIB, #name);                                       \
            state = -1;                                                                                               \
        }                                                                                                             \
    }
        VIEW_SDL_FUNCS(VIEW_SDL_SYM)
#undef VIEW_SDL_SYM
        if (state < 0) memset(&view_sdl, 0, sizeof view_sdl);
    }
    if (state < 0 && err && n > 0) snprintf(err, n, "%s", why);
    return state == 1;
}
