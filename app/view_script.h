/* view_script.h - timed input for `partray view --script FILE`, and the
 * actions that both a script and the keyboard/mouse produce (the viewer
 * applies them through one function, so a script drives exactly the code
 * paths a user does).
 *
 * Script grammar: one event per line,
 *
 *     TIME COMMAND [ARGUMENTS]        # comment
 *
 * The commands name what the viewer does; key, drag and wheel instead feed
 * raw input through the window's event queue.
 *
 * TIME is in seconds (a decimal number >= 0), counted from the moment the
 * first image is on screen; events run in time order (ties in file order).
 * Blank lines and everything after '#' are ignored. Commands:
 *
 *   screenshot [PATH]          save the image on screen: PATH ending in .exr
 *                              or .png writes that file; any other PATH
 *                              writes PATH.exr and PATH.png; no PATH: the
 *                              next free SCENE-NNNN.exr/.png (as F12)
 *   window PATH                save the window as shown (the image scaled
 *                              to the window, the overlay over it) as an
 *                              8-bit PNG, after the next redraw
 *   light N select             make light N (1-based, scene order) the
 *                              selected light (as the number keys)
 *   light N move DX DY DZ      move light N by a world-space offset (spot
 *                              and cylinder lights carry their point_at)
 *   light N scale F            multiply light N's colour by F (F >= 0)
 *   camera orbit YAW PITCH     orbit around look_at, degrees (+YAW towards
 *                              screen right, +PITCH up; as a left drag)
 *   camera look YAW PITCH      turn in place, degrees (as a right drag)
 *   camera move F R U          fly: forward, screen right, up (world units)
 *   camera zoom K              distance to look_at times K (as the wheel)
 *   camera write [PATH]        print the camera{} block and write it to
 *                              PATH (default: the next free SCENE-camera-NNNN.inc)
 *   gi MODE                    switch to none | particle | path | pmfg | next
 *   clock V                    evaluate the scene again at clock V (as the
 *                              [ and ] keys step it): the scene is parsed
 *                              and, in --gi links, linked again where it
 *                              deformed, off the UI and render threads;
 *                              the image shows the old clock until then
 *   key NAME [HOLD]            press the key NAME (SDL key names: w, Left,
 *                              Page Up, F12, Tab, 1, ...; a name with a space
 *                              is written with '_': Page_Up) and release it
 *                              HOLD seconds later (default 0: a tap); goes
 *                              through the window's event queue as a real
 *                              key press does, so held keys fly and move
 *                              lights at their real speed
 *   drag left|right DX DY      a mouse motion of DX, DY pixels with that
 *                              button down (left orbits, right looks)
 *   wheel N                    N wheel clicks (positive: towards the screen)
 *   wait-idle                  hold the later events until the image is
 *                              refined to its last level; the clock then
 *                              resumes at this event's TIME, so the next
 *                              event's TIME difference runs from there
 *   mark NAME                  print "view: mark NAME ..." with frame counts
 *                              and times so far (for benchmarks)
 *   quit                       close the viewer (exit status 0)
 *
 * Example:
 *     0.0 wait-idle
 *     0.1 screenshot a.exr
 *     0.2 light 1 move 2 0 0
 *     0.3 wait-idle
 *     0.4 screenshot b.exr
 *     0.5 quit
 */
#ifndef PT_VIEW_SCRIPT_H
#define PT_VIEW_SCRIPT_H
#include "diag.h"

typedef enum {
    VIEW_ACT_NONE,
    VIEW_ACT_SCREENSHOT,   /* text: path or NULL */
    VIEW_ACT_LIGHT_SELECT, /* light: 1-based, 0 = the next one (Tab) */
    VIEW_ACT_LIGHT_MOVE,   /* light (0 = selected), v: world offset */
    VIEW_ACT_LIGHT_SCALE,  /* light (0 = selected), v[0]: factor */
    VIEW_ACT_CAMERA_ORBIT, /* v[0] yaw, v[1] pitch (degrees) */
    VIEW_ACT_CAMERA_LOOK,  /* v[0] yaw, v[1] pitch (degrees) */
    VIEW_ACT_CAMERA_MOVE,  /* v: forward, right, up */
    VIEW_ACT_CAMERA_ZOOM,  /* v[0]: factor */
    VIEW_ACT_CAMERA_WRITE, /* text: path or NULL */
    VIEW_ACT_GI,           /* mode: a gi_mode, or -1 = the next one (G) */
    VIEW_ACT_WAIT_IDLE,    /* scripts only; handled inside view_script_next */
    VIEW_ACT_MARK,         /* text: name */
    VIEW_ACT_QUIT,
    VIEW_ACT_KEY,          /* text: key name ('_' for spaces), v[0]: hold seconds */
    VIEW_ACT_DRAG,         /* mode: 1 left, 3 right button; v[0], v[1]: pixels */
    VIEW_ACT_WHEEL,        /* v[0]: clicks */
    VIEW_ACT_WINDOW_SHOT,  /* text: path (PNG) */
    VIEW_ACT_CLOCK         /* v[0]: the clock (mode 0) or a step added to it (mode 1) */
} view_action_kind;

typedef struct {
    view_action_kind kind;
    int light;
    int mode;
    double v[3];
    const char *text; /* owned by the script (or static) */
} view_action;

typedef struct view_script view_script;

/* Reads and checks the whole file; errors are "FILE:LINE:COL: error: ..."
 * in d (PT_ERR_SYNTAX; PT_ERR_IO when unreadable). */
pt_status view_script_load(const char *path, view_script **out, diag *d);
/* Same from text (`name` for messages). */
pt_status view_script_parse(const char *name, const char *text, view_script **out, diag *d);
void view_script_free(view_script *vs);

/* Starts the clock (call when the first image is on screen). */
void view_script_start(view_script *vs, double now);
/* The next due event at wall time `now`: returns 1 and fills *a, or 0 when
 * nothing is due yet (or a wait-idle holds: `idle` is the renderer's state). */
int view_script_next(view_script *vs, double now, int idle, view_action *a);
/* Event i's action (0 <= i < view_script_count), for checks before a run. */
const view_action *view_script_action(const view_script *vs, int i);
/* 1 when every event has run. */
int view_script_done(const view_script *vs);
int view_script_count(const view_script *vs);

#endif
