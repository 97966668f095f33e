/* cmd_farm.c - `partray farm`.
 *
 * The plan: frames (the animation options, as `render` reads them) x tiles
 * (horizontal bands, +SR/+ER in pixels), one task each. A task is one line
 * of DIR/tasks.txt, a shell command that is idempotent: it renders its tile
 * to DIR/tiles/fFRAME_tTILE.exr (32-bit EXR, written under a temporary
 * name and renamed) unless that file is there, and records its exit status
 * in DIR/status/INDEX. So any task may run twice, and a farm run again on
 * the same DIR does only what is missing.
 *
 * Engines (docs/farm.md):
 *  - slurm: one job array (`sbatch --requeue --array=...`) of the missing
 *    tasks and a merge job (`--dependency=afterany:ARRAY`: it runs however
 *    the tasks ended) running `partray farm --merge-step DIR`, which merges
 *    every frame whose tiles are all there and resubmits the tasks that are
 *    missing with a new merge job, up to --max-rounds. Slurm's own requeue
 *    of a task makes it eligible again only after a delay of minutes (Slurm
 *    22.05; docs/farm.md) and an `afterok` dependency is never
 *    satisfied once a task failed, hence resubmission and afterany.
 *  - parallel: GNU parallel runs the lines of tasks.txt on the hosts of
 *    --sshloginfile (":" is this machine) with --retries, --joblog and, from
 *    the second round on, --resume-failed; then the same merge step.
 * A task that ends with 130 or 143 (SIGINT, SIGTERM: preempted, cancelled)
 * or leaves no status (a lost node) is run again; any other failure (a
 * scene error, exit 1-3) would fail again and is reported instead.
 * Progress (frames merged, tiles rendered, an ETA from the rate so far)
 * comes from the files in DIR, whatever engine runs the tasks. */
#include "cmd_farm.h"
#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include "anim.h"
#include "cli.h"
#include "cmd_merge.h"
#include "gi.h"
#include "img_io.h"
#include "ini.h"
#include "pipeline.h"
#include "subproc.h"
#include "timer.h"

#define FARM_MAX_TILES 256

typedef struct {
    char dir[1024];        /* absolute */
    char partray[2048];    /* this binary */
    int first, last, digits, animated;
    int tiles, width, height;
    char output[2048];     /* the merged frames' name before numbering */
    char engine[16];       /* slurm | parallel */
    int max_rounds;
    /* parallel */
    char sshloginfile[2048];
    char sbatch_opts[1024]; /* slurm: extra sbatch options (partition, time limit...), as given */
    int jobs, retries;
    double timeout;        /* seconds the driver waits, 0 = no limit */
} farm_plan;

static int exists(const char *p)
{
    return access(p, F_OK) == 0;
}

static int ntasks(const farm_plan *p)
{
    return (p->last - p->first + 1) * p->tiles;
}

/* What a tile's render is told to write (-o): render numbers an
 * animation's outputs, so the frame number comes after "_f". */
static void tile_arg(const farm_plan *p, int tile, char *buf, size_t n)
{
    snprintf(buf, n, "%s/tiles/t%03d_f.exr", p->dir, tile);
}

/* The file a tile's render writes: DIR/tiles/tTTT_fFRAME.exr. */
static void tile_path(const farm_plan *p, int frame, int tile, char *buf, size_t n)
{
    char arg[2200];
    tile_arg(p, tile, arg, sizeof arg);
    char *s = anim_output_name(arg, frame, p->animated ? p->digits : 0);
    snprintf(buf, n, "%s", s ? s : arg);
    free(s);
}

static void frame_path(const farm_plan *p, int frame, char *buf, size_t n)
{
    char *s = anim_output_name(p->output, frame, p->animated ? p->digits : 0);
    snprintf(buf, n, "%s", s ? s : p->output);
    free(s);
}

/* Appends s to the buffer, single-quoted for sh. */
static void quote(char *buf, size_t n, const char *s)
{
    size_t k = strlen(buf);
    if (k + 3 >= n) return;
    buf[k++] = '\'';
    for (; *s && k + 6 < n; s++) {
        if (*s == '\'') {
            memcpy(buf + k, "'\\''", 4);
            k += 4;
        } else {
            buf[k++] = *s;
        }
    }
    buf[k++] = '\'';
    buf[k] = 0;
}

static void append(char *buf, size_t n, const char *s)
{
    size_t k = strlen(buf);
    snprintf(buf + k, n - k, "%s", s);
}

