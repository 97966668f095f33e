/* sdl_media.c - media { } and density { } (see sdl_media.h).
 *
 * Defaults and checks as POV-Ray 3.7's parser documents and applies them
 * (reference manual "Media"; Parse_Media read for semantics): a media
 * written at #version 3.5 or later starts as method 3, intervals 1,
 * samples 10,10; earlier ones as method 1, intervals 10, samples 1,1.
 * intervals >= 1, samples >= 1 with max >= min, method 1-3,
 * aa_threshold > 0, aa_level >= 1, 0 <= confidence < 1 are located errors;
 * eccentricity is only allowed with scattering type 5. Transforms written
 * in the media move its densities (media space). */
#include "sdl_media.h"
#include <string.h>
#include "sdl_directive.h"
#include "sdl_expr.h"
#include "sdl_material.h"
#include "sdl_pattern.h"

static void media_defaults(sdl_parser *p, scene_media *m)
{
    memset(m, 0, sizeof *m);
    if (p->version >= 3.5 - 1e-9) {
        m->method = 3;
        m->intervals = 1;
        m->min_samples = m->max_samples = 10;
    } else {
        m->method = 1;
        m->intervals = 10;
        m->min_samples = m->max_samples = 1;
    }
    m->ratio = 0.9;
    m->confidence = 0.9;
    m->variance = 1.0 / 128.0;
    m->aa_threshold = 0.1;
    m->aa_level = 3;
    m->scattering_type = MEDIA_ISOTROPIC;
    m->extinction = 1.0;
    m->collect = 1;
    m->transform = xform_identity();
}

static int is_named(const sdl_tok *t, const char *what)
{
    return t->tk.kind == TOK_IDENT && t->val.kind == VAL_OPAQUE && t->val.str && strcmp(t->val.str, what) == 0 &&
           t->val.ptr;
}

scene_pigment *sdl_parse_density(sdl_parser *p)
{
    scene_pigment *pg = sdl_alloc(p, sizeof *pg);
    if (!pg) return NULL;
    /* POV-Ray's Create_Pigment: a plain black pigment until a body says more */
    scene_default_pigment(pg);
    if (!sdl_begin_block(p, "density")) return NULL;
    sdl_pattern_pigment_body(p, pg); /* takes a density identifier first (sdl_pattern.c) */
    sdl_end_block(p);
    return sdl_ok(p) ? pg : NULL;
}

static void add_density(sdl_parser *p, scene_media *m, scene_pigment *pg)
{
    if (!pg) return;
    const scene_pigment **d = sdl_alloc(p, sizeof *d * (size_t)(m->ndensity + 1));
    if (!d) return;
    if (m->ndensity) memcpy(d, m->density, sizeof *d * (size_t)m->ndensity);
    d[m->ndensity++] = pg;
    m->density = d;
}

/* scattering '{' type, colour { eccentricity f | extinction f } '}' */
static void scattering(sdl_parser *p, scene_media *m)
{
    if (!sdl_begin_block(p, "scattering")) return;
    src_loc loc = sdl_peek(p)->tk.loc;
    m->scattering_type = sdl_to_int(sdl_float(p));
    if (m->scattering_type < MEDIA_ISOTROPIC || m->scattering_type > MEDIA_HENYEY_GREENSTEIN)
        sdl_warning(p, loc, "Unknown atmospheric scattering type.");
    sdl_accept(p, TOK_COMMA);
    m->scattering = sdl_rgb(p);
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE)) {
        sdl_tok t = sdl_next(p);
        if (sdl_is_kw(&t, KW_ECCENTRICITY)) {
            if (m->scattering_type != MEDIA_HENYEY_GREENSTEIN) {
                sdl_error(p, t.tk.loc, PT_ERR_SYNTAX, "Eccentricity cannot be used with this scattering type.");
                return;
            }
            m->eccentricity = sdl_float(p);
        } else if (sdl_is_kw(&t, KW_EXTINCTION)) {
            m->extinction = sdl_float(p);
        } else {
            sdl_unexpected(p, &t, "eccentricity, extinction or '}'");
            return;
        }
    }
    sdl_end_block(p);
}

