/* sdl_scene.c - camera, lights, global settings, background, statements. */
#include "sdl_scene.h"
#include <math.h>
#include <stddef.h>
#include <string.h>
#include "sdl_atmos.h"
#include "sdl_directive.h"
#include "sdl_expr.h"
#include "sdl_material.h"
#include "sdl_media.h"
#include "sdl_object.h"

/* ------------------------------------------------------------ camera */

/* What a camera block said, before POV-Ray 3.5+'s fixed-order evaluation. */
typedef struct {
    int had_angle, had_up, had_right, had_look_at, had_focal;
    double angle;
    xform trans;
} camera_said;

/* mesh_camera := 'mesh_camera' '{' rays_per_pixel [','] distribution [ [','] max_distance ]
 *   ( mesh | mesh2 ) { mesh | mesh2 } [ 'smooth' ] '}'   (POV-Ray 3.7's checks) */
static void mesh_camera(sdl_parser *p, scene_camera *c, src_loc loc)
{
    if (!sdl_begin_block(p, "mesh_camera")) return;
    src_loc at = sdl_peek(p)->tk.loc;
    c->kind = CAMERA_MESH;
    c->mesh_rays_per_pixel = sdl_to_int(sdl_float(p));
    if (sdl_ok(p) && c->mesh_rays_per_pixel <= 0) sdl_error(p, at, PT_ERR_SYNTAX, "mesh_camera rays per pixel must be at least 1");
    sdl_accept(p, TOK_COMMA);
    at = sdl_peek(p)->tk.loc;
    c->mesh_distribution = sdl_to_int(sdl_float(p));
    if (sdl_ok(p) && (c->mesh_distribution < 0 || c->mesh_distribution > 3))
        sdl_error(p, at, PT_ERR_SYNTAX, "unknown mesh_camera distribution %d (0 to 3)", c->mesh_distribution);
    if (sdl_ok(p) && c->mesh_distribution >= 2 && c->mesh_rays_per_pixel != 1)
        sdl_error(p, at, PT_ERR_SYNTAX, "mesh_camera distribution %d needs 1 ray per pixel", c->mesh_distribution);
    sdl_accept(p, TOK_COMMA);
    c->mesh_max_distance = sdl_allow_float(p, 0.0);
    const scene_object *meshes[256];
    int n = 0;
    while (sdl_ok(p) && (sdl_is_kw(sdl_peek(p), KW_MESH) || sdl_is_kw(sdl_peek(p), KW_MESH2))) {
        src_loc ml = sdl_peek(p)->tk.loc;
        sdl_obj *o = sdl_parse_object(p);
        if (!o || !o->obj) break;
        if (n == 256) {
            sdl_error(p, ml, PT_ERR_LIMIT, "mesh_camera has more than 256 meshes");
            break;
        }
        meshes[n++] = o->obj;
    }
    c->mesh_smooth = sdl_accept_kw(p, KW_SMOOTH);
    if (sdl_ok(p) && c->mesh_smooth && c->mesh_distribution != 3)
        sdl_error(p, p->last_loc, PT_ERR_SYNTAX, "smooth needs mesh_camera distribution 3");
    if (sdl_ok(p) && n == 0) {
        sdl_tok t = sdl_next(p);
        sdl_unexpected(p, &t, "mesh or mesh2 in mesh_camera");
        return;
    }
    sdl_end_block(p);
    if (sdl_ok(p) && c->mesh_distribution == 0 && c->mesh_rays_per_pixel > n)
        sdl_error(p, loc, PT_ERR_SYNTAX, "mesh_camera distribution 0 needs at least as many meshes (%d) as rays per pixel (%d)", n,
                  c->mesh_rays_per_pixel);
    const scene_object **m = sdl_alloc(p, sizeof *m * (size_t)(n ? n : 1));
    if (!m) return;
    memcpy(m, meshes, sizeof *m * (size_t)n);
    c->meshes = m;
    c->nmeshes = n;
    if (c->mesh_max_distance > 0)
        sdl_warn_once(p, loc, "mesh_camera: max_distance is not applied (rays go on past %g)", c->mesh_max_distance);
}

/* camera_type := perspective | orthographic | fisheye | ultra_wide_angle |
 *   omnimax | panoramic | spherical | cylinder N | mesh_camera ; returns 0 if none */