/* ---- the plan on disk -------------------------------------------------- */

static int write_text(const char *path, const char *text)
{
    char tmp[2100];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE *f = fopen(tmp, "w");
    if (!f) return 0;
    int ok = fputs(text, f) >= 0;
    ok &= fclose(f) == 0;
    return ok && rename(tmp, path) == 0;
}

static int save_plan(const farm_plan *p)
{
    char path[2100], text[16384];
    snprintf(text, sizeof text,
             "partray_farm 1\ndir %s\npartray %s\nframes %d %d %d %d\ntiles %d %d %d\noutput %s\nengine %s\n"
             "max_rounds %d\nsshloginfile %s\njobs %d\nretries %d\nsbatch_opts %s\n",
             p->dir, p->partray, p->first, p->last, p->digits, p->animated, p->tiles, p->width, p->height, p->output,
             p->engine, p->max_rounds, p->sshloginfile, p->jobs, p->retries, p->sbatch_opts);
    snprintf(path, sizeof path, "%s/plan", p->dir);
    return write_text(path, text);
}

static int load_plan(const char *dir, farm_plan *p)
{
    char path[2100];
    snprintf(path, sizeof path, "%s/plan", dir);
    char *t = subproc_read_text(path, NULL);
    if (!t) return 0;
    memset(p, 0, sizeof *p);
    int ok = 0;
    for (char *line = strtok(t, "\n"); line; line = strtok(NULL, "\n")) {
        char *v = strchr(line, ' ');
        if (!v) continue;
        *v++ = 0;
        if (!strcmp(line, "partray_farm")) ok = atoi(v) == 1;
        else if (!strcmp(line, "dir")) snprintf(p->dir, sizeof p->dir, "%s", v);
        else if (!strcmp(line, "partray")) snprintf(p->partray, sizeof p->partray, "%s", v);
        else if (!strcmp(line, "frames")) sscanf(v, "%d %d %d %d", &p->first, &p->last, &p->digits, &p->animated);
        else if (!strcmp(line, "tiles")) sscanf(v, "%d %d %d", &p->tiles, &p->width, &p->height);
        else if (!strcmp(line, "output")) snprintf(p->output, sizeof p->output, "%s", v);
        else if (!strcmp(line, "engine")) snprintf(p->engine, sizeof p->engine, "%s", v);
        else if (!strcmp(line, "max_rounds")) p->max_rounds = atoi(v);
        else if (!strcmp(line, "sshloginfile")) snprintf(p->sshloginfile, sizeof p->sshloginfile, "%s", v);
        else if (!strcmp(line, "jobs")) p->jobs = atoi(v);
        else if (!strcmp(line, "retries")) p->retries = atoi(v);
        else if (!strcmp(line, "sbatch_opts")) snprintf(p->sbatch_opts, sizeof p->sbatch_opts, "%s", v);
    }
    free(t);
    return ok && p->tiles > 0 && p->last >= p->first;
}

static int read_int_file(const char *path, int def)
{
    char *t = subproc_read_text(path, NULL);
    if (!t) return def;
    int v = atoi(t);
    free(t);
    return v;
}

static void write_int_file(const char *path, int v)
{
    char s[32];
    snprintf(s, sizeof s, "%d\n", v);
    write_text(path, s);
}

/* ---- progress and the merge step --------------------------------------- */

typedef struct {
    int frames_done, tiles_done;
    int retry[FARM_MAX_TILES * 64]; /* task indices to run again */
    int nretry;
    int failed;                     /* tasks that failed for good */
    char why[1200];
} farm_state;

/* Looks at DIR: frames merged, tiles there; merges every frame whose tiles
 * are all there (merge on); lists the tasks to run again. */
