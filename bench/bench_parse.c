/* bench_parse.c - parse time of the SDL parser beside POV-Ray 3.7's own
 * "Parse Time" for the same files:
 *   1. a generated mesh2 of N triangles (default 1,000,000),
 *   2. a macro-heavy scene: a #while of M iterations (default 100,000) that
 *      calls a macro building one textured sphere each time.
 * Prints seconds (best of R runs), IR bytes and peak RSS growth per
 * triangle. Figures only; never a pass/fail test.
 *
 *   bench_parse [--tris N] [--iters M] [--runs R] [--dir DIR] [--no-povray] */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>
#include "arena.h"
#include "pipeline.h"
#include "scene.h"
#include "sdl.h"
#include "timer.h"

static long peak_rss_kib(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_maxrss;
}

/* A grid mesh2 with at least `tris` triangles (two per cell). */
static int write_mesh2(const char *path, long tris, long *out_tris)
{
    long side = (long)ceil(sqrt((double)tris / 2.0));
    long cells = side * side, verts = (side + 1) * (side + 1);
    FILE *f = fopen(path, "w");
    if (!f) return 0;
    fprintf(f, "#version 3.7;\nglobal_settings { assumed_gamma 1 }\ncamera { location <0.5, 2, -1> look_at <0.5, 0, 0.5> }\n");
    fprintf(f, "light_source { <0, 10, -10>, rgb 1 }\nmesh2 {\n  vertex_vectors { %ld", verts);
    for (long j = 0; j <= side; j++)
        for (long i = 0; i <= side; i++) {
            double x = (double)i / side, z = (double)j / side;
            fprintf(f, ",\n    <%.6f, %.6f, %.6f>", x, 0.05 * sin(12 * x) * cos(9 * z), z);
        }
    fprintf(f, "\n  }\n  face_indices { %ld", cells * 2);
    for (long j = 0; j < side; j++)
        for (long i = 0; i < side; i++) {
            long a = j * (side + 1) + i, b = a + 1, c = a + side + 1, d = c + 1;
            fprintf(f, ",\n    <%ld, %ld, %ld>, <%ld, %ld, %ld>", a, b, d, a, d, c);
        }
    fprintf(f, "\n  }\n  pigment { rgb 0.8 }\n}\n");
    *out_tris = cells * 2;
    return fclose(f) == 0;
}

static int write_macro_scene(const char *path, long iters)
{
    FILE *f = fopen(path, "w");
    if (!f) return 0;
    fprintf(f, "#version 3.7;\nglobal_settings { assumed_gamma 1 }\ncamera { location <50, 50, -150> look_at <50, 50, 0> }\n"
               "light_source { <0, 100, -100>, rgb 1 }\n"
               "#macro Ball(I)\n"
               "  #local P = <mod(I, 100), div(I, 100) * 0.1, 0>;\n"
               "  sphere { P, 0.4 texture { pigment { rgb <I / %ld, 0.5, 1 - I / %ld> } finish { phong 0.3 } } }\n"
               "#end\n"
               "#declare I = 0;\n#while (I < %ld)\n  Ball(I)\n  #declare I = I + 1;\n#end\n",
            iters, iters, iters);
    return fclose(f) == 0;
}

/* Best-of-runs parse time; IR bytes of the last parse. */
static double time_parse(const char *path, int runs, size_t *ir_bytes, long *rss_growth_kib)
{
    double best = INFINITY;
    for (int r = 0; r < runs; r++) {
        long before = peak_rss_kib();
        diag *d = diag_new();
        scene *s = NULL;
        sdl_options so;
        pipeline_sdl_options(&so, NULL, 320, 240);
        double t = 0.0;
        pt_status st = pipeline_parse(path, &so, &s, d, &t);
        if (st != PT_OK) {
            for (int i = 0; i < diag_count(d); i++) {
                char *m = diag_format(diag_get(d, i));
                fprintf(stderr, "%s\n", m);
                free(m);
            }
            diag_free(d);
            return NAN;
        }
        if (t < best) best = t;
        if (ir_bytes) *ir_bytes = arena_bytes(s->mem);
        if (rss_growth_kib && r == 0) *rss_growth_kib = peak_rss_kib() - before;
        scene_free(s);
        diag_free(d);
    }
    return best;
}

