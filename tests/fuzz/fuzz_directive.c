/* fuzz_directive.c - libFuzzer target for the directive and macro layer
 * (parser/sdl_directive.c): #declare/#local, #if/#ifdef/#switch, #while/#for,
 * #macro and calls, #include, #undef, #version, #debug/#warning/#error.
 *
 * The input is made mostly of directives: every line that does not start
 * with '#' or a blank gets a '#' in front ("declare A = 1;" becomes
 * "#declare A = 1;"), while indented lines stay as written (macro bodies,
 * expressions, objects). A few macros and identifiers are declared first so
 * that short inputs reach calls, recursion and scopes. The dictionary
 * (sdl.dict) holds the directive and keyword spellings. */
#include "fuzz_sdl.h"

static const char prelude[] =
    "#declare F = 1;\n"
    "#declare V = <1, 2, 3>;\n"
    "#declare S = \"s\";\n"
    "#macro Id(A) A #end\n"
    "#macro Rec(N) #if (N > 0) Rec(N - 1) #end #end\n"
    "#macro Loc(A) #local L = A; L #end\n";

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > FUZZ_MAX_INPUT) return 0;
    size_t np = sizeof prelude - 1;
    char *text = malloc(np + 2 * size + 2);
    if (!text) return 0;
    memcpy(text, prelude, np);
    size_t o = np;
    int line_start = 1;
    for (size_t i = 0; i < size; i++) {
        char c = (char)data[i];
        if (line_start && c != '#' && c != ' ' && c != '\t' && c != '\n' && c != '\r') text[o++] = '#';
        text[o++] = c;
        line_start = c == '\n' || c == '\r';
    }
    text[o++] = '\n';
    text[o] = 0;
    fuzz_parse_text("fuzz_directive.pov", text);
    free(text);
    return 0;
}
