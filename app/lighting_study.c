/* lighting_study.c - lighting-study options: photometric units, AOV layers and
 * the quantity of the false-colour map (see lighting_study.h, docs/units.md). */
#include "lighting_study.h"
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "img_falsecolor.h"
#include "shade_light.h"

static const struct {
    const char *name;
    double metres;
} unit_table[] = {{"m", 1.0}, {"cm", 0.01}, {"mm", 0.001}, {"km", 1000.0}, {"in", 0.0254}, {"ft", 0.3048}, {"yd", 0.9144}};

int lighting_parse_units(const char *s, double *mpu)
{
    if (!s || !*s) return 0;
    for (size_t i = 0; i < sizeof unit_table / sizeof unit_table[0]; i++) {
        if (strcmp(s, unit_table[i].name) == 0) {
            *mpu = unit_table[i].metres;
            return 1;
        }
    }
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end || !(v > 0.0) || !isfinite(v)) return 0;
    *mpu = v;
    return 1;
}

pt_status lighting_setup(lighting_study *ls, const char *units, const char *aovs, const char *fc_quantity, diag *d)
{
    memset(ls, 0, sizeof *ls);
    if (units && !lighting_parse_units(units, &ls->metres_per_unit)) {
        diag_error(d, "--units wants m, cm, mm, km, in, ft, yd or a positive number of metres per scene unit, got '%s'",
                   units);
        return PT_ERR_USAGE;
    }
    if (aovs) {
        pt_status st = shade_aov_parse(aovs, &ls->aov_mask, d);
        if (st != PT_OK) return st;
    }
    if (fc_quantity) {
        if (strcmp(fc_quantity, "luminance") == 0) ls->fc_quantity = LIGHTING_LUMINANCE;
        else if (strcmp(fc_quantity, "illuminance") == 0) ls->fc_quantity = LIGHTING_ILLUMINANCE;
        else {
            diag_error(d, "--false-color-quantity wants luminance or illuminance, got '%s'", fc_quantity);
            return PT_ERR_USAGE;
        }
    }
    if (ls->metres_per_unit > 0.0)
        snprintf(ls->units_text, sizeof ls->units_text,
                 "1 scene unit = %g m; lights photometric (point/spot/area: Y of colour = cd, parallel: lx); "
                 "RGB = luminance in cd/m2 (Rec.709 Y)",
                 ls->metres_per_unit);
    else
        snprintf(ls->units_text, sizeof ls->units_text, "POV-Ray light units (relative)");
    size_t at = 0;
    for (int k = 0; k < AOV_COUNT; k++) {
        if (!(ls->aov_mask & (1u << k))) continue;
        int n = snprintf(ls->aovs_text + at, sizeof ls->aovs_text - at, "%s%s", at ? "," : "", shade_aov_name(k));
        if (n > 0 && (size_t)n < sizeof ls->aovs_text - at) at += (size_t)n;
    }
    return PT_OK;
}

void lighting_check_outputs(const lighting_study *ls, const char *const *outputs, int n, diag *d)
{
    if (!ls->aov_mask) return;
    for (int i = 0; i < n; i++)
        if (img_format_from_path(outputs[i]) == IMG_FMT_EXR) return;
    src_loc none = {NULL, 0, 0};
    diag_report(d, DIAG_WARNING, none, NULL, "--aovs: the layers are written into .exr outputs only, and none is given");
}

pt_status lighting_apply_units(lighting_study *ls, scene *sc, diag *d)
{
    if (!(ls->metres_per_unit > 0.0)) return PT_OK;
    return shade_light_units_apply(sc, ls->metres_per_unit, d);
}

pt_status lighting_alloc(lighting_study *ls, int w, int h, diag *d)
{
    unsigned mask = ls->aov_mask;
    if (ls->fc_quantity == LIGHTING_ILLUMINANCE) mask |= 1u << AOV_ILLUMINANCE;
    if (!mask) return PT_OK;
    ls->aov = shade_aov_new(w, h, mask);
    if (!ls->aov) {
        diag_error(d, "out of memory for the AOV buffers (%dx%d)", w, h);
        return PT_ERR_NOMEM;
    }
    return PT_OK;
}

void lighting_write_opts(lighting_study *ls, img_write_opts *wo)
{
    ls->nlayers = 0;
    for (int k = 0; ls->aov && k < AOV_COUNT; k++) {
        if (!(ls->aov_mask & (1u << k)) || !ls->aov->buf[k]) continue;
        img_layer *l = &ls->layers[ls->nlayers++];
        l->name = shade_aov_name(k);
        l->suffixes = shade_aov_suffixes(k);
        l->data = ls->aov->buf[k];
        l->colour = shade_aov_is_colour(k);
        l->full_float = k == AOV_DEPTH;
    }
    wo->layers = ls->nlayers ? ls->layers : NULL;
    wo->nlayers = ls->nlayers;
    /* Under --units the values are absolute: RGB (1,1,1) is 1 cd/m^2. */
    wo->white_luminance = ls->metres_per_unit > 0.0 ? 1.0 : 0.0;
}

float *lighting_fc_values(const lighting_study *ls, const framebuffer *fb)
{
    if (ls->fc_quantity != LIGHTING_ILLUMINANCE) return img_fc_luminance(fb, 1.0);
    if (!ls->aov || !ls->aov->buf[AOV_ILLUMINANCE]) return NULL;
    size_t n = (size_t)ls->aov->width * (size_t)ls->aov->height;
    float *v = malloc(sizeof(float) * (n ? n : 1));
    if (!v) return NULL;
    const float *e = ls->aov->buf[AOV_ILLUMINANCE];
    for (size_t i = 0; i < n; i++) v[i] = (float)(0.2126 * e[i * 3] + 0.7152 * e[i * 3 + 1] + 0.0722 * e[i * 3 + 2]);
    return v;
}

const char *lighting_fc_unit(const lighting_study *ls)
{
    if (!(ls->metres_per_unit > 0.0)) return NULL;
    return ls->fc_quantity == LIGHTING_ILLUMINANCE ? "lx" : "cd/m2";
}

const char *lighting_fc_name(const lighting_study *ls)
{
    return ls->fc_quantity == LIGHTING_ILLUMINANCE ? "illuminance" : "luminance";
}

void lighting_free(lighting_study *ls)
{
    shade_aov_free(ls->aov);
    ls->aov = NULL;
}
