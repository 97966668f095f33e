/* camera.c - POV-Ray 3.7 camera projections (see camera.h).
 *
 * As POV-Ray 3.7's TracePixel::CreateCameraRay defines them (studied, not
 * copied), with screen coordinates x0 in [-0.5, 0.5] left to right and y0
 * in [-0.5, 0.5] bottom to top:
 *  - perspective: d = direction + x0 right + y0 up; orthographic: origin
 *    moves by x0 right + y0 up, d = direction.
 *  - fisheye (vectors normalised): (X, Y) = (2 x0 |right|, 2 y0 |up|),
 *    r = |(X, Y)| (no ray beyond 1), phi = atan-like angle of (X, Y),
 *    theta = r * angle/2; d = cos(phi) sin(theta) right + sin(phi) sin(theta) up
 *    + cos(theta) direction.
 *  - omnimax: the same with theta = 1.411269 r - 0.09439 r^3 + 0.25674 r^5,
 *    its aspect correction, no rays below 45 degrees under the axis.
 *  - panoramic: phi = (1 - (x0 + 0.5)) pi, theta = y0 pi;
 *    d = cos(phi) right + tan(theta) up + sin(phi) direction.
 *  - ultra_wide_angle: a = x0 angle, b = y0 angle |up|/|right| (radians);
 *    d = sin(a) right + sin(b) up + cos(a) cos(b) direction.
 *  - cylinder 1 (vertical axis, pinhole), 2 (horizontal axis), 3 and 4 (the
 *    same with an orthographic second axis).
 *  - spherical: direction turned by -y0 * v_angle about right, then by
 *    x0 * h_angle about up.
 *  - focal blur: origin moved by the lens offset across the film plane
 *    (axes up x direction and direction x that), direction scaled to the
 *    focal distance / |direction| and corrected by the same offset, as
 *    POV-Ray's JitterCameraRay. Angles default to 90 degrees (spherical 360
 *    by angle/2).
 *  - mesh_camera: one ray per mesh face, from its centroid along its
 *    normal (distributions 0, 1, 2) or from the point of the face whose uv
 *    is the pixel's (3), as TracePixel::CreateCameraRay's MESH_CAMERA case. */
#include "camera.h"
#include <math.h>

#define CAM_PI 3.1415926535897932384626
#define CAM_EPSILON 1.0e-10

int camera_focal_blur(const scene_camera *c) { return c->aperture > 0.0 && c->blur_samples > 0; }

/* Rodrigues rotation of v about axis k by angle a, the sense of POV-Ray's
 * Compute_Axis_Rotation_Transform. */
static vec3 rotate_axis(vec3 v, vec3 k, double a)
{
    k = v3_norm(k);
    double c = cos(a), s = sin(a);
    /* v' = c v + (1-c)(k.v) k + s k x v (checked against POV-Ray renders) */
    vec3 kxv = v3_cross(k, v);
    return v3_add(v3_add(v3_scale(v, c), v3_scale(k, (1.0 - c) * v3_dot(k, v))), v3_scale(kxv, s));
}

/* ------------------------------------------------------------ mesh_camera */

static vec3 fv3(const float *f) { return v3(f[0], f[1], f[2]); }

/* Origin and direction from face `face` of mesh object m: the centroid and
 * POV-Ray's face normal normalize((P3-P1) x (P2-P1)) (Compute_Mesh_Triangle),
 * or, for distribution 3, the point with barycentrics b and (smooth) the
 * interpolated vertex normal. Returns 0 for a degenerate face. */
