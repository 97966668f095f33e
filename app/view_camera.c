/* view_camera.c - fly/orbit camera moves and the camera{} block. */
#include "view_camera.h"
#include <math.h>
#include <stdio.h>
#include <string.h>

#define DEG (M_PI / 180.0)
#define MAX_ELEVATION 89.0

static double clampd(double v, double lo, double hi) { return v < lo ? lo : (v > hi ? hi : v); }

/* Rodrigues: v turned by `a` radians about unit axis k (right-hand rule in
 * the coordinates' own sense). */
static vec3 rotate(vec3 v, vec3 k, double a)
{
    double c = cos(a), s = sin(a);
    return v3_add(v3_add(v3_scale(v, c), v3_scale(v3_cross(k, v), s)), v3_scale(k, v3_dot(k, v) * (1.0 - c)));
}

/* Any unit vector perpendicular to unit n. */
static vec3 perpendicular(vec3 n)
{
    vec3 t, b;
    v3_basis(n, &t, &b);
    return t;
}

/* Unsigned right: sky x d, normalised (d not parallel to sky). */
static vec3 right_unsigned(const view_camera *vc, vec3 d)
{
    vec3 r = v3_cross(vc->sky, d);
    if (v3_len2(r) < 1e-20) r = v3_cross(perpendicular(vc->sky), d);
    return v3_norm(r);
}

static vec3 forward(const view_camera *vc)
{
    vec3 d = v3_sub(vc->look_at, vc->location);
    if (v3_len2(d) < 1e-30) return perpendicular(vc->sky);
    return v3_norm(d);
}

void view_camera_frame(const view_camera *vc, vec3 *fwd, vec3 *right, vec3 *up)
{
    vec3 d = forward(vc);
    vec3 r = right_unsigned(vc, d);
    if (fwd) *fwd = d;
    if (right) *right = vc->mirrored ? v3_neg(r) : r;
    if (up) *up = v3_norm(v3_cross(d, r));
}

void view_camera_from_scene(view_camera *vc, const scene_camera *c, double fallback_distance)
{
    memset(vc, 0, sizeof *vc);
    vc->base = *c;
    vc->kind = c->kind;
    vc->location = c->location;
    double dl = v3_len(c->direction);
    vec3 d = dl > 0 ? v3_scale(c->direction, 1.0 / dl) : v3(0, 0, 1);
    vc->right_len = v3_len(c->right);
    vc->up_len = v3_len(c->up);
    if (!(vc->right_len > 0)) vc->right_len = 4.0 / 3.0;
    if (!(vc->up_len > 0)) vc->up_len = 1.0;
    vc->mirrored = v3_dot(v3_cross(c->up, c->direction), c->right) < 0;
    if (dl > 0)
        vc->angle = 2.0 * atan(vc->right_len / (2.0 * dl)) / DEG;
    else
        vc->angle = c->angle > 0 ? c->angle : 67.380135;
    /* sky: the scene's, unless the camera is rolled away from it (a
     * transform after look_at); then the camera's own up. */
    vec3 sky = v3_len2(c->sky) > 0 ? v3_norm(c->sky) : v3(0, 1, 0);
    vec3 up = v3_len2(c->up) > 0 ? v3_norm(c->up) : sky;
    vec3 sky_perp = v3_sub(sky, v3_scale(d, v3_dot(sky, d)));
    vec3 up_perp = v3_norm(v3_sub(up, v3_scale(d, v3_dot(up, d))));
    if (v3_len2(sky_perp) < 1e-12 || v3_dot(v3_norm(sky_perp), up_perp) < cos(1.0 * DEG)) sky = up_perp;
    vc->sky = sky;
    vec3 l = v3_sub(c->look_at, c->location);
    double ll = v3_len(l);
    if (ll > 1e-9 && v3_dot(v3_scale(l, 1.0 / ll), d) > cos(0.5 * DEG))
        vc->look_at = c->look_at;
    else
        vc->look_at = v3_madd(c->location, d, fallback_distance > 0 ? fallback_distance : 1.0);
}

void view_camera_to_scene(const view_camera *vc, scene_camera *out)
{
    *out = vc->base;
    if (!vc->moved || (vc->kind != CAMERA_PERSPECTIVE && vc->kind != CAMERA_ORTHOGRAPHIC)) return;
    vec3 d = forward(vc);
    vec3 r = right_unsigned(vc, d);
    vec3 u = v3_norm(v3_cross(d, r));
    double dl;
    if (vc->kind == CAMERA_PERSPECTIVE)
        dl = 0.5 * vc->right_len / tan(0.5 * clampd(vc->angle, 1e-3, 179.0) * DEG);
    else
        dl = v3_len(vc->base.direction) > 0 ? v3_len(vc->base.direction) : 1.0;
    out->location = vc->location;
    out->look_at = vc->look_at;
    out->sky = vc->sky;
    out->direction = v3_scale(d, dl);
    out->right = v3_scale(r, vc->mirrored ? -vc->right_len : vc->right_len);
    out->up = v3_scale(u, vc->up_len);
    if (vc->kind == CAMERA_PERSPECTIVE) out->angle = vc->angle;
}

