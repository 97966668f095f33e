/* view.h - `partray view`: the interactive viewer.
 *
 *   partray view SCENE.pov [--size WxH] [--gi MODE] [--threads N] [--seed N]
 *                [--script FILE] [--preview D] [--verbose] [-D NAME=VALUE] [-L DIR]
 *
 * An SDL2 window shows the scene while the render thread (view_render.h)
 * refines it; the UI thread only handles input, swaps in finished images and
 * writes files. Keys and mouse:
 *   W A S D, Q E        fly forward/left/back/right, down/up (Shift faster, Ctrl slower)
 *   right drag          look around          left drag   orbit around look_at
 *   wheel               zoom towards look_at R           back to the scene's camera
 *   1..9, Tab           select a light       arrows      move it (screen-horizontal)
 *   PgUp, PgDn          move it up/down      + -         brighten/dim it
 *   G                   cycle GI: none -> particle -> path (reference preview)
 *   F12, P              screenshot (SCENE-NNNN.exr + .png)
 *   C                   print the camera{} block, write SCENE-camera-NNNN.inc
 *   H                   print this help      Esc         quit
 * The title bar shows the GI mode, the refinement level, the frame time and
 * its stages (GI build, lighting, per-view, render), images per second and
 * the selected light. --script (view_script.h) injects the same actions on
 * a timeline; --preview D fixes the preview's divisor (default: adaptive);
 * --verbose prints a line per image shown (level, size, stage times, latency).
 * On exit the viewer prints figures (images/s, latencies) to stderr.
 * Exit status: 0 ok, 1 scene or script error, 2 usage, 3 I/O or no display. */
#ifndef PT_VIEW_H
#define PT_VIEW_H

/* argv: the arguments after `view`. Returns the exit status. */
int cmd_view(int argc, char **argv);

#endif
