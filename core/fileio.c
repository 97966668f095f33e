/* fileio.c - see fileio.h. */
#include "fileio.h"
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>

char *pt_read_file(const char *path, int regular_only, size_t max, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    struct stat st;
    if (fstat(fileno(f), &st) != 0 || (regular_only && !S_ISREG(st.st_mode))) {
        fclose(f);
        errno = EINVAL;
        return NULL;
    }
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap);
    int err = buf ? 0 : ENOMEM;
    while (buf) {
        size_t got = fread(buf + n, 1, cap - 1 - n, f); /* one byte kept for the NUL */
        n += got;
        if (n > max) {
            err = EFBIG;
            break;
        }
        if (n < cap - 1) break;
        char *nb = realloc(buf, cap * 2);
        if (!nb) {
            err = ENOMEM;
            break;
        }
        buf = nb;
        cap *= 2;
    }
    if (!err && ferror(f)) err = EIO;
    fclose(f);
    if (err) {
        free(buf);
        errno = err;
        return NULL;
    }
    buf[n] = 0;
    if (len) *len = n;
    return buf;
}