/* Elevation of unit v above the plane perpendicular to sky, degrees. */
static double elevation(const view_camera *vc, vec3 v) { return asin(clampd(v3_dot(v, vc->sky), -1.0, 1.0)) / DEG; }

/* Unit v with its elevation replaced by e degrees, azimuth kept. */
static vec3 with_elevation(const view_camera *vc, vec3 v, double e)
{
    vec3 h = v3_sub(v, v3_scale(vc->sky, v3_dot(v, vc->sky)));
    if (v3_len2(h) < 1e-24) h = perpendicular(vc->sky);
    h = v3_norm(h);
    return v3_add(v3_scale(h, cos(e * DEG)), v3_scale(vc->sky, sin(e * DEG)));
}

void view_camera_orbit(view_camera *vc, double yaw, double pitch)
{
    vec3 v = v3_sub(vc->location, vc->look_at);
    double r = v3_len(v);
    if (!(r > 0)) return;
    v = v3_scale(v, 1.0 / r);
    /* sky x v = -(sky x d): turning v by +a about sky moves the camera
     * towards -(unsigned right). */
    double a = (vc->mirrored ? yaw : -yaw) * DEG;
    vec3 w = rotate(v, vc->sky, a);
    double e = clampd(elevation(vc, v) + pitch, -MAX_ELEVATION, MAX_ELEVATION);
    w = with_elevation(vc, w, e);
    vc->location = v3_madd(vc->look_at, w, r);
    vc->moved = 1;
}

void view_camera_look(view_camera *vc, double yaw, double pitch)
{
    vec3 l = v3_sub(vc->look_at, vc->location);
    double dist = v3_len(l);
    if (!(dist > 0)) return;
    vec3 d = v3_scale(l, 1.0 / dist);
    /* sky x d = unsigned right: turning d by +a looks towards it. */
    double a = (vc->mirrored ? -yaw : yaw) * DEG;
    vec3 w = rotate(d, vc->sky, a);
    double e = clampd(elevation(vc, d) + pitch, -MAX_ELEVATION, MAX_ELEVATION);
    w = with_elevation(vc, w, e);
    vc->look_at = v3_madd(vc->location, w, dist);
    vc->moved = 1;
}

void view_camera_move(view_camera *vc, double fwd, double right, double up)
{
    vec3 d, r;
    view_camera_frame(vc, &d, &r, NULL);
    vec3 delta = v3_add(v3_add(v3_scale(d, fwd), v3_scale(r, right)), v3_scale(vc->sky, up));
    vc->location = v3_add(vc->location, delta);
    vc->look_at = v3_add(vc->look_at, delta);
    vc->moved = 1;
}

void view_camera_zoom(view_camera *vc, double k)
{
    if (!(k > 0) || !isfinite(k)) return;
    if (vc->kind == CAMERA_ORTHOGRAPHIC) {
        vc->right_len *= k;
        vc->up_len *= k;
        vc->moved = 1;
        return;
    }
    vec3 v = v3_sub(vc->location, vc->look_at);
    vec3 nv = v3_scale(v, k);
    if (v3_len(nv) < 1e-9) return;
    vc->location = v3_add(vc->look_at, nv);
    vc->moved = 1;
}

int view_camera_format(const view_camera *vc, char *buf, size_t n)
{
    const char *kind = vc->kind == CAMERA_ORTHOGRAPHIC ? "orthographic" : "perspective";
    char angle[64] = "";
    if (vc->kind != CAMERA_ORTHOGRAPHIC) snprintf(angle, sizeof angle, "  angle     %.9g\n", vc->angle);
    /* Items in the order POV-Ray applies them (also before #version 3.5):
     * right/up/direction fix the lengths and the handedness, angle the
     * direction's length, look_at turns everything towards the target. */
    return snprintf(buf, n,
                    "camera {\n"
                    "  %s\n"
                    "  location  <%.9g, %.9g, %.9g>\n"
                    "  right     <%.9g, 0, 0>\n"
                    "  up        <0, %.9g, 0>\n"
                    "  direction <0, 0, 1>\n"
                    "  sky       <%.9g, %.9g, %.9g>\n"
                    "%s"
                    "  look_at   <%.9g, %.9g, %.9g>\n"
                    "}\n",
                    kind, vc->location.x, vc->location.y, vc->location.z, vc->mirrored ? -vc->right_len : vc->right_len,
                    vc->up_len, vc->sky.x, vc->sky.y, vc->sky.z, angle, vc->look_at.x, vc->look_at.y, vc->look_at.z);
}