/* POV-Ray's "Parse Time: ... (x.xxx seconds)" for the file, or NAN. */
static double povray_parse_time(const char *path)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "povray +I'%s' +W1 +H1 -F -D 2>&1", path);
    FILE *p = popen(cmd, "r");
    if (!p) return NAN;
    char line[1024];
    double v = NAN;
    while (fgets(line, sizeof line, p)) {
        const char *k = strstr(line, "Parse Time:");
        const char *o = k ? strchr(k, '(') : NULL;
        if (o) v = atof(o + 1);
    }
    pclose(p);
    return v;
}

int main(int argc, char **argv)
{
    long tris = 1000000, iters = 100000;
    int runs = 3, povray = 1;
    const char *dir = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--tris") && i + 1 < argc) tris = atol(argv[++i]);
        else if (!strcmp(argv[i], "--iters") && i + 1 < argc) iters = atol(argv[++i]);
        else if (!strcmp(argv[i], "--runs") && i + 1 < argc) runs = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--dir") && i + 1 < argc) dir = argv[++i];
        else if (!strcmp(argv[i], "--no-povray")) povray = 0;
        else {
            fprintf(stderr, "usage: bench_parse [--tris N] [--iters M] [--runs R] [--dir DIR] [--no-povray]\n");
            return 2;
        }
    }
    char tmp[] = "/tmp/bench_parse_XXXXXX";
    if (!dir) {
        if (!mkdtemp(tmp)) {
            perror("mkdtemp");
            return 3;
        }
        dir = tmp;
    }
    char mesh[1024], macro[1024];
    snprintf(mesh, sizeof mesh, "%s/mesh2_%ld.pov", dir, tris);
    snprintf(macro, sizeof macro, "%s/macro_%ld.pov", dir, iters);
    long ntris = 0;
    if (!write_mesh2(mesh, tris, &ntris) || !write_macro_scene(macro, iters)) {
        fprintf(stderr, "bench_parse: cannot write the scenes in %s: %s\n", dir, strerror(errno));
        return 3;
    }
    struct stat st;
    stat(mesh, &st);
    size_t ir_mesh = 0, ir_macro = 0;
    long rss_mesh = 0, rss_macro = 0;
    double t_mesh = time_parse(mesh, runs, &ir_mesh, &rss_mesh);
    double t_macro = time_parse(macro, runs, &ir_macro, &rss_macro);
    double p_mesh = povray ? povray_parse_time(mesh) : NAN;
    double p_macro = povray ? povray_parse_time(macro) : NAN;
    printf("bench_parse: best of %d runs; POV-Ray 3.7 'Parse Time' from its statistics (+W1 +H1 -F)\n", runs);
    printf("%-34s %12s %12s %8s\n", "scene", "partray s", "POV-Ray s", "ratio");
    printf("%-34s %12.3f %12.3f %8.2f\n", "mesh2, triangles", t_mesh, p_mesh, t_mesh / p_mesh);
    printf("  (%ld triangles, %.1f MB of text)\n", ntris, st.st_size / 1e6);
    printf("%-34s %12.3f %12.3f %8.2f\n", "macro #while, iterations", t_macro, p_macro, t_macro / p_macro);
    printf("  (%ld iterations, %ld spheres)\n", iters, iters);
    printf("memory per triangle: %.1f bytes of IR, %.1f bytes of peak RSS growth while parsing\n", (double)ir_mesh / ntris,
           rss_mesh * 1024.0 / ntris);
    printf("memory per sphere (macro scene): %.1f bytes of IR\n", (double)ir_macro / iters);
    if (dir == tmp) {
        unlink(mesh);
        unlink(macro);
        rmdir(tmp);
    }
    return 0;
}
