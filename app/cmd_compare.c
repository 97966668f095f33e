/* cmd_compare.c - placeholder until the image metrics land. */
#include "cmd_compare.h"
#include <stdio.h>
int cmd_compare(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    fprintf(stderr, "partray compare: not built yet\n");
    return 2;
}