static void survey(const farm_plan *p, int merge, farm_state *s)
{
    memset(s, 0, sizeof *s);
    for (int f = p->first; f <= p->last; f++) {
        char out[2200], tiles[FARM_MAX_TILES][2200];
        frame_path(p, f, out, sizeof out);
        if (exists(out)) {
            s->frames_done++;
            s->tiles_done += p->tiles;
            continue;
        }
        int have = 0;
        for (int t = 0; t < p->tiles; t++) {
            tile_path(p, f, t, tiles[t], sizeof tiles[t]);
            if (exists(tiles[t])) {
                have++;
                continue;
            }
            int idx = (f - p->first) * p->tiles + t;
            char st[2200];
            snprintf(st, sizeof st, "%s/status/%d", p->dir, idx);
            int rc = read_int_file(st, -1);
            /* no status: never ran, or its node was lost; 130/143: interrupted */
            if (rc == -1 || rc == 130 || rc == 143 || rc == 0) {
                if (s->nretry < (int)(sizeof s->retry / sizeof s->retry[0])) s->retry[s->nretry++] = idx;
            } else {
                s->failed++;
                snprintf(s->why, sizeof s->why, "task %d (frame %d, tile %d) failed with exit %d; its log: %s/logs", idx, f,
                         t, rc, p->dir);
            }
        }
        s->tiles_done += have;
        if (merge && have == p->tiles) {
            const char *names[FARM_MAX_TILES];
            for (int t = 0; t < p->tiles; t++) names[t] = tiles[t];
            diag *d = diag_new();
            pt_status st = merge_tiles(out, names, p->tiles, d);
            cli_print_diags(d, 0, 0);
            diag_free(d);
            if (st == PT_OK) {
                s->frames_done++;
                for (int t = 0; t < p->tiles; t++) { /* the frame holds them now; a stopped try's partial too */
                    remove(tiles[t]);
                    char *dot = strrchr(tiles[t], '.');
                    if (dot) {
                        snprintf(dot, (size_t)(tiles[t] + sizeof tiles[t] - dot), ".partial.exr");
                        remove(tiles[t]);
                    }
                }
            } else {
                s->failed++;
                snprintf(s->why, sizeof s->why, "frame %d: its tiles do not merge (see above)", f);
            }
        }
    }
}

static void farm_report(const farm_plan *p, const farm_state *s, double t0, int *last)
{
    int key = s->frames_done * 100000 + s->tiles_done;
    if (key == *last) return;
    *last = key;
    int total = ntasks(p), nframes = p->last - p->first + 1;
    double el = timer_now() - t0;
    char eta[64] = "";
    if (s->tiles_done > 0 && s->tiles_done < total)
        snprintf(eta, sizeof eta, ", ETA %.1f s", el / s->tiles_done * (total - s->tiles_done));
    fprintf(stderr, "farm: frames %d/%d merged, tiles %d/%d rendered, %.1f s%s\n", s->frames_done, nframes, s->tiles_done,
            total, el, eta);
}

/* ---- engines ----------------------------------------------------------- */

