/* camera.h - primary rays of every POV-Ray 3.7 camera type: perspective,
 * orthographic, fisheye, ultra_wide_angle, omnimax, panoramic, cylinder 1-4,
 * spherical, mesh_camera, with focal blur (aperture, focal distance). */
#ifndef PT_CAMERA_H
#define PT_CAMERA_H
#include "scene.h"

/* Ray through pixel position (px, py) in [0,w)x[0,h) (pixel centres at .5).
 * (lu, lv) in [-0.5, 0.5]^2 picks a point of the lens for focal blur (the
 * offset is aperture/2 * (lu, lv) across the film plane; ignored without
 * aperture). Returns 0 where POV-Ray traces no ray (outside a fisheye's or
 * omnimax's circle): the pixel is then black. Direction is normalised. */
int camera_ray(const scene_camera *c, double px, double py, int w, int h, double lu, double lv, vec3 *org, vec3 *dir);

/* mesh_camera (POV-Ray 3.7): ray `ray` (0 .. rays_per_pixel-1) of pixel
 * (px, py). Distribution 0: pixel i (row by row from the top left) shoots
 * from face i of mesh `ray`; 1: from face i + ray*(all faces) of the meshes
 * taken in order; 2: the meshes side by side, each over w/nmeshes columns;
 * 3: from the point of the first mesh whose uv coordinates are the pixel's
 * (uv per vertex; smooth interpolates the vertex normals). The origin is
 * moved by location.z along the face normal; direction.z < 0 reverses the
 * ray. Returns 0 where no ray is shot. camera_ray uses ray 0. */
int camera_mesh_ray(const scene_camera *c, double px, double py, int w, int h, int ray, vec3 *org, vec3 *dir);

/* Does the camera blur (aperture > 0 and blur_samples > 0)? */
int camera_focal_blur(const scene_camera *c);

#endif
