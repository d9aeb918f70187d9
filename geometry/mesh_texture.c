#include "mesh_texture.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <png.h>
#include <setjmp.h>
#include <stdio.h> /* before jpeglib.h, which needs FILE */
#include <jpeglib.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io.h"
#include "log.h"

static enum sb_result check_size(uint32_t width, uint32_t height, const char *model, const char *name)
{
    if (!width || !height || width > SB_TEXTURE_MAX_SIDE || height > SB_TEXTURE_MAX_SIDE) {
        sb_error("%s: image %s: %u x %u texels; images are read from 1 x 1 to %u x %u", model, name, width, height,
                 SB_TEXTURE_MAX_SIDE, SB_TEXTURE_MAX_SIDE);
        return SB_ERR_TOO_LARGE;
    }
    return SB_OK;
}

static enum sb_result decode_png(const void *bytes, size_t size, const char *model, struct sb_mesh_texture *t)
{
    png_image image = {.version = PNG_IMAGE_VERSION};
    if (!png_image_begin_read_from_memory(&image, bytes, size)) {
        sb_error("%s: image %s: libpng cannot read it: %s", model, t->name, image.message);
        return SB_ERR_IO;
    }
    enum sb_result res = check_size(image.width, image.height, model, t->name);
    if (res) {
        png_image_free(&image);
        return res;
    }
    image.format = PNG_FORMAT_RGBA; /* any of PNG's layouts, 8 bits a channel */
    t->width = image.width;
    t->height = image.height;
    t->rgba = malloc(sb_texture_bytes(t));
    if (!t->rgba) {
        png_image_free(&image);
        return SB_ERR_NOMEM;
    }
    if (!png_image_finish_read(&image, NULL, t->rgba, 0, NULL)) {
        sb_error("%s: image %s: libpng cannot read it: %s", model, t->name, image.message);
        free(t->rgba);
        t->rgba = NULL;
        return SB_ERR_IO;
    }
    return SB_OK;
}

struct jpeg_failure {
    struct jpeg_error_mgr manager;
    jmp_buf back;
    char message[JMSG_LENGTH_MAX];
};

static void jpeg_fail(j_common_ptr info)
{
    struct jpeg_failure *f = (struct jpeg_failure *)info->err;
    info->err->format_message(info, f->message);
    longjmp(f->back, 1);
}

static void jpeg_quiet(j_common_ptr info)
{
    (void)info; /* warnings: a corrupt image then fails or decodes; either is reported */
}

static enum sb_result decode_jpeg(const void *bytes, size_t size, const char *model, struct sb_mesh_texture *t)
{
    struct jpeg_decompress_struct info;
    struct jpeg_failure failure = {0};
    info.err = jpeg_std_error(&failure.manager);
    failure.manager.error_exit = jpeg_fail;
    failure.manager.output_message = jpeg_quiet;
    /* volatile: set between setjmp and a longjmp back to it */
    uint8_t *volatile rgba = NULL;
    volatile enum sb_result res = SB_OK;
    if (setjmp(failure.back)) {
        sb_error("%s: image %s: libjpeg cannot decode it: %s", model, t->name, failure.message);
        res = SB_ERR_IO;
        goto done;
    }
    jpeg_create_decompress(&info);
    jpeg_mem_src(&info, bytes, (unsigned long)size);
    jpeg_read_header(&info, TRUE);
    if ((res = check_size(info.image_width, info.image_height, model, t->name)))
        goto done;
    if (info.num_components != 1 && info.num_components != 3) {
        sb_error("%s: image %s: a JPEG of %d colour components; grey (1) and colour (3) are read", model, t->name,
                 info.num_components);
        res = SB_ERR_IO;
        goto done;
    }
    info.out_color_space = JCS_EXT_RGBA;
    jpeg_start_decompress(&info);
    t->width = info.output_width;
    t->height = info.output_height;
    rgba = malloc(sb_texture_bytes(t));
    if (!rgba) {
        res = SB_ERR_NOMEM;
        goto done;
    }
    while (info.output_scanline < info.output_height) {
        JSAMPROW row = rgba + (size_t)info.output_scanline * 4 * t->width;
        jpeg_read_scanlines(&info, &row, 1);
    }
    jpeg_finish_decompress(&info);
    if (failure.manager.num_warnings) { /* libjpeg fills a truncated image with grey and warns */
        sb_error("%s: image %s: a truncated or corrupt JPEG", model, t->name);
        res = SB_ERR_IO;
    }
done:
    jpeg_destroy_decompress(&info);
    if (res)
        free(rgba);
    else
        t->rgba = rgba;
    return res;
}

