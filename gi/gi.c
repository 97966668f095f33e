/* gi.c - GI mode names. */
#include "gi.h"
#include <string.h>

static const char *const names[] = {"none", "particle", "pmfg", "path", "detp", "vpl", "links"};
#define NMODES ((int)(sizeof names / sizeof names[0]))

const char *gi_mode_name(gi_mode m) { return (unsigned)m < (unsigned)NMODES ? names[m] : "?"; }

int gi_mode_parse(const char *s)
{
    for (int i = 0; i < NMODES; i++)
        if (strcmp(s, names[i]) == 0) return i;
    return -1;
}