static int run_capture(const char *cmd, char *out, size_t n)
{
    FILE *f = popen(cmd, "r");
    if (!f) return -1;
    size_t k = fread(out, 1, n - 1, f);
    out[k] = 0;
    int st = pclose(f);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* sbatch the tasks idx[] as one array and a merge job after it. */
static int slurm_submit(const farm_plan *p, const int *idx, int n)
{
    char list[65536] = "", cmd[70000], out[256];
    for (int i = 0; i < n; i++) {
        char s[16];
        snprintf(s, sizeof s, "%s%d", i ? "," : "", idx[i]);
        append(list, sizeof list, s);
    }
    snprintf(cmd, sizeof cmd, "sbatch --parsable --requeue %s -J partray-tiles --array=%s -o '%s/logs/task-%%A_%%a.log' '%s/task.sh'",
             p->sbatch_opts, list, p->dir, p->dir);
    if (run_capture(cmd, out, sizeof out) != 0) {
        fprintf(stderr, "farm: sbatch failed: %s", out);
        return -1;
    }
    int job = atoi(out);
    snprintf(cmd, sizeof cmd,
             "sbatch --parsable %s -J partray-merge --dependency=afterany:%d -o '%s/logs/merge-%%j.log' '%s/merge.sh'",
             p->sbatch_opts, job, p->dir, p->dir);
    if (run_capture(cmd, out, sizeof out) != 0) {
        fprintf(stderr, "farm: sbatch of the merge job failed: %s", out);
        return -1;
    }
    fprintf(stderr, "farm: slurm array job %d (%d tasks), merge job %d\n", job, n, atoi(out));
    return 0;
}

/* The merge step: merge what is complete; with Slurm resubmit what is
 * missing (up to max_rounds), else report. Writes DIR/state. */
static int merge_step(const char *dir)
{
    farm_plan p;
    if (!load_plan(dir, &p)) {
        fprintf(stderr, "farm: '%s' holds no farm plan\n", dir);
        return 2;
    }
    farm_state s;
    survey(&p, 1, &s);
    char path[2200];
    snprintf(path, sizeof path, "%s/round", p.dir);
    int round = read_int_file(path, 1);
    snprintf(path, sizeof path, "%s/state", p.dir);
    int nframes = p.last - p.first + 1;
    if (s.frames_done == nframes) {
        write_text(path, "done\n");
        return 0;
    }
    if (s.nretry > 0 && round < p.max_rounds && !strcmp(p.engine, "slurm")) {
        for (int i = 0; i < s.nretry; i++) {
            char st[2200];
            snprintf(st, sizeof st, "%s/status/%d", p.dir, s.retry[i]);
            remove(st);
        }
        char rp[2200];
        snprintf(rp, sizeof rp, "%s/round", p.dir);
        write_int_file(rp, round + 1);
        fprintf(stderr, "farm: round %d: %d tasks missing, resubmitted\n", round + 1, s.nretry);
        return slurm_submit(&p, s.retry, s.nretry) == 0 ? 0 : 3;
    }
    if (s.nretry > 0 && !strcmp(p.engine, "slurm")) {
        char t[700];
        snprintf(t, sizeof t, "failed: %d tasks still missing after %d rounds\n", s.nretry, round);
        write_text(path, t);
        return 1;
    }
    if (s.failed || strcmp(p.engine, "slurm") == 0) {
        char t[1300];
        snprintf(t, sizeof t, "failed: %s\n", s.why[0] ? s.why : "frames missing");
        write_text(path, t);
        return 1;
    }
    return 0; /* parallel: the driver decides on another round */
}

static volatile sig_atomic_t g_stop = 0;
static void on_signal(int sig)
{
    g_stop = sig;
}

/* Runs argv as a child, printing progress until it ends; its exit code. */
static int run_with_progress(const farm_plan *p, char *const *argv, double t0, int *last)
{
    pid_t pid = fork();
    if (pid < 0) return -1;
    if (pid == 0) {
        execvp(argv[0], argv);
        _exit(127);
    }
    int status = 0;
    for (;;) {
        pid_t r = waitpid(pid, &status, WNOHANG);
        if (r == pid) break;
        if (r < 0 && errno != EINTR) return -1;
        if (g_stop) kill(pid, SIGTERM);
        farm_state s;
        survey(p, 0, &s);
        farm_report(p, &s, t0, last);
        usleep(200000);
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

static int run_parallel(const farm_plan *p, double t0)
{
    int last = -1;
    farm_state s0;
    survey(p, 1, &s0);
    farm_report(p, &s0, t0, &last);
    if (s0.frames_done == p->last - p->first + 1) return 0;
    for (int round = 1; round <= p->max_rounds && !g_stop; round++) {
        char joblog[2200], tasks[2200], jobs[32], retries[32], rp[2200];
        snprintf(joblog, sizeof joblog, "%s/joblog", p->dir);
        snprintf(tasks, sizeof tasks, "%s/tasks.txt", p->dir);
        snprintf(jobs, sizeof jobs, "%d", p->jobs);
        snprintf(retries, sizeof retries, "%d", p->retries);
        snprintf(rp, sizeof rp, "%s/round", p->dir);
        write_int_file(rp, round);
        /* --resume-failed from the second round: the joblog says what
         * succeeded; a rerun of the farm on this DIR starts there too */
        char *argv[20];
        int n = 0;
        argv[n++] = "parallel";
        argv[n++] = "--will-cite";
        argv[n++] = "--sshloginfile";
        argv[n++] = (char *)p->sshloginfile;
        argv[n++] = "--retries";
        argv[n++] = retries;
        argv[n++] = "--joblog";
        argv[n++] = joblog;
        if (exists(joblog)) argv[n++] = "--resume-failed";
        argv[n++] = "-j";
        argv[n++] = jobs;
        argv[n++] = "-a";
        argv[n++] = tasks;
        argv[n] = NULL;
        int rc = run_with_progress(p, argv, t0, &last);
        fprintf(stderr, "farm: round %d: GNU parallel exit %d\n", round, rc);
        farm_state s;
        survey(p, 1, &s);
        farm_report(p, &s, t0, &last);
        if (s.frames_done == p->last - p->first + 1) return 0;
        if (s.failed && !s.nretry) {
            fprintf(stderr, "farm: %s\n", s.why);
            return 1;
        }
        for (int i = 0; i < s.nretry; i++) {
            char st[2200];
            snprintf(st, sizeof st, "%s/status/%d", p->dir, s.retry[i]);
            remove(st);
        }
    }
    fprintf(stderr, "farm: frames still missing after %d rounds\n", p->max_rounds);
    return 1;
}

static int run_slurm(const farm_plan *p, double t0)
{
    farm_state s;
    survey(p, 1, &s);
    char state[2200];
    snprintf(state, sizeof state, "%s/state", p->dir);
    remove(state);
    if (s.frames_done == p->last - p->first + 1) return 0;
    /* everything not yet there; failed statuses of an earlier run are retried */
    int *idx = malloc(sizeof(int) * (size_t)ntasks(p));
    int n = 0;
    for (int f = p->first; f <= p->last; f++) {
        char out[2200];
        frame_path(p, f, out, sizeof out);
        if (exists(out)) continue;
        for (int t = 0; t < p->tiles; t++) {
            char tp[2200], st[2200];
            tile_path(p, f, t, tp, sizeof tp);
            int i = (f - p->first) * p->tiles + t;
            snprintf(st, sizeof st, "%s/status/%d", p->dir, i);
            remove(st);
            if (!exists(tp)) idx[n++] = i;
        }
    }
    char rp[2200];
    snprintf(rp, sizeof rp, "%s/round", p->dir);
    write_int_file(rp, 1);
    int rc = 0;
    if (n > 0) rc = slurm_submit(p, idx, n);
    else rc = merge_step(p->dir);
    free(idx);
    if (rc) return 3;
    int last = -1;
    for (;;) {
        if (g_stop) {
            fprintf(stderr, "farm: interrupted; the Slurm jobs go on (scancel -n partray-tiles,partray-merge stops them)\n");
            return 130;
        }
        survey(p, 0, &s);
        farm_report(p, &s, t0, &last);
        char *t = subproc_read_text(state, NULL);
        if (t) {
            int done = strncmp(t, "done", 4) == 0;
            if (!done) fprintf(stderr, "farm: %s", t);
            free(t);
            survey(p, 0, &s);
            farm_report(p, &s, t0, &last);
            return done ? 0 : 1;
        }
        if (p->timeout > 0 && timer_now() - t0 > p->timeout) {
            fprintf(stderr, "farm: no result after %.0f s (--timeout)\n", p->timeout);
            return 1;
        }
        usleep(300000);
    }
}

/* ---- planning ---------------------------------------------------------- */

static const char *farm_help =
    "usage: partray farm SCENE.pov|anim.ini [render options] -o OUT.exr|.png|.pfm --dir DIR [--tiles N]\n"
    "                    [--engine parallel|slurm] [--sshloginfile FILE] [--jobs N] [--retries N]\n"
    "                    [--max-rounds N] [--timeout SECONDS] [--sbatch-opts STR]\n"
    "Splits the frames (+KFI +KFF ... as render reads them) into N horizontal tiles each, one\n"
    "idempotent `partray render` task per frame x tile (DIR/tasks.txt), runs them with GNU parallel\n"
    "(--sshloginfile, ':' = this machine, the default) or Slurm (a job array and a merge job),\n"
    "and merges each frame into OUT (numbered as render numbers frames). Tasks already done are\n"
    "skipped, so the same command on the same DIR resumes. A task ending with 130 or 143 is run again.\n"
    "The scene is parsed first (an error stops the farm); with particle GI the tasks share the\n"
    "geometry stage through DIR/gi.gic (--gi-cache, unless the render options name a cache).\n"
    "  --tiles N          tiles per frame (horizontal bands; default 1)\n"
    "  --dir DIR          work directory: plan, tasks, tiles, statuses, logs (default farm)\n"
    "  --engine E         parallel (default) or slurm (sbatch; SLURM_CONF as for sbatch)\n"
    "  --jobs N           parallel: tasks at once per host (default 2)\n"
    "  --retries N        parallel: tries of a task within a round (default 2)\n"
    "  --max-rounds N     rounds of running what is missing (default 3)\n"
    "  --timeout S        slurm: stop waiting after S seconds (the jobs go on)\n"
    "  --sbatch-opts STR  slurm: more sbatch options for every job, e.g. '-p render --time=1:00:00'\n";

int cmd_farm(int argc, char **argv)
{
    if (argc >= 2 && strcmp(argv[0], "--merge-step") == 0) return merge_step(argv[1]);
    if (cli_wants_help(argc, argv)) {
        fputs(farm_help, stdout);
        return 0;
    }
    farm_plan p = {.tiles = 1, .jobs = 2, .retries = 2, .max_rounds = 3};
    snprintf(p.engine, sizeof p.engine, "parallel");
    const char *dir = "farm", *out = NULL, *sshlogin = NULL, *fault = NULL;
    char **rest = calloc((size_t)argc + 1, sizeof *rest);
    int nrest = 0;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        int takes = !strcmp(a, "--tiles") || !strcmp(a, "--dir") || !strcmp(a, "--engine") || !strcmp(a, "--jobs") ||
                    !strcmp(a, "--retries") || !strcmp(a, "--max-rounds") || !strcmp(a, "--sshloginfile") ||
                    !strcmp(a, "--timeout") || !strcmp(a, "--inject-fault") || !strcmp(a, "-o") || !strcmp(a, "--output") ||
                    !strcmp(a, "--sbatch-opts");
        if (takes && !v) {
            fprintf(stderr, "partray farm: option '%s' needs a value\n", a);
            free(rest);
            return 2;
        }
        if (!strcmp(a, "--tiles")) p.tiles = atoi(v);
        else if (!strcmp(a, "--dir")) dir = v;
        else if (!strcmp(a, "--engine")) snprintf(p.engine, sizeof p.engine, "%s", v);
        else if (!strcmp(a, "--jobs")) p.jobs = atoi(v);
        else if (!strcmp(a, "--retries")) p.retries = atoi(v);
        else if (!strcmp(a, "--max-rounds")) p.max_rounds = atoi(v);
        else if (!strcmp(a, "--sshloginfile")) sshlogin = v;
        else if (!strcmp(a, "--timeout")) p.timeout = atof(v);
        else if (!strcmp(a, "--sbatch-opts")) {
            /* given to sbatch through sh: the words of one option list, no
             * quotes or shell characters (the plan file holds one line) */
            if (strpbrk(v, "'\"`$;&|<>\n\\") || strlen(v) >= sizeof p.sbatch_opts) {
                fprintf(stderr, "partray farm: --sbatch-opts wants plain sbatch options (no quotes or shell characters)\n");
                free(rest);
                return 2;
            }
            snprintf(p.sbatch_opts, sizeof p.sbatch_opts, "%s", v);
        }
        /* for tests of the recovery: the first run of task F:T (frame,
         * tile) is sent SIGTERM as it starts, as a preempted job is; the
         * render then stops with exit 143 */
        else if (!strcmp(a, "--inject-fault")) fault = v;
        else if (!strcmp(a, "-o") || !strcmp(a, "--output")) out = v;
        else if (a[0] == '+' && (a[1] == 'O' || a[1] == 'o')) out = a + 2;
        else {
            rest[nrest++] = argv[i];
            takes = 0;
        }
        if (takes) i++;
    }
    if (p.tiles < 1 || p.tiles > FARM_MAX_TILES || p.jobs < 1 || p.retries < 0 || p.max_rounds < 1 ||
        (strcmp(p.engine, "slurm") && strcmp(p.engine, "parallel"))) {
        fprintf(stderr, "partray farm: --tiles 1..%d, --jobs >= 1, --max-rounds >= 1, --engine parallel|slurm\n%s",
                FARM_MAX_TILES, farm_help);
        free(rest);
        return 2;
    }
    /* the render options as render reads them (INI files expanded) */
    diag *d = diag_new();
    ini_args *ia = NULL;
    pt_status st = ini_expand(nrest, rest, &ia, d);
    cli_print_diags(d, 0, 0);
    diag_free(d);
    free(rest);
    if (st != PT_OK) return st == PT_ERR_IO ? 3 : 2;
    cli_render o;
    char err[512];
    anim_plan plan;
    if (cli_parse_render(ini_argc(ia), ini_argv(ia), &o, err, sizeof err) || cli_frames(&o, &plan, err, sizeof err)) {
        fprintf(stderr, "partray farm: %s\n", err);
        ini_free(ia);
        return 2;
    }
    if (o.noutputs > 0 && !out) out = o.outputs[0];
    /* The scene's first frame parsed here: a scene error stops the farm
     * before any task is planned, and with particle GI the tasks share its
     * geometry stage through a GI cache in DIR (unless --gi-cache names
     * one): the tasks that start after the first one's stage is saved
     * (the other tiles of a frame; every task of a fly-through, whose
     * frames share one cache) read it instead of running it. */
    int auto_cache = 0;
    {
        sdl_options so;
        pipeline_sdl_options(&so, &o, o.width > 0 ? o.width : 320, o.height > 0 ? o.height : 240);
        cli_frame_options(&o, &plan, plan.first, &so);
        diag *pd = diag_new();
        scene *sc = NULL;
        pt_status pst = pipeline_parse(o.scene, &so, &sc, pd, NULL);
        if (pst != PT_OK) cli_print_diags(pd, 0, 1);
        diag_free(pd);
        if (pst != PT_OK) {
            if (plan.animated) fprintf(stderr, "partray farm: the scene does not parse (frame %d): nothing planned\n", plan.first);
            else fprintf(stderr, "partray farm: the scene does not parse: nothing planned\n");
            ini_free(ia);
            return pst == PT_ERR_IO ? 3 : 1;
        }
        auto_cache = !o.gi_cache && pipeline_gi_mode(o.gi, sc, o.quality) == GI_PARTICLE;
        scene_free(sc);
    }
    p.width = o.width > 0 ? o.width : 320;
    p.height = o.height > 0 ? o.height : 240;
    if (p.tiles > p.height || (p.tiles > 1 && p.height / p.tiles < 2)) {
        fprintf(stderr, "partray farm: %d tiles of a %d-row image: each tile needs 2 rows at least\n", p.tiles, p.height);
        ini_free(ia);
        return 2;
    }
    p.first = plan.first;
    p.last = plan.last;
    p.digits = plan.digits;
    p.animated = plan.animated;
    char real[PATH_MAX];
    if (!subproc_mkdirs(dir) || !realpath(dir, real) || strlen(real) >= sizeof p.dir ||
        !subproc_self_exe(p.partray, sizeof p.partray)) {
        fprintf(stderr, "partray farm: cannot make the work directory '%s': %s\n", dir, strerror(errno));
        ini_free(ia);
        return 3;
    }
    memcpy(p.dir, real, strlen(real) + 1);
    char cwd[2048];
    if (!getcwd(cwd, sizeof cwd)) cwd[0] = 0;
    if (!out) snprintf(p.output, sizeof p.output, "%s/frame.exr", p.dir);
    else if (out[0] == '/') snprintf(p.output, sizeof p.output, "%s", out);
    else snprintf(p.output, sizeof p.output, "%s/%s", cwd, out);
    if (img_format_from_path(p.output) == IMG_FMT_UNKNOWN) {
        fprintf(stderr, "partray farm: output '%s': unknown format (use .exr, .png or .pfm)\n", p.output);
        ini_free(ia);
        return 2;
    }
    if (sshlogin) {
        if (!realpath(sshlogin, real) || strlen(real) >= sizeof p.sshloginfile) {
            fprintf(stderr, "partray farm: --sshloginfile '%s': %s\n", sshlogin, strerror(errno));
            ini_free(ia);
            return 3;
        }
        memcpy(p.sshloginfile, real, strlen(real) + 1);
    } else {
        snprintf(p.sshloginfile, sizeof p.sshloginfile, "%s/sshloginfile", p.dir);
        write_text(p.sshloginfile, ":\n"); /* this machine */
    }
    char sub[2200];
    const char *subs[] = {"tiles", "status", "logs"};
    for (int i = 0; i < 3; i++) {
        snprintf(sub, sizeof sub, "%s/%s", p.dir, subs[i]);
        subproc_mkdirs(sub);
    }
    int fault_frame = -1, fault_tile = -1;
    if (fault && sscanf(fault, "%d:%d", &fault_frame, &fault_tile) != 2) {
        fprintf(stderr, "partray farm: --inject-fault wants FRAME:TILE\n");
        ini_free(ia);
        return 2;
    }
    /* the tasks: one line each, in frame-major order (index = line - 1) */
    size_t cap = 1 << 16;
    char *tasks = malloc(cap);
    tasks[0] = 0;
    char base[16384] = "";
    quote(base, sizeof base, p.partray);
    append(base, sizeof base, " render");
    for (int i = 0; i < ini_argc(ia); i++) {
        const char *a = ini_argv(ia)[i];
        if (!strcmp(a, "-o") || !strcmp(a, "--output")) { i++; continue; }
        if ((a[0] == '+' || a[0] == '-') && (a[1] == 'O' || a[1] == 'o') && a[2]) continue;
        append(base, sizeof base, " ");
        quote(base, sizeof base, a);
    }
    if (auto_cache) {
        char gc[2300];
        snprintf(gc, sizeof gc, "%s/gi.gic", p.dir);
        append(base, sizeof base, " --gi-cache ");
        quote(base, sizeof base, gc);
    }
    for (int f = p.first; f <= p.last; f++) {
        for (int t = 0; t < p.tiles; t++) {
            int idx = (f - p.first) * p.tiles + t;
            int y0 = t * p.height / p.tiles, y1 = (t + 1) * p.height / p.tiles;
            char tp[2200], ta[2200], line[20000], render[18000], statusp[2200];
            tile_path(&p, f, t, tp, sizeof tp);
            tile_arg(&p, t, ta, sizeof ta);
            snprintf(statusp, sizeof statusp, "%s/status/%d", p.dir, idx);
            snprintf(render, sizeof render, "%s", base);
            char w[96];
            if (p.animated) {
                snprintf(w, sizeof w, " --frame %d", f);
                append(render, sizeof render, w);
            }
            /* rows in pixels, 1-based and inclusive (+SR/+ER); y1 >= 2 */
            snprintf(w, sizeof w, " +SR%d +ER%d --float -q -o ", y0 + 1, y1);
            append(render, sizeof render, w);
            quote(render, sizeof render, ta);
            line[0] = 0;
            append(line, sizeof line, "cd ");
            quote(line, sizeof line, cwd);
            /* done when the tile, or its merged frame, is there */
            char fp[2200];
            frame_path(&p, f, fp, sizeof fp);
            append(line, sizeof line, " || exit 1; if [ -e ");
            quote(line, sizeof line, tp);
            append(line, sizeof line, " ] || [ -e ");
            quote(line, sizeof line, fp);
            append(line, sizeof line, " ]; then rc=0; else ");
            if (f == fault_frame && t == fault_tile) {
                char fd[2300];
                snprintf(fd, sizeof fd, "%s/fault.%d", p.dir, idx);
                append(line, sizeof line, "if mkdir '");
                append(line, sizeof line, fd);
                append(line, sizeof line, "' 2>/dev/null; then ");
                append(line, sizeof line, render);
                /* no wait before the signal: a render shorter than any wait
                 * (64x48 tiles take 0.15 s) would finish first and exit 0 */
                append(line, sizeof line, " & p=$!; kill -TERM $p; wait $p; rc=$?; else ");
                append(line, sizeof line, render);
                append(line, sizeof line, "; rc=$?; fi");
            } else {
                append(line, sizeof line, render);
                append(line, sizeof line, "; rc=$?");
            }
            /* the last exit in status/INDEX, every attempt's in INDEX.history */
            append(line, sizeof line, "; fi; echo $rc >> ");
            quote(line, sizeof line, statusp);
            append(line, sizeof line, ".history; echo $rc > ");
            quote(line, sizeof line, statusp);
            append(line, sizeof line, "; exit $rc\n");
            if (strlen(tasks) + strlen(line) + 1 > cap) {
                cap = (cap + strlen(line)) * 2;
                tasks = realloc(tasks, cap);
            }
            strcat(tasks, line);
        }
    }
    ini_free(ia);
    char path[2200], script[8192];
    snprintf(path, sizeof path, "%s/tasks.txt", p.dir);
    int ok = write_text(path, tasks);
    free(tasks);
    snprintf(path, sizeof path, "%s/task.sh", p.dir);
    snprintf(script, sizeof script,
             "#!/bin/sh\n# one task of the farm: line SLURM_ARRAY_TASK_ID + 1 of tasks.txt\n"
             "exec sh -c \"$(sed -n \"$((SLURM_ARRAY_TASK_ID + 1))p\" '%s/tasks.txt')\"\n",
             p.dir);
    ok &= write_text(path, script);
    chmod(path, 0755);
    snprintf(path, sizeof path, "%s/merge.sh", p.dir);
    snprintf(script, sizeof script, "#!/bin/sh\nexec '%s' farm --merge-step '%s'\n", p.partray, p.dir);
    ok &= write_text(path, script);
    chmod(path, 0755);
    ok &= save_plan(&p);
    if (!ok) {
        fprintf(stderr, "partray farm: cannot write the plan into '%s'\n", p.dir);
        return 3;
    }
    fprintf(stderr, "farm: %d frames x %d tiles = %d tasks in %s/tasks.txt, engine %s\n", p.last - p.first + 1, p.tiles,
            ntasks(&p), p.dir, p.engine);
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    double t0 = timer_now();
    int rc = !strcmp(p.engine, "slurm") ? run_slurm(&p, t0) : run_parallel(&p, t0);
    if (rc == 0) fprintf(stderr, "farm: all %d frames in %.1f s\n", p.last - p.first + 1, timer_now() - t0);
    return rc;
}