static int camera_type(sdl_parser *p, scene_camera *c)
{
    const sdl_tok *t = sdl_peek(p);
    if (t->tk.kind != TOK_KEYWORD) return 0;
    switch (t->tk.kw) {
    case KW_PERSPECTIVE: c->kind = CAMERA_PERSPECTIVE; break;
    case KW_ORTHOGRAPHIC: c->kind = CAMERA_ORTHOGRAPHIC; break;
    case KW_FISHEYE: c->kind = CAMERA_FISHEYE; break;
    case KW_ULTRA_WIDE_ANGLE: c->kind = CAMERA_ULTRA_WIDE_ANGLE; break;
    case KW_OMNIMAX: c->kind = CAMERA_OMNIMAX; break;
    case KW_PANORAMIC: c->kind = CAMERA_PANORAMIC; break;
    case KW_SPHERICAL: c->kind = CAMERA_SPHERICAL; break;
    case KW_CYLINDER: {
        sdl_tok k = sdl_next(p);
        int n = sdl_to_int(sdl_float(p));
        if (n < 1 || n > 4) sdl_error(p, k.tk.loc, PT_ERR_SYNTAX, "invalid cylinder camera type %d (1 to 4)", n);
        c->kind = CAMERA_CYLINDER;
        c->cylinder_type = n;
        return 1;
    }
    case KW_MESH_CAMERA: {
        sdl_tok k = sdl_next(p);
        if (p->version < 3.5) sdl_error(p, k.tk.loc, PT_ERR_SYNTAX, "mesh_camera needs #version 3.5 or later");
        else mesh_camera(p, c, k.tk.loc);
        return 1;
    }
    default: return 0;
    }
    sdl_next(p);
    return 1;
}

/* camera_angle := 'angle' float [ ',' float ]  (orthographic: the float is optional) */
static void camera_angle(sdl_parser *p, scene_camera *c, camera_said *said, src_loc loc)
{
    double a = c->kind == CAMERA_ORTHOGRAPHIC ? sdl_allow_float(p, 0.0) : sdl_float(p);
    if (c->kind == CAMERA_SPHERICAL) { /* angle h [,] [v]: the vertical angle defaults to h/2 */
        sdl_accept(p, TOK_COMMA);
        c->v_angle = sdl_allow_float(p, a * 0.5);
    }
    if (a < 0) sdl_error(p, loc, PT_ERR_SYNTAX, "negative viewing angle");
    said->had_angle = 1;
    said->angle = a;
}

/* camera_item := angle .. | location v | direction v | up v | right v | sky v |
 *   look_at v | transform_item | aperture f | blur_samples n [, n] |
 *   focal_point v | confidence f | variance f | normal {..} | bokeh {..} */
static int camera_item(sdl_parser *p, scene_camera *c, camera_said *said)
{
    xform x;
    if (sdl_transform_item(p, &x)) {
        said->trans = xform_then(said->trans, x);
        return 1;
    }
    const sdl_tok *pk = sdl_peek(p);
    if (pk->tk.kind != TOK_KEYWORD) return 0;
    sdl_tok t = sdl_next(p);
    switch (t.tk.kw) {
    case KW_ANGLE: camera_angle(p, c, said, t.tk.loc); break;
    case KW_LOCATION: c->location = sdl_vector(p); break;
    case KW_DIRECTION: c->direction = sdl_vector(p); break;
    case KW_UP: c->up = sdl_vector(p); said->had_up = 1; break;
    case KW_RIGHT: c->right = sdl_vector(p); said->had_right = 1; break;
    case KW_SKY: c->sky = sdl_vector(p); break;
    case KW_LOOK_AT: c->look_at = sdl_vector(p); said->had_look_at = 1; break;
    case KW_APERTURE: c->aperture = sdl_float(p); break;
    case KW_BLUR_SAMPLES:
        /* blur_samples MAX, or blur_samples MIN, MAX (POV-Ray 3.7's Parse_Camera) */
        c->blur_samples = sdl_to_int(sdl_float(p));
        c->blur_samples_min = 0;
        if (sdl_accept(p, TOK_COMMA)) {
            double mx = sdl_allow_float(p, 0.0);
            if (mx > 0) {
                c->blur_samples_min = c->blur_samples;
                c->blur_samples = sdl_to_int(mx);
                if (c->blur_samples_min > c->blur_samples)
                    sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "focal blur samples minimum must not be larger than maximum");
            }
        }
        break;
    case KW_FOCAL_POINT: c->focal_point = sdl_vector(p); said->had_focal = 1; break;
    case KW_CONFIDENCE: {
        double k = sdl_float(p);
        if (k > 0.0 && k < 1.0) c->confidence = k;
        else sdl_warning(p, t.tk.loc, "illegal confidence value %g (0 < confidence < 1); the default 0.9 is used", k);
        break;
    }
    case KW_VARIANCE: {
        double k = sdl_float(p);
        if (k >= 0.0 && k <= 1.0) c->variance = k;
        else sdl_warning(p, t.tk.loc, "illegal variance value %g (0 <= variance <= 1); the default is used", k);
        break;
    }
    case KW_NORMAL:
        c->normal = sdl_parse_normal(p); /* shade.c perturbs the primary rays */
        break;
    case KW_BOKEH:
        sdl_ignore_block(p, t.tk.loc, "bokeh", "camera bokeh is not supported yet and is ignored");
        break;
    default:
        sdl_unget(p, &t);
        return 0;
    }
    return 1;
}

/* POV-Ray 3.7 (Parse_Camera, language >= 3.5): `angle` rescales direction
 * to |right|/2/tan(angle/2) keeping its orientation; `look_at` then turns
 * direction towards the point and rebuilds right = sky x direction and
 * up = direction x right, keeping each vector's length and the handedness
 * of the (up, direction, right) triple as given. */
