/* io_display_sdl.c - the SDL2 window backend (io_display.h) for
 * development machines. libSDL2 is opened with dlopen when a window is
 * opened (compiled against the headers only), so the egofuse commands
 * that do not open one never load it and the dozens of libraries behind
 * it. EGOFUSE_SDL_LIB names another library file (tests). The library
 * stays loaded once opened (X11 libraries do not like being unloaded). */
#include "io_display_impl.h"

#ifdef EGOFUSE_NO_SDL2
/* Built where SDL2's headers were missing (the Makefile defines
 * EGOFUSE_NO_SDL2 when pkg-config finds no sdl2: `make demo` does not
 * install libsdl2-dev, scripts/deps.sh). The Makefile recompiles this file
 * once the headers are there. */
io_result io_display_sdl_open(io_display *d, const io_display_spec *sp, io_error *err)
{
    (void)d;
    (void)sp;
    return io_fail(err, IO_ERR_DEVICE, "sdl: this egofuse was built without SDL2's headers "
                   "(Debian: libsdl2-dev, installed by 'make test'); install them and run make again");
}
#else

#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <SDL.h>

#define SDL_LIB "libSDL2-2.0.so.0"

/* The functions used, as a table filled by dlsym. */
#define SDL_FUNCS(X)                                                                       \
    X(int, SDL_InitSubSystem, (Uint32))                                                    \
    X(void, SDL_QuitSubSystem, (Uint32))                                                   \
    X(const char *, SDL_GetError, (void))                                                  \
    X(SDL_bool, SDL_SetHint, (const char *, const char *))                                 \
    X(SDL_Window *, SDL_CreateWindow, (const char *, int, int, int, int, Uint32))          \
    X(void, SDL_DestroyWindow, (SDL_Window *))                                             \
    X(SDL_Renderer *, SDL_CreateRenderer, (SDL_Window *, int, Uint32))                     \
    X(void, SDL_DestroyRenderer, (SDL_Renderer *))                                         \
    X(int, SDL_GetRendererInfo, (SDL_Renderer *, SDL_RendererInfo *))                      \
    X(SDL_Texture *, SDL_CreateTexture, (SDL_Renderer *, Uint32, int, int, int))           \
    X(void, SDL_DestroyTexture, (SDL_Texture *))                                           \
    X(int, SDL_UpdateTexture, (SDL_Texture *, const SDL_Rect *, const void *, int))        \
    X(int, SDL_SetRenderDrawColor, (SDL_Renderer *, Uint8, Uint8, Uint8, Uint8))           \
    X(int, SDL_RenderClear, (SDL_Renderer *))                                              \
    X(int, SDL_RenderCopy, (SDL_Renderer *, SDL_Texture *, const SDL_Rect *, const SDL_Rect *)) \
    X(void, SDL_RenderPresent, (SDL_Renderer *))                                           \
    X(int, SDL_PollEvent, (SDL_Event *))

typedef struct sdl_api {
#define X(ret, name, args) ret(*name) args;
    SDL_FUNCS(X)
#undef X
} sdl_api;

static sdl_api api;
static int api_loaded;