enum sb_result sb_texture_decode(const void *bytes, size_t size, const char *model, struct sb_mesh_texture *texture)
{
    static const uint8_t png_signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    const uint8_t *b = bytes;
    texture->rgba = NULL;
    if (size >= 8 && !memcmp(b, png_signature, 8))
        return decode_png(bytes, size, model, texture);
    if (size >= 3 && b[0] == 0xff && b[1] == 0xd8 && b[2] == 0xff)
        return decode_jpeg(bytes, size, model, texture);
    sb_error("%s: image %s: neither PNG nor JPEG (%zu bytes)", model, texture->name, size);
    return SB_ERR_IO;
}

/* `image` relative to the model's folder, refused if it could lead out. */
static enum sb_result resolve(const char *model_path, const char *image, char *path, size_t size)
{
    int depth = 0;
    bool escapes = image[0] == '/' || !image[0];
    for (const char *p = image; *p && !escapes;) {
        size_t n = strcspn(p, "/");
        if (n == 2 && p[0] == '.' && p[1] == '.')
            escapes = --depth < 0;
        else if (n && !(n == 1 && p[0] == '.'))
            depth++;
        p += n + (p[n] == '/');
    }
    if (escapes) {
        sb_error("%s: image %s: lies outside the model's folder; images are read from beside the model", model_path,
                 image);
        return SB_ERR_UNSAFE_PATH;
    }
    const char *slash = strrchr(model_path, '/');
    int folder = slash ? (int)(slash - model_path) : 1;
    if (snprintf(path, size, "%.*s/%s", folder, slash ? model_path : ".", image) >= (int)size) {
        sb_error("%s: image %s: its path is too long", model_path, image);
        return SB_ERR_IO;
    }
    /* and no link inside the folder leads out of it */
    char real_folder[PATH_MAX], real_image[PATH_MAX], folder_path[PATH_MAX];
    snprintf(folder_path, sizeof(folder_path), "%.*s", folder, slash ? model_path : ".");
    if (!realpath(folder_path, real_folder) || !realpath(path, real_image)) {
        sb_error("%s: image %s: cannot read it: %s", model_path, image, strerror(errno));
        return SB_ERR_IO;
    }
    size_t n = strlen(real_folder);
    if (strncmp(real_image, real_folder, n) != 0 || (real_image[n] != '/' && strcmp(real_folder, "/") != 0)) {
        sb_error("%s: image %s: a link to %s, outside the model's folder", model_path, image, real_image);
        return SB_ERR_UNSAFE_PATH;
    }
    return SB_OK;
}

enum sb_result sb_texture_read(const char *model_path, const char *image, struct sb_mesh_texture *texture)
{
    texture->rgba = NULL;
    if (snprintf(texture->name, sizeof(texture->name), "%s", image) >= (int)sizeof(texture->name)) {
        sb_error("%s: image %s: a name of %zu bytes; at most %d", model_path, image, strlen(image),
                 SB_TEXTURE_NAME_MAX - 1);
        return SB_ERR_IO;
    }
    char path[PATH_MAX];
    enum sb_result res = resolve(model_path, image, path, sizeof(path));
    if (res)
        return res;
    char source[PATH_MAX + 64];
    snprintf(source, sizeof(source), "%s: image %s", model_path, image);
    char *bytes = NULL;
    size_t size = 0;
    res = sb_read_file(AT_FDCWD, path, source, SB_TEXTURE_MAX_FILE_BYTES, true, &bytes, &size);
    if (res)
        return res == SB_ERR_OUT_OF_RANGE ? SB_ERR_TOO_LARGE : res;
    res = sb_texture_decode(bytes, size, model_path, texture);
    free(bytes);
    return res;
}