static void camera_look_at(sdl_parser *p, scene_camera *c, src_loc loc)
{
    double dl = v3_len(c->direction), ul = v3_len(c->up), rl = v3_len(c->right);
    double handed = v3_dot(v3_cross(c->up, c->direction), c->right);
    vec3 d = v3_sub(c->look_at, c->location);
    if (v3_len2(d) < 1e-10) {
        sdl_error(p, loc, PT_ERR_SYNTAX, "camera location and look_at point must be different");
        return;
    }
    d = v3_norm(d);
    vec3 r = v3_cross(c->sky, d);
    if (fabs(r.x) < 1e-10 && fabs(r.y) < 1e-10 && fabs(r.z) < 1e-10) {
        sdl_warning(p, loc, "camera look_at direction and sky are parallel; using the given right vector");
        r = c->right;
    }
    r = v3_norm(r);
    c->up = v3_scale(v3_cross(d, r), ul);
    c->direction = v3_scale(d, dl);
    c->right = v3_scale(r, handed > 0 ? rl : -rl);
}

static void camera_apply(sdl_parser *p, scene_camera *c, const camera_said *said, src_loc loc)
{
    if (said->had_angle) {
        c->angle = said->angle;
        if ((c->kind == CAMERA_PERSPECTIVE || c->kind == CAMERA_ORTHOGRAPHIC) && said->angle >= 180)
            sdl_error(p, loc, PT_ERR_SYNTAX, "viewing angle has to be smaller than 180 degrees");
        if ((c->kind == CAMERA_PERSPECTIVE || c->kind == CAMERA_ORTHOGRAPHIC) && said->angle > 0 && said->angle < 180)
            c->direction = v3_scale(v3_norm(c->direction), v3_len(c->right) / tan(said->angle * M_PI / 360.0) / 2.0);
    }
    if (said->had_look_at && sdl_ok(p)) camera_look_at(p, c, loc);
    if (c->kind == CAMERA_ORTHOGRAPHIC && ((!said->had_up && !said->had_right) || said->had_angle)) {
        /* same image area as the perspective camera would show at look_at */
        double k1 = v3_len(v3_sub(c->look_at, c->location)), k2 = v3_len(c->direction);
        if (k1 > 1e-10 && k2 > 1e-10) {
            c->right = v3_scale(c->right, k1 / k2);
            c->up = v3_scale(c->up, k1 / k2);
        }
    }
    /* focal blur: POV-Ray measures the focal distance before the transforms */
    c->focal_distance = said->had_focal ? v3_len(v3_sub(c->focal_point, c->location)) : v3_len(c->direction);
    c->location = xform_point(&said->trans, c->location);
    c->direction = xform_vector(&said->trans, c->direction);
    c->up = xform_vector(&said->trans, c->up);
    c->right = xform_vector(&said->trans, c->right);
}

/* Before #version 3.5 camera items apply in the order written. */
static void camera_old_style(sdl_parser *p, scene_camera *c, src_loc loc)
{
    for (;;) {
        camera_said said;
        memset(&said, 0, sizeof said);
        said.trans = xform_identity();
        if (!sdl_ok(p) || (!camera_type(p, c) && !camera_item(p, c, &said))) return;
        camera_apply(p, c, &said, loc);
    }
}

/* camera := '{' ( camera_identifier { transform_item } |
 *                 { camera_type } { camera_item } ) '}' */
static void camera_block(sdl_parser *p, scene_camera *c)
{
    src_loc loc = sdl_peek(p)->tk.loc;
    if (!sdl_begin_block(p, "camera")) return;
    c->loc = loc;
    camera_said said;
    memset(&said, 0, sizeof said);
    said.trans = xform_identity();
    const sdl_tok *t = sdl_peek(p);
    if (t->tk.kind == TOK_IDENT && t->val.kind == VAL_CAMERA) {
        sdl_tok id = sdl_next(p);
        *c = *(const scene_camera *)id.val.ptr;
        xform x;
        while (sdl_ok(p) && sdl_transform_item(p, &x)) said.trans = xform_then(said.trans, x);
        c->location = xform_point(&said.trans, c->location);
        c->direction = xform_vector(&said.trans, c->direction);
        c->up = xform_vector(&said.trans, c->up);
        c->right = xform_vector(&said.trans, c->right);
    } else if (p->version < 3.5) {
        camera_old_style(p, c, loc);
    } else {
        while (sdl_ok(p) && camera_type(p, c)) {}
        while (sdl_ok(p) && camera_item(p, c, &said)) {}
        if (sdl_ok(p)) camera_apply(p, c, &said, loc);
    }
    sdl_end_block(p);
}

scene_camera *sdl_parse_camera_new(sdl_parser *p)
{
    scene_camera *c = sdl_alloc(p, sizeof *c);
    if (!c) return NULL;
    scene_default_camera(c);
    p->view_depth++;
    camera_block(p, c);
    p->view_depth--;
    return c;
}

/* ------------------------------------------------------------ lights */

static int is_spot(const scene_light *l) { return l->kind == LIGHT_SPOT || l->kind == LIGHT_CYLINDER; }