static int mesh_face_ray(const scene_camera *c, const scene_object *m, int face, const double *b, vec3 *org, vec3 *dir)
{
    const scene_mesh *ms = m->u.mesh.mesh;
    const int *t = ms->tris[face];
    vec3 p1 = fv3(ms->verts[t[0]]), p2 = fv3(ms->verts[t[1]]), p3 = fv3(ms->verts[t[2]]);
    vec3 n = v3_cross(v3_sub(p3, p1), v3_sub(p2, p1));
    double ln = v3_len(n);
    if (!(ln > 0.0)) return 0;
    n = v3_scale(n, 1.0 / ln);
    vec3 o;
    if (b) {
        o = v3_add(v3_add(v3_scale(p1, b[0]), v3_scale(p2, b[1])), v3_scale(p3, b[2]));
        if (c->mesh_smooth && ms->normals && ms->tri_normals) {
            const int *tn = ms->tri_normals[face];
            vec3 s = v3_add(v3_add(v3_scale(fv3(ms->normals[tn[0]]), b[0]), v3_scale(fv3(ms->normals[tn[1]]), b[1])),
                            v3_scale(fv3(ms->normals[tn[2]]), b[2]));
            if (v3_len(s) > 0.0) n = v3_norm(s);
        }
    } else {
        o = v3_scale(v3_add(v3_add(p1, p2), p3), 1.0 / 3.0);
    }
    /* location.z moves the origin along the normal; direction.z < 0 turns
     * the ray round (POV-Ray 3.7's conventions for the mesh camera) */
    o = v3_madd(o, n, c->location.z);
    if (c->direction.z < -CAM_EPSILON) n = v3_neg(n);
    *org = xform_point(&m->transform, o);
    *dir = v3_norm(xform_normal(&m->transform, n));
    return v3_finite(*org) && v3_finite(*dir);
}

int camera_mesh_ray(const scene_camera *c, double px, double py, int w, int h, int ray, vec3 *org, vec3 *dir)
{
    if (c->nmeshes <= 0 || w <= 0 || h <= 0) return 0;
    /* POV-Ray's coordinates: CreateCameraRay gets the pixel's column and row
     * and moves them by +0.5 and -0.5 (for a pixel centre px = col + 0.5,
     * py = row + 0.5 here: x = px, y = py - 1), then clamps them into the
     * image and truncates them to indices; so rows 0 and 1 both use the
     * first row of faces and row r > 0 uses row r - 1, as POV-Ray 3.7 does. */
    double x0 = px, y0 = py - 1.0;
    double x = fmax(0.0, fmin(x0, w - 1.0)), y = fmax(0.0, fmin(y0, h - 1.0));
    unsigned ix = (unsigned)x, iy = (unsigned)y;
    switch (c->mesh_distribution) {
    case 0: { /* pixel i -> face i; ray r of a pixel uses mesh r */
        if (ray < 0 || ray >= c->nmeshes) return 0;
        const scene_object *m = c->meshes[ray];
        unsigned long face = (unsigned long)iy * (unsigned)w + ix;
        if (!m->u.mesh.mesh || face >= (unsigned long)m->u.mesh.mesh->ntris) return 0;
        return mesh_face_ray(c, m, (int)face, NULL, org, dir);
    }
    case 1: { /* the meshes' faces summed; ray r adds r * (all faces) */
        unsigned long total = 0;
        for (int i = 0; i < c->nmeshes; i++) total += c->meshes[i]->u.mesh.mesh ? (unsigned long)c->meshes[i]->u.mesh.mesh->ntris : 0;
        unsigned long face = (unsigned long)iy * (unsigned)w + ix + (unsigned long)(ray < 0 ? 0 : ray) * total;
        for (int i = 0; i < c->nmeshes; i++) {
            const scene_mesh *ms = c->meshes[i]->u.mesh.mesh;
            unsigned long n = ms ? (unsigned long)ms->ntris : 0;
            if (face < n) return mesh_face_ray(c, c->meshes[i], (int)face, NULL, org, dir);
            face -= n;
        }
        return 0;
    }
    case 2: { /* one camera per mesh, side by side */
        unsigned per = (unsigned)w / (unsigned)c->nmeshes;
        if (per == 0) return 0;
        unsigned mi = ix / per;
        if (mi >= (unsigned)c->nmeshes) return 0;
        const scene_object *m = c->meshes[mi];
        /* POV-Ray 3.7 indexes with the full x here (not x - mi * per) */
        unsigned long face = (unsigned long)iy * per + ix;
        if (!m->u.mesh.mesh || face >= (unsigned long)m->u.mesh.mesh->ntris) return 0;
        return mesh_face_ray(c, m, (int)face, NULL, org, dir);
    }
    default: { /* 3: the pixel's (u, v) located in the first mesh's uv map */
        const scene_object *m = c->meshes[0];
        const scene_mesh *ms = m->u.mesh.mesh;
        if (!ms || !ms->uvs || ms->nuvs != ms->nverts) return 0;
        double u = (x - 0.5) / w, v = 1.0 - (y + 0.5) / h;
        for (int f = 0; f < ms->ntris; f++) {
            const int *t = ms->tris[f];
            double u1 = ms->uvs[t[0]][0], v1 = ms->uvs[t[0]][1], u2 = ms->uvs[t[1]][0], v2 = ms->uvs[t[1]][1];
            double u3 = ms->uvs[t[2]][0], v3_ = ms->uvs[t[2]][1];
            double sc = (u2 - u1) * (v3_ - v1) - (u3 - u1) * (v2 - v1);
            if (sc == 0.0) continue;
            double b[3] = {((u2 - u) * (v3_ - v) - (u3 - u) * (v2 - v)) / sc, ((u3 - u) * (v1 - v) - (u1 - u) * (v3_ - v)) / sc,
                           ((u1 - u) * (v2 - v) - (u2 - u) * (v1 - v)) / sc};
            if (b[0] < 0 || b[1] < 0 || b[2] < 0) continue;
            return mesh_face_ray(c, m, f, b, org, dir);
        }
        return 0;
    }
    }
}