static io_result load_api(io_error *err)
{
    if (api_loaded) return IO_OK;
    const char *lib = getenv("EGOFUSE_SDL_LIB");
    if (!lib || !lib[0]) lib = SDL_LIB;
    void *h = dlopen(lib, RTLD_NOW | RTLD_LOCAL);
    if (!h)
        return io_fail(err, IO_ERR_NOT_FOUND, "sdl: cannot load %s (Debian: apt-get install libsdl2-2.0-0): %s",
                       lib, dlerror());
    sdl_api a;
#define X(ret, name, args)                                                                      \
    *(void **)&a.name = dlsym(h, #name);                                                        \
    if (!a.name) {                                                                              \
        dlclose(h);                                                                             \
        return io_fail(err, IO_ERR_FORMAT, "sdl: %s has no %s (SDL 2.0.5 or newer needed)", lib, #name); \
    }
    SDL_FUNCS(X)
#undef X
    api = a;
    api_loaded = 1;
    return IO_OK;
}

typedef struct sdl {
    SDL_Window *win;
    SDL_Renderer *ren;
    SDL_Texture *tex;
    int inited;
    uint32_t seq;
} sdl;

static void handle(io_display *d, const SDL_Event *e)
{
    if (e->type == SDL_QUIT) d->quit = 1;
    if (e->type == SDL_WINDOWEVENT && e->window.event == SDL_WINDOWEVENT_CLOSE) d->quit = 1;
    if (e->type == SDL_KEYDOWN && (e->key.keysym.sym == SDLK_ESCAPE || e->key.keysym.sym == SDLK_q))
        d->quit = 1;
}

static void pump(io_display *d)
{
    SDL_Event e;
    while (api.SDL_PollEvent(&e)) handle(d, &e);
}

static io_result sdl_present(io_display *d, const uint8_t *const rgba[2], const size_t stride[2],
                             uint64_t frame_id, io_error *err)
{
    sdl *s = d->be;
    for (int i = 0; i < 2; i++) {
        SDL_Rect r = {i * d->eye_w, 0, d->eye_w, d->eye_h};
        if (api.SDL_UpdateTexture(s->tex, &r, rgba[i], (int)stride[i]) != 0)
            return io_fail(err, IO_ERR_DEVICE, "sdl: SDL_UpdateTexture: %s", api.SDL_GetError());
    }
    api.SDL_SetRenderDrawColor(s->ren, 0, 0, 0, 255);
    api.SDL_RenderClear(s->ren);
    if (api.SDL_RenderCopy(s->ren, s->tex, NULL, NULL) != 0)
        return io_fail(err, IO_ERR_DEVICE, "sdl: SDL_RenderCopy: %s", api.SDL_GetError());
    api.SDL_RenderPresent(s->ren);
    /* no vblank time stamp: the flip is "now", when the present returned */
    io_display_push_flip(d, frame_id, io_display_now_ns(), ++s->seq);
    pump(d);
    return IO_OK;
}

/* Flips are queued by the present itself: nothing is ever pending, so
 * this only handles the window's events (no wait, as KMS with no flip
 * pending). */
static io_result sdl_wait(io_display *d, int timeout_ms, io_error *err)
{
    (void)err;
    (void)timeout_ms;
    pump(d);
    return IO_OK;
}

static int sdl_fd(const io_display *d) { (void)d; return -1; }
static int sdl_busy(const io_display *d) { (void)d; return 0; }

static void sdl_release(void *be)
{
    sdl *s = be;
    if (s->tex) api.SDL_DestroyTexture(s->tex);
    if (s->ren) api.SDL_DestroyRenderer(s->ren);
    if (s->win) api.SDL_DestroyWindow(s->win);
    if (s->inited) api.SDL_QuitSubSystem(SDL_INIT_VIDEO);
    s->tex = NULL;
    s->ren = NULL;
    s->win = NULL;
    s->inited = 0;
}

static const io_display_ops sdl_ops = {sdl_present, sdl_wait, sdl_fd, sdl_busy, sdl_release};

io_result io_display_sdl_open(io_display *d, const io_display_spec *sp, io_error *err)
{
    io_result r = load_api(err);
    if (r != IO_OK) return r;
    sdl *s = calloc(1, sizeof *s);
    if (!s) return io_fail(err, IO_ERR_NOMEM, "sdl: out of memory");
    int tw = 2 * d->eye_w, th = d->eye_h;
    int ww = sp->win_w ? sp->win_w : tw, wh = sp->win_h ? sp->win_h : th;
    /* egofuse handles SIGINT itself; scaling is nearest (exact at 1:1) */
    api.SDL_SetHint(SDL_HINT_NO_SIGNAL_HANDLERS, "1");
    api.SDL_SetHint(SDL_HINT_RENDER_SCALE_QUALITY, "0");
    if (api.SDL_InitSubSystem(SDL_INIT_VIDEO) != 0) {
        r = io_fail(err, IO_ERR_DEVICE, "sdl: cannot start SDL video: %s (no DISPLAY or WAYLAND_DISPLAY?)",
                    api.SDL_GetError());
        goto fail;
    }
    s->inited = 1;
    s->win = api.SDL_CreateWindow("egofuse", SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED, ww, wh,
                                  SDL_WINDOW_SHOWN | SDL_WINDOW_RESIZABLE);
    if (!s->win) {
        r = io_fail(err, IO_ERR_DEVICE, "sdl: cannot open a %dx%d window: %s", ww, wh, api.SDL_GetError());
        goto fail;
    }
    s->ren = api.SDL_CreateRenderer(s->win, -1, 0);
    if (!s->ren) s->ren = api.SDL_CreateRenderer(s->win, -1, SDL_RENDERER_SOFTWARE);
    if (!s->ren) {
        r = io_fail(err, IO_ERR_DEVICE, "sdl: no renderer for the window: %s", api.SDL_GetError());
        goto fail;
    }
    s->tex = api.SDL_CreateTexture(s->ren, SDL_PIXELFORMAT_RGBA32, SDL_TEXTUREACCESS_STREAMING, tw, th);
    if (!s->tex) {
        r = io_fail(err, IO_ERR_DEVICE, "sdl: cannot create a %dx%d texture: %s", tw, th, api.SDL_GetError());
        goto fail;
    }
    SDL_RendererInfo info;
    memset(&info, 0, sizeof info);
    api.SDL_GetRendererInfo(s->ren, &info);
    d->be = s;
    d->ops = &sdl_ops;
    d->out_w = tw;
    d->out_h = th;
    d->refresh_ns = 0;
    snprintf(d->desc, sizeof d->desc, "sdl %dx%d window (%s renderer, eyes %dx%d side by side)", ww, wh,
             info.name ? info.name : "?", d->eye_w, d->eye_h);
    pump(d);
    return IO_OK;
fail:
    sdl_release(s);
    free(s);
    return r;
}
#endif /* EGOFUSE_NO_SDL2 */
