/* view_sdl.h - SDL2, loaded when the viewer opens its window.
 *
 * Only `partray view` uses SDL2, but as a link-time dependency it and the
 * libraries it needs (X11, Wayland, PulseAudio, D-Bus, codecs: about 45
 * of the binary's shared objects) were mapped and relocated at the start
 * of every partray process, a render's fixed cost. The viewer loads it
 * with dlopen instead (view_sdl_load) and calls it through view_sdl's
 * pointers; the macros below give those the SDL names, so the viewer's
 * code reads as SDL code. Types and constants come from SDL's headers. */
#ifndef PT_VIEW_SDL_H
#define PT_VIEW_SDL_H

#define SDL_MAIN_HANDLED
#include <SDL.h>

/* The functions the viewer calls: return type, name without "SDL_",
 * parameters (as SDL 2.0's headers declare them). */
#define VIEW_SDL_FUNCS(X)                                                                                             \
    X(int, Init, (Uint32 flags))                                                                                      \
    X(void, Quit, (void))                                                                                             \
    X(void, SetMainReady, (void))                                                                                     \
    X(const char *, GetError, (void))                                                                                 \
    X(SDL_Window *, CreateWindow, (const char *title, int x, int y, int w, int h, Uint32 flags))                      \
    X(void, DestroyWindow, (SDL_Window * window))                                                                     \
    X(void, SetWindowTitle, (SDL_Window * window, const char *title))                                                 \
    X(SDL_Renderer *, CreateRenderer, (SDL_Window * window, int index, Uint32 flags))                                 \
    X(void, DestroyRenderer, (SDL_Renderer * renderer))                                                               \
    X(int, GetRendererOutputSize, (SDL_Renderer * renderer, int *w, int *h))                                          \
    X(int, RenderSetLogicalSize, (SDL_Renderer * renderer, int w, int h))                                             \
    X(int, SetRenderDrawColor, (SDL_Renderer * renderer, Uint8 r, Uint8 g, Uint8 b, Uint8 a))                         \
    X(int, RenderClear, (SDL_Renderer * renderer))                                                                    \
    X(int, RenderCopy, (SDL_Renderer * renderer, SDL_Texture * texture, const SDL_Rect *srcrect,                      \
                        const SDL_Rect *dstrect))                                                                     \
    X(void, RenderPresent, (SDL_Renderer * renderer))                                                                 \
    X(int, RenderReadPixels, (SDL_Renderer * renderer, const SDL_Rect *rect, Uint32 format, void *pixels, int pitch)) \
    X(SDL_Texture *, CreateTexture, (SDL_Renderer * renderer, Uint32 format, int access, int w, int h))               \
    X(void, DestroyTexture, (SDL_Texture * texture))                                                                  \
    X(int, UpdateTexture, (SDL_Texture * texture, const SDL_Rect *rect, const void *pixels, int pitch))               \
    X(int, SetTextureBlendMode, (SDL_Texture * texture, SDL_BlendMode blendMode))                                     \
    X(int, SetTextureScaleMode, (SDL_Texture * texture, SDL_ScaleMode scaleMode))                                     \
    X(int, PollEvent, (SDL_Event * event))                                                                            \
    X(int, WaitEventTimeout, (SDL_Event * event, int timeout))                                                        \
    X(int, PushEvent, (SDL_Event * event))                                                                            \
    X(SDL_Keycode, GetKeyFromName, (const char *name))                                                                \
    X(SDL_Scancode, GetScancodeFromKey, (SDL_Keycode key))

#define VIEW_SDL_MEMBER(ret, name, params) ret(SDLCALL *name) params;
typedef struct {
    VIEW_SDL_FUNCS(VIEW_SDL_MEMBER)
} view_sdl_api;
#undef VIEW_SDL_MEMBER

/* Filled by view_sdl_load; read only after it returned 1. */
extern view_sdl_api view_sdl;

/* Loads SDL2 (once; later calls return the first call's result). 1: every
 * function above is there; 0: not, with the reason in err (n bytes). */
int view_sdl_load(char *err, size_t n);

#define SDL_Init view_sdl.Init
#define SDL_Quit view_sdl.Quit
#define SDL_SetMainReady view_sdl.SetMainReady
#define SDL_GetError view_sdl.GetError
#define SDL_CreateWindow view_sdl.CreateWindow
#define SDL_DestroyWindow view_sdl.DestroyWindow
#define SDL_SetWindowTitle view_sdl.SetWindowTitle
#define SDL_CreateRenderer view_sdl.CreateRenderer
#define SDL_DestroyRenderer view_sdl.DestroyRenderer
#define SDL_GetRendererOutputSize view_sdl.GetRendererOutputSize
#define SDL_RenderSetLogicalSize view_sdl.RenderSetLogicalSize
#define SDL_SetRenderDrawColor view_sdl.SetRenderDrawColor
#define SDL_RenderClear view_sdl.RenderClear
#define SDL_RenderCopy view_sdl.RenderCopy
#define SDL_RenderPresent view_sdl.RenderPresent
#define SDL_RenderReadPixels view_sdl.RenderReadPixels
#define SDL_CreateTexture view_sdl.CreateTexture
#define SDL_DestroyTexture view_sdl.DestroyTexture
#define SDL_UpdateTexture view_sdl.UpdateTexture
#define SDL_SetTextureBlendMode view_sdl.SetTextureBlendMode
#define SDL_SetTextureScaleMode view_sdl.SetTextureScaleMode
#define SDL_PollEvent view_sdl.PollEvent
#define SDL_WaitEventTimeout view_sdl.WaitEventTimeout
#define SDL_PushEvent view_sdl.PushEvent
#define SDL_GetKeyFromName view_sdl.GetKeyFromName
#define SDL_GetScancodeFromKey view_sdl.GetScancodeFromKey

#endif
