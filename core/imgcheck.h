/* imgcheck.h - checks of an image file's declared size, made before any
 * pixel memory is allocated; shared by io/ (img_read) and parser/
 * (image_map, height_field images), which read the same formats.
 *
 * A corrupt or truncated file may declare any size in a few bytes; the
 * readers ask these first, so such a file is a clear error rather than a
 * multi-gigabyte allocation. Every function returns 0 when the file may be
 * read, else 1 with a reason (no file name) in `why`. */
#ifndef PT_IMGCHECK_H
#define PT_IMGCHECK_H
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/* Hard limits of every reader (a side, pixels in all); a caller's limit
 * (e.g. --max-image-pixels) may only be lower. */
#define IMGCHECK_MAX_SIDE 65536
#define IMGCHECK_MAX_PIXELS (1ull << 28)

/* w x h against the side limit and max_pixels (0 = IMGCHECK_MAX_PIXELS). */
int imgcheck_size(uint64_t w, uint64_t h, uint64_t max_pixels, char *why, size_t whycap);

/* Walks a PNG file's chunk list (f positioned anywhere; rewound to the
 * start on return): the signature, IHDR first, every chunk inside the file,
 * IEND present, the declared size within the limits, and enough IDAT bytes
 * for the declared image: zlib's deflate cannot expand data more than 1032
 * to 1 (RFC 1951: a 258-byte match coded in 2 bits), so a file whose image
 * data could not inflate to w x h pixels is truncated or corrupt. */
int imgcheck_png(FILE *f, uint64_t max_pixels, char *why, size_t whycap);

#endif
