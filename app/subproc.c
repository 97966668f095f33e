/* subproc.c - fork/exec a child with its output in a log file. */
#include "subproc.h"
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "fileio.h"
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>
#include "timer.h"

int subproc_find_program(const char *name, char *buf, size_t n)
{
    if (!name || !*name) return 0;
    if (strchr(name, '/')) {
        if (access(name, X_OK) != 0) return 0;
        snprintf(buf, n, "%s", name);
        return 1;
    }
    const char *path = getenv("PATH");
    if (!path) path = "/usr/local/bin:/usr/bin:/bin";
    while (*path) {
        const char *colon = strchr(path, ':');
        size_t len = colon ? (size_t)(colon - path) : strlen(path);
        char cand[4096];
        if (len == 0)
            snprintf(cand, sizeof cand, "./%s", name);
        else
            snprintf(cand, sizeof cand, "%.*s/%s", (int)len, path, name);
        struct stat sb;
        if (stat(cand, &sb) == 0 && S_ISREG(sb.st_mode) && access(cand, X_OK) == 0) {
            snprintf(buf, n, "%s", cand);
            return 1;
        }
        if (!colon) break;
        path = colon + 1;
    }
    return 0;
}

static volatile sig_atomic_t g_child = 0;

void subproc_forward_signal(int sig)
{
    pid_t pid = (pid_t)g_child;
    if (pid > 0) kill(pid, sig);
}

int subproc_self_exe(char *buf, size_t n)
{
    if (n < 2) return 0;
    ssize_t k = readlink("/proc/self/exe", buf, n - 1);
    if (k <= 0 || (size_t)k >= n - 1) return 0;
    buf[k] = 0;
    return 1;
}

int subproc_run(const char *const *argv, const char *cwd, const char *log_path, double *seconds, diag *d)
{
    if (seconds) *seconds = 0.0;
    if (!argv || !argv[0]) {
        diag_error(d, "no program to run");
        return -1;
    }
    char prog[4096];
    if (!subproc_find_program(argv[0], prog, sizeof prog)) {
        diag_error(d, "cannot find program '%s'", argv[0]);
        return -1;
    }
    int logfd = -1;
    if (log_path) {
        logfd = open(log_path, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0666);
        if (logfd < 0) {
            diag_error(d, "cannot open log file '%s': %s", log_path, strerror(errno));
            return -1;
        }
    }
    fflush(stdout);
    fflush(stderr);
    double t0 = timer_now();
    pid_t pid = fork();
    if (pid < 0) {
        diag_error(d, "cannot start '%s': %s", prog, strerror(errno));
        if (logfd >= 0) close(logfd);
        return -1;
    }
    if (pid == 0) {
        int nul = open("/dev/null", O_RDONLY);
        if (nul >= 0) dup2(nul, 0);
        if (logfd >= 0) {
            dup2(logfd, 1);
            dup2(logfd, 2);
        }
        if (cwd && chdir(cwd) != 0) _exit(126);
        execv(prog, (char *const *)argv);
        _exit(127);
    }
    if (logfd >= 0) close(logfd);
    g_child = (sig_atomic_t)pid;
    int status = 0;
    while (waitpid(pid, &status, 0) < 0) {
        if (errno != EINTR) {
            g_child = 0;
            diag_error(d, "waiting for '%s': %s", prog, strerror(errno));
            return -1;
        }
    }
    g_child = 0;
    if (seconds) *seconds = timer_now() - t0;
    if (WIFEXITED(status)) {
        int rc = WEXITSTATUS(status);
        if (rc == 126 && cwd) diag_error(d, "'%s': cannot enter directory '%s'", prog, cwd);
        if (rc == 127) diag_error(d, "'%s' could not be executed", prog);
        return rc;
    }
    if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
    return -1;
}

char *subproc_read_text(const char *path, size_t *len)
{
    return pt_read_file(path, 0, (size_t)-1, len);
}

int subproc_mkdirs(const char *path)
{
    char tmp[4096];
    if (!path || !*path || strlen(path) >= sizeof tmp) return 0;
    snprintf(tmp, sizeof tmp, "%s", path);
    for (char *p = tmp + 1; *p; p++) {
        if (*p != '/') continue;
        *p = 0;
        if (mkdir(tmp, 0777) != 0 && errno != EEXIST) return 0;
        *p = '/';
    }
    if (mkdir(tmp, 0777) != 0 && errno != EEXIST) return 0;
    struct stat sb;
    return stat(tmp, &sb) == 0 && S_ISDIR(sb.st_mode);
}