scene_media *sdl_parse_media(sdl_parser *p)
{
    scene_media *m = sdl_alloc(p, sizeof *m);
    if (!m) return NULL;
    src_loc loc = sdl_peek(p)->tk.loc;
    if (!sdl_begin_block(p, "media")) return NULL;
    const sdl_tok *t = sdl_peek(p);
    if (is_named(t, "media")) {
        sdl_tok id = sdl_next(p);
        *m = *(const scene_media *)id.val.ptr;
    } else {
        media_defaults(p, m);
    }
    m->loc = loc;
    while (sdl_ok(p) && !sdl_is(sdl_peek(p), TOK_RBRACE) && !sdl_is(sdl_peek(p), TOK_EOF)) {
        xform x;
        if (sdl_transform_item(p, &x)) {
            m->transform = xform_then(m->transform, x);
            continue;
        }
        sdl_tok k = sdl_next(p);
        src_loc at = k.tk.loc;
        switch (k.tk.kind == TOK_KEYWORD ? k.tk.kw : KW_NONE) {
        case KW_INTERVALS:
            m->intervals = sdl_to_int(sdl_float(p));
            if (m->intervals < 1) sdl_error(p, at, PT_ERR_SYNTAX, "At least one interval is needed in media.");
            break;
        case KW_SAMPLES:
            m->min_samples = sdl_to_int(sdl_float(p));
            sdl_accept(p, TOK_COMMA);
            m->max_samples = sdl_to_int(sdl_allow_float(p, m->min_samples));
            if (m->min_samples < 1)
                sdl_error(p, at, PT_ERR_SYNTAX, "At least one sample per interval is needed in media.");
            else if (m->max_samples < m->min_samples)
                sdl_error(p, at, PT_ERR_SYNTAX, "Maximum number of samples per interval smaller than minimum number.");
            break;
        case KW_METHOD:
            m->method = sdl_to_int(sdl_float(p));
            if (m->method < 1 || m->method > 3) sdl_error(p, at, PT_ERR_SYNTAX, "Sample method choices are 1, 2, or 3.");
            break;
        case KW_JITTER: m->jitter = sdl_float(p); break;
        case KW_AA_THRESHOLD:
            m->aa_threshold = sdl_float(p);
            if (!(m->aa_threshold > 0.0)) sdl_error(p, at, PT_ERR_SYNTAX, "aa_threshold in media must be greater than zero.");
            break;
        case KW_AA_LEVEL:
            m->aa_level = sdl_to_int(sdl_float(p));
            if (m->aa_level < 1) sdl_error(p, at, PT_ERR_SYNTAX, "aa_level in media must be at least one.");
            break;
        case KW_COLLECT: m->collect = sdl_allow_float(p, 1.0) > 0.0; break;
        case KW_ABSORPTION: m->absorption = sdl_rgb(p); break;
        case KW_EMISSION: m->emission = sdl_rgb(p); break;
        case KW_SCATTERING: scattering(p, m); break;
        case KW_CONFIDENCE:
            m->confidence = sdl_float(p);
            if (!(m->confidence >= 0.0 && m->confidence < 1.0)) sdl_error(p, at, PT_ERR_SYNTAX, "Illegal confidence value in media.");
            break;
        case KW_VARIANCE: m->variance = sdl_float(p); break;
        case KW_RATIO: m->ratio = sdl_float(p); break;
        case KW_DENSITY: {
            scene_pigment *pg = sdl_parse_density(p);
            /* the media's transforms so far are not the new density's: it is
             * written in media space as it stands now */
            if (pg && !xform_is_identity(&m->transform)) pg->transform = xform_then(pg->transform, xform_inverse(m->transform));
            add_density(p, m, pg);
            break;
        }
        default: sdl_unexpected(p, &k, "media item"); break;
        }
    }
    sdl_end_block(p);
    return sdl_ok(p) ? m : NULL;
}

void sdl_media_append(sdl_parser *p, const scene_media *const **list, int *n, const scene_media *m)
{
    if (!m) return;
    const scene_media **a = sdl_alloc(p, sizeof *a * (size_t)(*n + 1));
    if (!a) return;
    if (*n) memcpy(a, *list, sizeof *a * (size_t)*n);
    a[(*n)++] = m;
    *list = a;
}

static int in_list(const scene_interior *in, const scene_media *m)
{
    for (int i = 0; in && i < in->nmedia; i++)
        if (in->media[i] == m) return 1;
    return 0;
}

void sdl_media_attach(sdl_parser *p, scene_interior *in, const scene_interior *before, const xform *obj)
{
    if (!in || in->nmedia == 0 || xform_is_identity(obj)) return;
    const scene_media **a = sdl_alloc(p, sizeof *a * (size_t)in->nmedia);
    if (!a) return;
    xform back = xform_inverse(*obj);
    for (int i = 0; i < in->nmedia; i++) {
        a[i] = in->media[i];
        if (in_list(before, in->media[i])) continue;
        scene_media *c = sdl_dup(p, in->media[i], sizeof *c);
        if (!c) return;
        c->transform = xform_then(c->transform, back);
        a[i] = c;
    }
    in->media = a;
}

void sdl_media_statement(sdl_parser *p)
{
    scene_media *m = sdl_parse_media(p);
    if (!m || !sdl_ok(p)) return;
    /* POV-Ray keeps the atmosphere's media in the order written */
    sdl_media_append(p, &p->s->atmosphere, &p->s->natmosphere, m);
}