/* area_light := 'area_light' axis ',' axis ',' size ',' size */
static void area_light(sdl_parser *p, scene_light *l, src_loc loc)
{
    l->area = 1;
    l->axis1 = sdl_vector(p);
    sdl_accept(p, TOK_COMMA);
    l->axis2 = sdl_vector(p);
    sdl_accept(p, TOK_COMMA);
    l->size1 = sdl_to_int(sdl_float(p));
    sdl_accept(p, TOK_COMMA);
    l->size2 = sdl_to_int(sdl_float(p));
    if (sdl_ok(p) && (l->size1 <= 0 || l->size2 <= 0)) sdl_error(p, loc, PT_ERR_SYNTAX, "area light sizes must be greater than zero");
}

/* looks_like := 'looks_like' '{' ( object_identifier | object_statement ) object_mods '}' */
static void looks_like(sdl_parser *p, scene_light *l)
{
    if (!sdl_begin_block(p, "looks_like")) return;
    const sdl_tok *t = sdl_peek(p);
    sdl_obj *o = NULL;
    if (t->tk.kind == TOK_IDENT && t->val.kind == VAL_OBJECT) {
        sdl_tok id = sdl_next(p);
        o = sdl_copy_obj(p, id.val.ptr);
    } else {
        o = sdl_parse_object(p);
    }
    if (o && o->obj) {
        xform t = xform_translate(l->position);
        sdl_obj_transform(o, &t);
        sdl_object_mods(p, o);
        o->obj->flags |= OBJ_NO_SHADOW;
        l->looks_like = o->obj;
    }
    sdl_end_block(p);
}

/* spot_param := ( radius | falloff | tightness | point_at ) value, only
 * for spotlights / cylinder lights (point_at also for parallel lights) */
static void spot_param(sdl_parser *p, scene_light *l, const sdl_tok *t)
{
    sdl_kw k = t->tk.kw;
    if (!(is_spot(l) || (k == KW_POINT_AT && l->parallel))) {
        sdl_error(p, t->tk.loc, PT_ERR_SYNTAX, "'%s' cannot be used with a standard light source", sdl_kw_text(k));
        return;
    }
    switch (k) {
    case KW_RADIUS: l->radius = sdl_float(p); break;
    case KW_FALLOFF: l->falloff = sdl_float(p); break;
    case KW_TIGHTNESS: l->tightness = sdl_float(p); break;
    default: l->point_at = sdl_vector(p); break;
    }
}

/* light_photons := '{' { refraction b | reflection b | area_light } '}'
 * (POV-Ray 3.7's light_source photons block, parser.cpp) */
static void light_photons(sdl_parser *p, scene_light *l)
{
    if (!sdl_begin_block(p, "photons")) return;
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE)) {
        sdl_tok t = sdl_next(p);
        if (sdl_is_kw(&t, KW_REFRACTION)) {
            int on = sdl_float(p) != 0.0;
            l->ph_refraction = on;
            l->ph_refraction_off = !on;
        } else if (sdl_is_kw(&t, KW_REFLECTION)) {
            int on = sdl_float(p) != 0.0;
            l->ph_reflection = on;
            l->ph_reflection_off = !on;
        } else if (sdl_is_kw(&t, KW_AREA_LIGHT)) {
            l->ph_area_light = 1;
        } else {
            sdl_unexpected(p, &t, "refraction, reflection, area_light or '}'");
            return;
        }
    }
    sdl_end_block(p);
}

/* light_item := spotlight | cylinder | parallel | point_at v | radius f |
 *   falloff f | tightness f | area_light .. | jitter | adaptive f | circular |
 *   orient | area_illumination [b] | fade_distance f | fade_power f |
 *   shadowless | media_interaction [b] | media_attenuation [b] |
 *   looks_like {..} | projected_through {..} | photons {..} | colour_map {..} |
 *   transform_item */
