#include "pngfile.h"

#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "log.h"

enum sb_result sb_png_write(const char *path, uint32_t width, uint32_t height, const uint8_t *rgba)
{
    char tmp[4200];
    snprintf(tmp, sizeof(tmp), "%s.tmp-%ld", path, (long)getpid());
    png_image image;
    memset(&image, 0, sizeof(image));
    image.version = PNG_IMAGE_VERSION;
    image.width = width;
    image.height = height;
    image.format = PNG_FORMAT_RGBA;
    /* flags 0: the pixels are sRGB-encoded, and libpng says so in the file */
    if (!png_image_write_to_file(&image, tmp, 0, rgba, 0, NULL)) {
        sb_error("%s: cannot write the PNG: %s", path, image.message);
        unlink(tmp);
        return SB_ERR_IO;
    }
    if (rename(tmp, path) != 0) {
        sb_error("%s: cannot rename %s into place", path, tmp);
        unlink(tmp);
        return SB_ERR_IO;
    }
    return SB_OK;
}
