/* fuzz_parse.c - libFuzzer target for the whole SDL parser: the input is a
 * scene file, parsed by sdl_parse_string under lowered limits. */
#include "fuzz_sdl.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > FUZZ_MAX_INPUT) return 0;
    char *text = fuzz_text(data, size, NULL, NULL);
    if (!text) return 0;
    fuzz_parse_text("fuzz.pov", text);
    free(text);
    return 0;
}