static int light_item(sdl_parser *p, sdl_obj *so)
{
    scene_light *l = &so->lights[0];
    xform x;
    if (sdl_transform_item(p, &x)) {
        sdl_obj_transform(so, &x);
        return 1;
    }
    if (sdl_peek(p)->tk.kind != TOK_KEYWORD) return 0;
    sdl_tok t = sdl_next(p);
    switch (t.tk.kw) {
    case KW_SPOTLIGHT: l->kind = LIGHT_SPOT; l->radius = 30; l->falloff = 45; l->tightness = 0; break;
    case KW_CYLINDER: l->kind = LIGHT_CYLINDER; l->radius = 0.75; l->falloff = 1; l->tightness = 0; l->parallel = 1; break;
    case KW_PARALLEL: l->parallel = 1; break;
    case KW_POINT_AT: case KW_RADIUS: case KW_FALLOFF: case KW_TIGHTNESS: spot_param(p, l, &t); break;
    case KW_AREA_LIGHT: area_light(p, l, t.tk.loc); break;
    case KW_JITTER: l->jitter = 1; break;
    case KW_ADAPTIVE: l->adaptive = sdl_to_int(sdl_float(p)); break;
    case KW_CIRCULAR: l->circular = 1; break;
    case KW_ORIENT: l->orient = 1; break;
    case KW_AREA_ILLUMINATION: l->area_illumination = sdl_allow_float(p, 1.0) > 0; break;
    case KW_FADE_DISTANCE: l->fade_distance = sdl_float(p); break;
    case KW_FADE_POWER: l->fade_power = sdl_float(p); break;
    case KW_SHADOWLESS: l->shadowless = 1; break;
    case KW_MEDIA_INTERACTION: l->media_interaction = sdl_allow_float(p, 1.0) > 0; break;
    case KW_MEDIA_ATTENUATION: l->media_attenuation = sdl_allow_float(p, 1.0) > 0; break;
    case KW_LOOKS_LIKE: looks_like(p, l); break;
    case KW_PROJECTED_THROUGH:
        /* projected_through := '{' ( object_identifier | object_statement ) object_mods '}' */
        if (sdl_begin_block(p, "projected_through")) {
            const sdl_tok *pt = sdl_peek(p);
            sdl_obj *o = NULL;
            if (pt->tk.kind == TOK_IDENT && pt->val.kind == VAL_OBJECT) {
                sdl_tok id = sdl_next(p);
                o = sdl_copy_obj(p, id.val.ptr);
            } else if (sdl_starts_object(pt)) {
                o = sdl_parse_object(p);
            }
            if (o && o->obj) {
                sdl_object_mods(p, o);
                l->projected_through = o->obj;
            }
            sdl_end_block(p);
        }
        break;
    case KW_PHOTONS: light_photons(p, l); break;
    case KW_COLOR_MAP: case KW_COLOUR_MAP:
        sdl_ignore_block(p, t.tk.loc, sdl_kw_text(t.tk.kw),
                         "colour_map in light_source is undocumented POV-Ray syntax that does nothing; ignored");
        break;
    default:
        sdl_unget(p, &t);
        return 0;
    }
    return 1;
}

/* light := '{' ( light_identifier { transform_item } |
 *                location [','] colour { light_item } ) '}' */
sdl_obj *sdl_parse_light(sdl_parser *p, src_loc loc)
{
    if (!sdl_begin_block(p, "light_source")) return NULL;
    /* a light's values may change per frame without the rest of the scene
     * (looks_like and projected_through are geometry: the app checks those) */
    p->view_depth++;
    sdl_obj *so = NULL;
    const sdl_tok *t = sdl_peek(p);
    if (t->tk.kind == TOK_IDENT && t->val.kind == VAL_OBJECT) {
        sdl_tok id = sdl_next(p);
        so = sdl_copy_obj(p, id.val.ptr);
        if (so) sdl_object_mods(p, so);
    } else {
        so = sdl_alloc(p, sizeof *so);
        scene_light *l = sdl_alloc(p, sizeof *l);
        if (!so || !l) {
            p->view_depth--;
            return NULL;
        }
        scene_default_light(l);
        l->loc = loc;
        so->lights = l;
        so->nlights = 1;
        l->position = sdl_vector(p);
        sdl_accept(p, TOK_COMMA);
        l->colour = sdl_rgb(p);
        while (sdl_ok(p) && light_item(p, so)) {}
        if (sdl_ok(p) && l->circular && (l->size1 <= 1 || l->size2 <= 1))
            sdl_error(p, loc, PT_ERR_SYNTAX, "circular area light must have more than 1 point per axis");
    }
    p->view_depth--;
    if (!sdl_end_block(p)) return NULL;
    return so;
}

/* ------------------------------------------------------------ global settings */

/* A radiosity value with POV-Ray 3.7's range check. */
static double checked(sdl_parser *p, src_loc loc, double v, int ok, const char *what)
{
    if (!ok && sdl_ok(p)) sdl_error(p, loc, PT_ERR_SYNTAX, "radiosity %s", what);
    return v;
}

/* radiosity count/nearest_count: N [ ',' M ] */
static void radiosity_counts(sdl_parser *p, scene_radiosity *r, sdl_kw k, src_loc loc)
{
    int n = sdl_to_int(sdl_float(p));
    sdl_accept(p, TOK_COMMA);
    if (k == KW_COUNT) {
        r->count = sdl_to_int(checked(p, loc, n, n > 0, "count must be a positive number"));
        r->direction_pool = sdl_to_int(sdl_allow_float(p, n > 1600 ? n : 1600));
        checked(p, loc, 0, r->direction_pool >= n, "count can not be more than the direction pool size (count's 2nd value)");
    } else {
        r->nearest_count = sdl_to_int(checked(p, loc, n, n >= 1 && n <= 20, "nearest_count must be from 1 to 20"));
        r->nearest_count_pretrace = sdl_to_int(sdl_allow_float(p, 0.0));
        checked(p, loc, 0, r->nearest_count_pretrace >= 0 && r->nearest_count_pretrace < n,
                "nearest_count for adaptive pretrace must be non-negative and smaller than nearest_count");
    }
}

/* radiosity_item := adc_bailout f | always_sample b | brightness f |
 *   count n [, n] | error_bound f | gray_threshold f | low_error_factor f |
 *   max_sample f | maximum_reuse f | minimum_reuse f | nearest_count n [, n] |
 *   normal b | media b | pretrace_start f | pretrace_end f |
 *   recursion_limit n | subsurface b | load_file s | save_file s */
