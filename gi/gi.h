/* gi.h - global illumination modes (particle-space GI of seed 000 lands with its issue). */
#ifndef PT_GI_H
#define PT_GI_H
typedef enum { GI_NONE, GI_PARTICLE, GI_PMFG, GI_PATH, GI_DETP, GI_VPL, GI_LINKS } gi_mode;
const char *gi_mode_name(gi_mode m);
/* Parses "none", "particle", "pmfg", "path", "detp", "vpl", "links"; returns -1 if unknown. */
int gi_mode_parse(const char *s);
#endif
