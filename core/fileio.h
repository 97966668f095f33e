/* fileio.h - the one whole-file reader (scene sources, #read files, GI
 * caches, tool outputs). */
#ifndef PT_FILEIO_H
#define PT_FILEIO_H
#include <stddef.h>

/* The whole file at path, malloc'd, with a NUL byte after its *len bytes
 * (text callers may treat it as a string), or NULL with errno set: the
 * fopen/fread error, EINVAL when regular_only and the path is not a regular
 * file (a FIFO or /dev/zero would block or never end), EFBIG when it holds
 * more than max bytes (reading stops there), ENOMEM. */
char *pt_read_file(const char *path, int regular_only, size_t max, size_t *len);

#endif