static int radiosity_item(sdl_parser *p, scene_radiosity *r)
{
    if (sdl_peek(p)->tk.kind != TOK_KEYWORD) return 0;
    sdl_tok t = sdl_next(p);
    src_loc at = t.tk.loc;
    double v;
    switch (t.tk.kw) {
    case KW_ADC_BAILOUT: v = sdl_float(p); r->adc_bailout = checked(p, at, v, v > 0, "adc_bailout must be a positive number"); break;
    case KW_ALWAYS_SAMPLE: r->always_sample = sdl_to_int(sdl_float(p)) != 0; break;
    case KW_BRIGHTNESS: v = sdl_float(p); r->brightness = checked(p, at, v, v > 0, "brightness must be a positive number"); break;
    case KW_COUNT: case KW_NEAREST_COUNT: radiosity_counts(p, r, t.tk.kw, at); break;
    case KW_ERROR_BOUND: v = sdl_float(p); r->error_bound = checked(p, at, v, v > 0, "error_bound must be a positive number"); break;
    case KW_GRAY_THRESHOLD: v = sdl_float(p); r->gray_threshold = checked(p, at, v, v >= 0 && v <= 1, "gray_threshold must be from 0 to 1"); break;
    case KW_LOW_ERROR_FACTOR: v = sdl_float(p); r->low_error_factor = checked(p, at, v, v > 0, "low_error_factor must be a positive number"); break;
    case KW_MAX_SAMPLE: r->max_sample = sdl_float(p); break;
    case KW_MAXIMUM_REUSE: v = sdl_float(p); r->maximum_reuse = checked(p, at, v, v > 0, "maximum_reuse must be a positive number"); break;
    case KW_MINIMUM_REUSE: v = sdl_float(p); r->minimum_reuse = checked(p, at, v, v >= 0, "minimum_reuse can not be negative"); break;
    case KW_NORMAL: r->normal = sdl_to_int(sdl_float(p)) != 0; break;
    case KW_MEDIA: r->media = sdl_to_int(sdl_float(p)) != 0; break;
    case KW_SUBSURFACE: r->subsurface = sdl_to_int(sdl_float(p)) != 0; break;
    case KW_PRETRACE_START: v = sdl_float(p); r->pretrace_start = checked(p, at, v, v > 0 && v <= 1, "pretrace_start must be greater than 0 and at most 1"); break;
    case KW_PRETRACE_END: v = sdl_float(p); r->pretrace_end = checked(p, at, v, v > 0 && v <= 1, "pretrace_end must be greater than 0 and at most 1"); break;
    case KW_RECURSION_LIMIT: v = sdl_float(p); r->recursion_limit = sdl_to_int(checked(p, at, v, v >= 1 && v <= 20, "recursion_limit must be from 1 to 20")); break;
    case KW_LOAD_FILE: case KW_SAVE_FILE:
        sdl_warn_once(p, at, "radiosity %s is ignored (POV-Ray 3.7 takes it from the command line)", sdl_kw_text(t.tk.kw));
        sdl_string(p);
        break;
    default:
        sdl_unget(p, &t);
        return 0;
    }
    return 1;
}

static void radiosity_block(sdl_parser *p, scene_radiosity *r)
{
    r->enabled = 1;
    if (!sdl_begin_block(p, "radiosity")) return;
    while (sdl_ok(p) && radiosity_item(p, r)) {}
    sdl_end_block(p);
}

/* photons := '{' { spacing f | count n | autostop f | jitter f |
 *   max_trace_level n | adc_bailout f | expand_thresholds f, n |
 *   gather n, n | radius [f] [, [f] [, [f] [, [f]]]] | media n [, f] |
 *   save_file s | load_file s } '}'
 * POV-Ray 3.7's global photons block (parser.cpp): every item into
 * scene_photons, with its checks and warnings. */
/* The photons items that are one number stored as it is: the keyword, the
 * field (an int field takes the number's integer part) and its given bit. */
static const struct {
    sdl_kw kw;
    size_t off;
    int is_int;
    unsigned given;
} photon_numbers[] = {
    {KW_SPACING, offsetof(scene_photons, spacing), 0, SCENE_PH_SPACING},
    {KW_COUNT, offsetof(scene_photons, count), 1, SCENE_PH_COUNT},
    {KW_AUTOSTOP, offsetof(scene_photons, autostop), 0, SCENE_PH_AUTOSTOP},
    {KW_JITTER, offsetof(scene_photons, jitter), 0, SCENE_PH_JITTER},
    {KW_MAX_TRACE_LEVEL, offsetof(scene_photons, max_trace_level), 1, SCENE_PH_MAX_TRACE_LEVEL},
    {KW_ADC_BAILOUT, offsetof(scene_photons, adc_bailout), 0, SCENE_PH_ADC_BAILOUT},
};

