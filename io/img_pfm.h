/* img_pfm.h - Portable Float Map files ("PF" colour, "Pf" greyscale). */
#ifndef PT_IMG_PFM_H
#define PT_IMG_PFM_H
#include "img_io.h"

/* Write "PF\n<w> <h>\n-1.0\n" and little-endian float RGB rows, bottom row
 * first as the format requires, to the open file `fd` (the caller closes it).
 * Non-finite values are written as 0; alpha is dropped. */
pt_status img_pfm_write(int fd, const char *name, const framebuffer *fb, diag *d);

/* Read "PF" (RGB) or "Pf" (grey, replicated to RGB); a negative scale means
 * little-endian data, a positive one big-endian. The |scale| is not applied. */
/* At most max_pixels pixels (img_read_limited). */
pt_status img_pfm_read(const char *path, uint64_t max_pixels, framebuffer **out, diag *d);

#endif
