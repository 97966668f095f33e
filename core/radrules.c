/* radrules.c - POV-Ray 3.7's rules for light entering radiosity (the rules
 * and their sources are in the header). */
#include "radrules.h"

int radrules_legacy(const scene *sc)
{
    /* POV-Ray compares int(version * 100 + 0.5) with 370; the parser keeps
     * major and the first decimal (0.0 when no #version was read, which
     * POV-Ray takes as 3.62). */
    return sc->version_major * 10 + sc->version_minor < 37;
}

radrules radrules_of(const scene *sc, int gi)
{
    const scene_radiosity *rad = &sc->global.radiosity;
    radrules r;
    r.gi = gi != 0;
    r.legacy = radrules_legacy(sc);
    r.ambient = !r.gi || r.legacy;
    r.brightness = rad->enabled ? rad->brightness : 1.0;
    r.recursion_limit = rad->enabled ? rad->recursion_limit : 0;
    r.media = rad->enabled && rad->media;
    r.normal = rad->enabled && rad->normal;
    return r;
}

rgb radrules_emission(const radrules *r, const scene *sc, const scene_finish *f)
{
    rgb e = f->emission;
    if (r->ambient) {
        const rgb al = sc->global.ambient_light;
        e.r += f->ambient.r * al.r;
        e.g += f->ambient.g * al.g;
        e.b += f->ambient.b * al.b;
    }
    return e;
}

int radrules_gather_level(int k) { return k > 0 ? (int)(1.5 * k) : 0; }

int radrules_level_limit(const scene *sc, int gather_level)
{
    int m = sc->global.max_trace_level > 0 ? sc->global.max_trace_level : 5;
    return gather_level > 0 && m < gather_level + 1 ? gather_level + 1 : m;
}

int radrules_gathers(unsigned obj_flags) { return !(obj_flags & OBJ_NO_RADIOSITY); }
