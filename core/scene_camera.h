/* scene_camera.h - the scene IR's camera (scene.h). */
#ifndef PT_SCENE_CAMERA_H
#define PT_SCENE_CAMERA_H
#include "diag.h"
#include "vec.h"

/* ---------------------------------------------------------------- camera */
typedef enum {
    CAMERA_PERSPECTIVE, CAMERA_ORTHOGRAPHIC, CAMERA_FISHEYE, CAMERA_ULTRA_WIDE_ANGLE,
    CAMERA_OMNIMAX, CAMERA_PANORAMIC, CAMERA_CYLINDER, CAMERA_SPHERICAL,
    CAMERA_MESH /* mesh_camera, parsed into the fields below */
} camera_kind;

typedef struct {
    camera_kind kind;
    int cylinder_type;
    src_loc loc;
    /* Final vectors after look_at, angle, sky and transforms, as POV-Ray
     * computes them while parsing: a primary ray through normalised screen
     * coordinates (sx, sy) in [-0.5, 0.5] is direction + sx*right + sy*up. */
    vec3 location, direction, up, right, sky, look_at;
    double angle;           /* horizontal field of view in degrees, 0 = unset */
    double aperture;        /* focal blur, 0 = off */
    int blur_samples;       /* at most this many rays per sample */
    /* POV-Ray's stopping rule for focal blur (blur_samples MIN, MAX;
     * confidence; variance): after at least blur_samples_min rays, a
     * sample stops once the variance of its mean is under a threshold
     * (shade_focal.h). Defaults 0, 0.9, 1/10000 (POV-Ray 3.7's camera.cpp). */
    int blur_samples_min;
    double confidence, variance;
    vec3 focal_point;
    double v_angle;         /* spherical camera: vertical field of view in degrees, 0 = angle/2 */
    double focal_distance;  /* focal blur: distance to the focal plane; 0 = |direction| */
    const struct scene_normal *normal; /* camera { normal {..} }: perturbs primary rays, NULL = none */
    /* mesh_camera { rays_per_pixel, distribution [, max_distance]
     * mesh { } ... [smooth] } (POV-Ray 3.7); meshes are SHAPE_MESH objects with
     * their transforms. location/direction then hold the mesh camera's offsets. */
    int mesh_rays_per_pixel;
    int mesh_distribution;  /* 0..3 */
    double mesh_max_distance; /* 0 = none */
    int mesh_smooth;
    int nmeshes;
    const struct scene_object *const *meshes;
} scene_camera;

#endif
