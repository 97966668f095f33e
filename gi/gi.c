/* gi.c - GI mode names. */
#include "gi.h"
#include <string.h>

static const char *const names[] = {"none", "particle", "pmfg", "path"};

const char *gi_mode_name(gi_mode m) { return (unsigned)m < 4u ? names[m] : "?"; }

int gi_mode_parse(const char *s)
{
    for (int i = 0; i < 4; i++)
        if (strcmp(s, names[i]) == 0) return i;
    return -1;
}
