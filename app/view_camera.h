/* view_camera.h - the viewer's camera: fly and orbit moves on a
 * location / look_at / sky camera, conversion to the scene IR's camera
 * (the vectors POV-Ray's `look_at` computes: parser/sdl_scene.c), and the
 * camera written back out as a POV-Ray camera{} block.
 *
 * Conventions: angles are degrees. "Screen right" is the direction that runs
 * left to right across the image, i.e. the camera's signed `right` vector, so
 * a mirrored camera (cbox's `right <-1,0,0>`) moves the way it looks.
 *   orbit(yaw, pitch)  turns the location around look_at: +yaw moves the
 *                      camera towards screen right, +pitch raises it (along
 *                      sky); the elevation stays within +-89 degrees.
 *   look(yaw, pitch)   turns the view in place: +yaw looks towards screen
 *                      right, +pitch looks up; look_at keeps its distance.
 *   move(f, r, u)      flies: forward along the view, screen right, up along
 *                      sky; look_at moves along.
 *   zoom(k)            distance to look_at times k (orthographic: the view
 *                      size times k). */
#ifndef PT_VIEW_CAMERA_H
#define PT_VIEW_CAMERA_H
#include <stddef.h>
#include "scene.h"

typedef struct {
    camera_kind kind;      /* perspective or orthographic; other kinds pass through unmoved */
    vec3 location, look_at;
    vec3 sky;              /* unit */
    double angle;          /* horizontal field of view, degrees (perspective) */
    double right_len, up_len;
    int mirrored;          /* right = -(sky x direction) */
    int moved;             /* 0: view_camera_to_scene gives the scene's camera unchanged */
    scene_camera base;     /* the scene's camera: aperture, focal point, ... kept as given */
} view_camera;

/* From the scene's camera. `fallback_distance` (> 0) places look_at when the
 * scene's look_at does not lie along the view direction (camera given by
 * direction vectors or transformed after look_at). */
void view_camera_from_scene(view_camera *vc, const scene_camera *c, double fallback_distance);
/* The scene IR camera these settings describe (POV-Ray's look_at rules). */
void view_camera_to_scene(const view_camera *vc, scene_camera *out);

void view_camera_orbit(view_camera *vc, double yaw, double pitch);
void view_camera_look(view_camera *vc, double yaw, double pitch);
void view_camera_move(view_camera *vc, double forward, double right, double up);
void view_camera_zoom(view_camera *vc, double k);
/* Unit vectors of the current view: forward, screen right (signed), up. */
void view_camera_frame(const view_camera *vc, vec3 *forward, vec3 *right, vec3 *up);

/* The camera{} block (POV-Ray 3.7 SDL) into buf; returns the length it
 * needs (as snprintf). Parsing it back gives the same scene camera. */
int view_camera_format(const view_camera *vc, char *buf, size_t n);

#endif