/* Reads the number of a photon_numbers item; 0 when kw is not one. */
static int photon_number(sdl_parser *p, scene_photons *ph, sdl_kw kw)
{
    for (size_t i = 0; i < sizeof photon_numbers / sizeof photon_numbers[0]; i++) {
        if (photon_numbers[i].kw != kw) continue;
        char *field = (char *)ph + photon_numbers[i].off;
        double v = sdl_float(p);
        if (photon_numbers[i].is_int) *(int *)field = sdl_to_int(v);
        else *(double *)field = v;
        ph->given |= photon_numbers[i].given;
        return 1;
    }
    return 0;
}

static void photons_block(sdl_parser *p, scene_global *g, src_loc loc)
{
    scene_photons *ph = &g->photons;
    scene_default_photons(ph);
    ph->loc = loc;
    if (!sdl_begin_block(p, "photons")) return;
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE)) {
        sdl_tok t = sdl_next(p);
        if (t.tk.kind != TOK_KEYWORD) {
            sdl_unexpected(p, &t, "a photons item or '}'");
            return;
        }
        if (photon_number(p, ph, t.tk.kw)) continue;
        switch (t.tk.kw) {
        case KW_EXPAND_THRESHOLDS:
            ph->expand_tolerance = sdl_float(p);
            sdl_accept(p, TOK_COMMA);
            ph->expand_min = sdl_to_int(sdl_float(p));
            if (ph->expand_tolerance < 0.0) {
                sdl_warning(p, t.tk.loc, "the first parameter of expand_thresholds must be at least 0; using 0");
                ph->expand_tolerance = 0.0;
            }
            if (ph->expand_min < 0) {
                sdl_warning(p, t.tk.loc, "the second parameter of expand_thresholds must be at least 0; using 0");
                ph->expand_min = 0;
            }
            ph->given |= SCENE_PH_EXPAND;
            break;
        case KW_GATHER:
            ph->gather_min = sdl_to_int(sdl_float(p));
            sdl_accept(p, TOK_COMMA);
            ph->gather_max = sdl_to_int(sdl_float(p));
            ph->given |= SCENE_PH_GATHER;
            break;
        case KW_RADIUS: {
            static const double def[4] = {-1.0, 1.0, -1.0, 1.0};
            for (int i = 0; i < 4; i++) {
                if (i > 0) sdl_accept(p, TOK_COMMA);
                ph->radius[i] = sdl_allow_float(p, def[i]);
            }
            ph->given |= SCENE_PH_RADIUS;
            break;
        }
        case KW_MEDIA:
            ph->media_steps = sdl_to_int(sdl_float(p));
            sdl_accept(p, TOK_COMMA);
            if (ph->media_steps < 0) sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "photons: max media steps must be non-negative");
            ph->media_factor = sdl_allow_float(p, 1.0);
            if (ph->media_factor <= 0.0)
                sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "photons: media spacing factor must be greater than zero");
            ph->given |= SCENE_PH_MEDIA;
            break;
        case KW_SAVE_FILE:
        case KW_LOAD_FILE: {
            int load = t.tk.kw == KW_LOAD_FILE;
            if (ph->file && ph->load != load)
                sdl_warning(p, t.tk.loc, "photons: cannot both load and save a photon map; now %s", load ? "loading" : "saving");
            ph->file = sdl_string(p);
            ph->load = load;
            ph->given |= load ? SCENE_PH_LOAD_FILE : SCENE_PH_SAVE_FILE;
            break;
        }
        default:
            sdl_unexpected(p, &t, "a photons item (spacing, count, autostop, jitter, max_trace_level, adc_bailout, "
                                  "expand_thresholds, gather, radius, media, save_file, load_file) or '}'");
            return;
        }
    }
    if (!sdl_end_block(p)) return;
    /* max gather count 0 means no photon maps (parser.cpp) */
    ph->enabled = ph->gather_max > 0;
    if (ph->enabled) {
        if (ph->gather_min < 0) sdl_error(p, p->last_loc, PT_ERR_SYNTAX, "photons: min gather count cannot be negative");
        else if (ph->gather_min > ph->gather_max)
            sdl_error(p, p->last_loc, PT_ERR_SYNTAX, "photons: min gather count must be less than max gather count");
    } else {
        sdl_warning(p, p->last_loc, "photons: gather's maximum is 0: photons stay off");
    }
}

/* global_item := assumed_gamma f | ambient_light c | max_trace_level n |
 *   adc_bailout f | max_intersections n | noise_generator n |
 *   irid_wavelength c | radiosity {..} | photons {..} | other (skipped) */
