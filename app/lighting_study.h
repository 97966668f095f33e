/* lighting_study.h - the lighting-study options of `partray render`:
 * --units (photometric lights, docs/units.md), --aovs (extra EXR layers,
 * shade/shade_aov.h) and --false-color-quantity (luminance or illuminance
 * map). main.c parses them here before the scene, applies the units after
 * parsing, hands the AOV buffers to render_gi and the layers to img_write. */
#ifndef PT_LIGHTING_STUDY_H
#define PT_LIGHTING_STUDY_H
#include "diag.h"
#include "framebuffer.h"
#include "img_io.h"
#include "scene.h"
#include "shade_aov.h"

enum { LIGHTING_LUMINANCE = 0, LIGHTING_ILLUMINANCE = 1 };

typedef struct {
    double metres_per_unit;      /* 0 = POV-Ray's own light units */
    unsigned aov_mask;           /* AOVs written as EXR layers */
    int fc_quantity;             /* LIGHTING_LUMINANCE or LIGHTING_ILLUMINANCE */
    shade_aov *aov;              /* buffers: aov_mask, + illuminance for an illuminance map */
    img_layer layers[AOV_COUNT];
    int nlayers;
    char units_text[160];        /* for the EXR metadata: "1 unit = 0.01 m; RGB in cd/m2 (...)" */
    char aovs_text[160];         /* "direct,albedo,..." */
} lighting_study;

/* Parse the three options (each may be NULL). units: m, cm, mm, km, in,
 * ft, yd, or a positive number of metres per scene unit. PT_ERR_USAGE with
 * a message in d when one is wrong. */
pt_status lighting_setup(lighting_study *ls, const char *units, const char *aovs, const char *fc_quantity, diag *d);

/* "cm" -> 0.01 etc.; returns 0 (and *mpu untouched) when not a unit. */
int lighting_parse_units(const char *s, double *mpu);

/* A warning in d when AOVs are asked for but no output is an EXR. */
void lighting_check_outputs(const lighting_study *ls, const char *const *outputs, int n, diag *d);

/* After parsing: make the lights photometric when --units was given
 * (shade_light_units_apply; warnings into d). */
pt_status lighting_apply_units(lighting_study *ls, scene *sc, diag *d);

/* AOV buffers for a w x h render, when any are wanted (ls->aov stays NULL
 * otherwise). PT_ERR_NOMEM. */
pt_status lighting_alloc(lighting_study *ls, int w, int h, diag *d);

/* EXR layers, whiteLuminance (1 cd/m^2 per unit under --units). */
void lighting_write_opts(lighting_study *ls, img_write_opts *wo);

/* The values of the false-colour map (malloc'd w*h floats): Rec.709 Y of
 * the image (luminance) or of the illuminance AOV; NULL when out of memory. */
float *lighting_fc_values(const lighting_study *ls, const framebuffer *fb);
/* Legend unit ("cd/m2", "lx") under --units, else NULL; the quantity's name. */
const char *lighting_fc_unit(const lighting_study *ls);
const char *lighting_fc_name(const lighting_study *ls);

void lighting_free(lighting_study *ls);

#endif