int camera_ray(const scene_camera *c, double px, double py, int w, int h, double lu, double lv, vec3 *org, vec3 *dir)
{
    if (c->kind == CAMERA_MESH) return camera_mesh_ray(c, px, py, w, h, 0, org, dir);
    double x0 = px / w - 0.5, y0 = 0.5 - py / h;
    vec3 D = c->direction, R = c->right, U = c->up;
    double lr = v3_len(R), lup = v3_len(U);
    double angle = c->angle > 0.0 ? c->angle : 90.0;
    int normalise = 0;
    double aspect = lup > 0.0 ? lr / lup : 4.0 / 3.0;
    switch (c->kind) {
    case CAMERA_CYLINDER:
        aspect = (c->cylinder_type == 1 || c->cylinder_type == 3) ? lup : lr;
        normalise = 1;
        break;
    case CAMERA_ULTRA_WIDE_ANGLE: aspect = lr > 0.0 ? lup / lr : 1.0; normalise = 1; break;
    case CAMERA_OMNIMAX: case CAMERA_FISHEYE: normalise = 1; break;
    default: break;
    }
    if (normalise) {
        R = v3_norm(R);
        U = v3_norm(U);
        D = v3_norm(D);
    }
    vec3 o = c->location, d = D;
    double cx, sx, cy, sy;
    switch (c->kind) {
    case CAMERA_ORTHOGRAPHIC:
        o = v3_add(o, v3_add(v3_scale(R, x0), v3_scale(U, y0)));
        d = D;
        break;
    case CAMERA_FISHEYE: case CAMERA_OMNIMAX: {
        double X = 2.0 * x0, Y = 2.0 * y0;
        if (c->kind == CAMERA_FISHEYE) {
            X *= lr;
            Y *= lup;
        } else if (aspect > 1.0) {
            if (aspect > 1.283458) {
                X *= aspect / 1.283458;
                Y = (Y - 1.0) / 1.283458 + 1.0;
            } else {
                Y = (Y - 1.0) / aspect + 1.0;
            }
        } else {
            Y /= aspect;
        }
        double rad = sqrt(X * X + Y * Y);
        if (rad > 1.0) return 0;
        double phi = rad == 0.0 ? 0.0 : (X < 0.0 ? CAM_PI - asin(Y / rad) : asin(Y / rad));
        double theta = c->kind == CAMERA_FISHEYE ? rad * angle * (CAM_PI / 360.0)
                                                 : 1.411269 * rad - 0.09439 * rad * rad * rad + 0.25674 * pow(rad, 5);
        cx = cos(phi); sx = sin(phi);
        cy = cos(theta); sy = sin(theta);
        if (c->kind == CAMERA_OMNIMAX && sx * sy < tan(135.0 * CAM_PI / 180.0) * cy) return 0;
        d = v3_add(v3_add(v3_scale(R, cx * sy), v3_scale(U, sx * sy)), v3_scale(D, cy));
        break;
    }
    case CAMERA_PANORAMIC: {
        double a = (1.0 - (x0 + 0.5)) * CAM_PI, b = (CAM_PI / 2.0) * (2.0 * y0);
        double ty;
        if (fabs(CAM_PI / 2.0 - fabs(b)) < CAM_EPSILON) ty = b > 0.0 ? 1e10 : -1e10;
        else ty = tan(b);
        d = v3_add(v3_add(v3_scale(R, cos(a)), v3_scale(U, ty)), v3_scale(D, sin(a)));
        break;
    }
    case CAMERA_ULTRA_WIDE_ANGLE: {
        double a = x0 * angle * (CAM_PI / 180.0), b = y0 * angle * aspect * (CAM_PI / 180.0);
        cx = cos(a); sx = sin(a);
        cy = cos(b); sy = sin(b);
        d = v3_add(v3_add(v3_scale(R, sx), v3_scale(U, sy)), v3_scale(D, cx * cy));
        break;
    }
    case CAMERA_CYLINDER:
        switch (c->cylinder_type) {
        case 1: case 3: {
            double a = x0 * angle * (CAM_PI / 180.0), y = y0 * aspect;
            if (c->cylinder_type == 1) {
                d = v3_add(v3_add(v3_scale(R, sin(a)), v3_scale(U, y)), v3_scale(D, cos(a)));
            } else {
                d = v3_add(v3_scale(R, sin(a)), v3_scale(D, cos(a)));
                o = v3_add(o, v3_scale(U, y));
            }
            break;
        }
        default: {
            double b = y0 * angle * (CAM_PI / 180.0), x = x0 * aspect;
            if (c->cylinder_type == 2) {
                d = v3_add(v3_add(v3_scale(R, x), v3_scale(U, sin(b))), v3_scale(D, cos(b)));
            } else {
                d = v3_add(v3_scale(U, sin(b)), v3_scale(D, cos(b)));
                o = v3_add(o, v3_scale(R, x));
            }
            break;
        }
        }
        break;
    case CAMERA_SPHERICAL: {
        double ha = c->angle > 0.0 ? c->angle : 360.0;
        double va = c->v_angle > 0.0 ? c->v_angle : ha * 0.5;
        double b = y0 * (va / 360.0) * 2.0 * CAM_PI, a = x0 * (ha / 360.0) * 2.0 * CAM_PI;
        vec3 v1 = rotate_axis(D, R, -b);
        d = rotate_axis(v1, U, a);
        break;
    }
    default: /* perspective */
        d = v3_add(D, v3_add(v3_scale(R, x0), v3_scale(U, y0)));
        break;
    }
    if (camera_focal_blur(c)) {
        /* POV-Ray's JitterCameraRay: the eye moves across the film plane. */
        double r = c->aperture * 0.5;
        vec3 xp = v3_norm(v3_cross(c->up, c->direction));
        vec3 yp = v3_norm(v3_cross(c->direction, xp));
        vec3 defl = v3_sub(v3_scale(xp, r * lu), v3_scale(yp, r * lv));
        double fd = c->focal_distance > 0.0 ? c->focal_distance : v3_len(c->direction);
        double dl = v3_len(c->direction);
        o = v3_add(c->location, defl);
        d = v3_sub(v3_scale(d, dl > 0.0 ? fd / dl : fd), defl);
    }
    *org = o;
    *dir = v3_norm(d);
    return 1;
}
