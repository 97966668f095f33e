/* fuzz_mesh2.c - libFuzzer target for mesh2 (and mesh) bodies: the input
 * goes inside `mesh2 { ... }`, so every byte is spent on vertex_vectors,
 * normal_vectors, uv_vectors, texture_list, face_indices, normal_indices,
 * uv_indices, inside_vector and object modifiers. A first byte 'M' wraps
 * the rest in `mesh { ... }` instead, for triangle/smooth_triangle lists.
 * The mesh is declared and used twice, so shared-mesh copies run too. */
#include "fuzz_sdl.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > FUZZ_MAX_INPUT) return 0;
    int plain_mesh = size > 0 && data[0] == 'M';
    char *text = fuzz_text(plain_mesh ? data + 1 : data, plain_mesh ? size - 1 : size,
                           plain_mesh ? "#declare M = mesh {\n" : "#declare M = mesh2 {\n",
                           "\n}\nobject { M }\nobject { M translate x }\n");
    if (!text) return 0;
    fuzz_parse_text("fuzz_mesh2.pov", text);
    free(text);
    return 0;
}