static int global_item(sdl_parser *p, scene_global *g)
{
    if (sdl_peek(p)->tk.kind != TOK_KEYWORD) return 0;
    sdl_tok t = sdl_next(p);
    switch (t.tk.kw) {
    case KW_ASSUMED_GAMMA: g->assumed_gamma = sdl_float(p); break;
    case KW_AMBIENT_LIGHT: g->ambient_light = sdl_rgb(p); break;
    case KW_MAX_TRACE_LEVEL: g->max_trace_level = sdl_to_int(sdl_float(p)); break;
    case KW_ADC_BAILOUT: g->adc_bailout = sdl_float(p); break;
    case KW_MAX_INTERSECTIONS: g->max_intersections = sdl_to_int(sdl_float(p)); break;
    case KW_NOISE_GENERATOR: g->noise_generator = sdl_to_int(sdl_float(p)); break;
    case KW_NUMBER_OF_WAVES: {
        int n = sdl_to_int(sdl_float(p));
        if (n <= 0) {
            sdl_warning(p, t.tk.loc, "illegal value for number_of_waves; using 1");
            n = 1;
        }
        g->number_of_waves = n;
        break;
    }
    case KW_IRID_WAVELENGTH: {
        rgb w = sdl_rgb(p);
        g->irid_wavelength[0] = w.r;
        g->irid_wavelength[1] = w.g;
        g->irid_wavelength[2] = w.b;
        break;
    }
    case KW_RADIOSITY: radiosity_block(p, &g->radiosity); break;
    case KW_PHOTONS: photons_block(p, g, t.tk.loc); break;
    case KW_CHARSET: { /* ascii | utf8 | sys: how string literals' bytes are read */
        sdl_tok k = sdl_next(p);
        if (k.tk.kind == TOK_KEYWORD && k.tk.kw == KW_ASCII) p->charset = 0;
        else if (k.tk.kind == TOK_KEYWORD && k.tk.kw == KW_UTF8) p->charset = 1;
        else if (k.tk.kind == TOK_KEYWORD && k.tk.kw == KW_SYS) p->charset = 2; /* read as UTF-8 here */
        else sdl_unexpected(p, &k, "ascii, utf8 or sys");
        break;
    }
    default:
        sdl_warn_once(p, t.tk.loc, "global_settings '%s' is not supported yet and is ignored", sdl_kw_text(t.tk.kw));
        sdl_skip_item(p);
        break;
    }
    return 1;
}

static void global_settings(sdl_parser *p)
{
    if (!sdl_begin_block(p, "global_settings")) return;
    while (sdl_ok(p) && global_item(p, &p->s->global)) {}
    sdl_end_block(p);
}

/* background := '{' colour '}' */
static void background(sdl_parser *p)
{
    if (!sdl_begin_block(p, "background")) return;
    p->s->background = sdl_colour(p, 1);
    sdl_end_block(p);
}

/* default := ['#'] 'default' '{' { texture | pigment | finish | normal } '}' */
void sdl_parse_default(sdl_parser *p)
{
    if (!sdl_begin_block(p, "#default")) return;
    scene_texture *dt = &p->s->default_texture;
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE)) {
        sdl_tok t = sdl_next(p);
        if (sdl_is_kw(&t, KW_TEXTURE)) {
            scene_texture *nt = sdl_parse_texture(p);
            if (nt) {
                *dt = *nt;
                dt->next = NULL;
            }
        } else if (sdl_is_kw(&t, KW_PIGMENT)) {
            sdl_parse_pigment(p, &dt->pigment);
        } else if (sdl_is_kw(&t, KW_FINISH)) {
            sdl_parse_finish(p, &dt->finish);
        } else if (sdl_is_kw(&t, KW_NORMAL)) {
            scene_normal *nm = sdl_parse_normal_from(p, dt->normal);
            if (nm) dt->normal = nm;
            dt->has_normal = 1;
        } else {
            sdl_unexpected(p, &t, "texture, pigment, finish or normal");
        }
    }
    sdl_end_block(p);
    p->default_texture_set = 1;
}

/* ------------------------------------------------------------ statements */

/* statement := camera | object_statement | global_settings | background |
 *   fog | sky_sphere | rainbow | media */
static void statement(sdl_parser *p)
{
    const sdl_tok *pk = sdl_peek(p);
    if (sdl_starts_object(pk)) {
        sdl_obj *o = sdl_parse_object(p);
        sdl_obj_add_to_scene(p, o);
        return;
    }
    sdl_tok t = sdl_next(p);
    switch (t.tk.kind == TOK_KEYWORD ? t.tk.kw : KW_NONE) {
    case KW_CAMERA: {
        scene_camera *c = sdl_parse_camera_new(p);
        if (c && sdl_ok(p)) {
            p->s->camera = *c;
            p->s->camera_set = 1;
        }
        return;
    }
    case KW_GLOBAL_SETTINGS: global_settings(p); return;
    case KW_DEFAULT: sdl_parse_default(p); return;
    case KW_BACKGROUND: background(p); return;
    case KW_FOG: case KW_SKY_SPHERE: sdl_atmos_statement(p, t.tk.kw); return; /* sdl_atmos.c */
    case KW_RAINBOW: sdl_atmos_statement(p, t.tk.kw); return; /* sdl_atmos.c */
    case KW_MEDIA: sdl_media_statement(p); return; /* atmospheric media (sdl_media.c) */
    default: break;
    }
    if (t.tk.kind == TOK_IDENT && t.val.kind == VAL_NONE)
        sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "unknown identifier '%.*s'", t.tk.len, t.tk.text);
    else if (t.tk.kind == TOK_IDENT)
        sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "identifier '%.*s' cannot start a statement (use object { %.*s })", t.tk.len, t.tk.text, t.tk.len, t.tk.text);
    else
        sdl_unexpected(p, &t, "object, light_source, camera or other scene statement");
}

void sdl_parse_scene(sdl_parser *p)
{
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_EOF)) statement(p);
}
