/*
 * Cube maps with their mip chains as EXR (exr.h): one tiled, mip-mapped
 * part a cube, the faces stacked as OpenEXR's envmap convention has them.
 */
#include <openexr.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "exr.h"
#include "exr_internal.h"
#include "log.h"

#define CUBE_TILE 64

uint32_t sb_cube_levels(uint32_t face_size)
{
    uint32_t levels = 1;
    while (face_size >> levels)
        levels++;
    return levels;
}

/* Where level `level` of cube `cube` starts in the image, and its width. */
static float *level_base(const struct sb_image *image, uint32_t cube, uint32_t level, uint32_t *width)
{
    uint32_t w = sb_image_level_size(image->width, level), h = sb_image_level_size(image->height, level);
    *width = w;
    return image->data + sb_image_level_offset(image, level) + (size_t)cube * h * w * image->channel_count;
}

/*
 * OpenEXR's mip chain goes on until the 6N-tall image is one pixel: two
 * levels past the cube's 1 x 6, which are no cube. skybake fills them
 * with means of the level above, 1 x 3 (pairs of faces) and 1 x 1 (the
 * three), computed the same way by the writer and the reader, which
 * refuses a file whose tail differs: the file holds nothing the content
 * hash does not vouch for.
 */
#define CUBE_TAIL_LEVELS 2
static void cube_tail(const float *faces, uint32_t channels, float *tail)
{
    for (uint32_t c = 0; c < channels; c++) {
        for (int y = 0; y < 3; y++)
            tail[y * channels + c] = (faces[2 * y * channels + c] + faces[(2 * y + 1) * channels + c]) * 0.5f;
        tail[3 * channels + c] = (tail[c] + tail[channels + c] + tail[2 * channels + c]) / 3.0f;
    }
}

/* Tiles across and down a level. */
static exr_result_t tile_counts(exr_const_context_t ctxt, int part, int level, int32_t *tiles_x, int32_t *tiles_y,
                                int32_t *tw, int32_t *th)
{
    int32_t w = 0, h = 0;
    exr_result_t rv = exr_get_level_sizes(ctxt, part, level, level, &w, &h);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_get_tile_sizes(ctxt, part, level, level, tw, th);
    if (rv == EXR_ERR_SUCCESS && (*tw <= 0 || *th <= 0))
        rv = EXR_ERR_INVALID_ATTR;
    if (rv == EXR_ERR_SUCCESS) {
        *tiles_x = (w + *tw - 1) / *tw;
        *tiles_y = (h + *th - 1) / *th;
    }
    return rv;
}

/* One part's tiles for sb_exr_write_chunks, in the file's order. */
struct cube_tile {
    int32_t level, tx, ty;
    float *base; /* the level's first pixel */
    uint32_t width;
    int32_t x0, y0; /* the tile's first pixel in its level */
};

struct cube_tiles {
    const struct sb_image *image;
    struct cube_tile *tile;
    float tail[4 * SB_IMAGE_MAX_CHANNELS]; /* the two levels past the cube (cube_tail) */
};

static exr_result_t tile_info(void *user, exr_context_t ctxt, int part, int index, exr_chunk_info_t *cinfo)
{
    const struct cube_tile *t = &((const struct cube_tiles *)user)->tile[index];
    return exr_write_tile_chunk_info(ctxt, part, t->tx, t->ty, t->level, t->level, cinfo);
}

static bool point_tile(void *user, int index, exr_coding_channel_info_t *channels, int16_t count)
{
    const struct cube_tiles *tiles = user;
    const struct cube_tile *t = &tiles->tile[index];
    return sb_exr_point_channels(channels, count, tiles->image, t->base, t->width, t->x0, t->y0, false);
}

static bool is_cube_image(const struct sb_image *image)
{
    uint32_t n = image->width;
    return n && !(n & (n - 1)) && image->height == 6 * n && image->levels == sb_cube_levels(n) && image->depth;
}

enum sb_result sb_exr_cube_write(const char *path, const struct sb_image *image, const struct sb_attribute *attributes,
                                 int attribute_count)
{
    if (!is_cube_image(image)) {
        sb_error("%s: %ux%ux%u with %u levels is not a cube array with its mip chain", path, image->width,
                 image->height, image->depth, image->levels);
        return SB_ERR_BAD_IMAGE;
    }
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = sb_exr_error_handler;
    exr_context_t ctxt = NULL;
    enum sb_result res = SB_OK;
    exr_result_t rv = exr_start_write(&ctxt, path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv != EXR_ERR_SUCCESS) {
        sb_error("%s: cannot create EXR file: %s", path, exr_get_default_error_message(rv));
        return SB_ERR_IO;
    }
    /* Tiles 1.5 times as tall as wide: every level's height (3 2^m) is then
     * a whole number of tiles or less than one, as its width (2^m) is.
     * OpenEXR 3.1's writer sizes a level's last row of tiles wrongly when
     * it is cut short (it claims the full tile height), which its reader
     * rightly refuses. */
    uint32_t tile_x = image->width < CUBE_TILE ? image->width : CUBE_TILE;
    uint32_t tile_y = tile_x > 1 ? 3 * tile_x / 2 : 1;
    for (uint32_t cube = 0; cube < image->depth; cube++) {
        char name[32];
        int part = 0;
        snprintf(name, sizeof(name), "cube.%u", cube);
        SB_EXR_TRY(exr_add_part(ctxt, name, EXR_STORAGE_TILED, &part), "adding a part");
        SB_EXR_TRY(exr_initialize_required_attr_simple(ctxt, part, (int32_t)image->width, (int32_t)image->height,
                                                       EXR_COMPRESSION_ZIP),
                   "setting the header");
        SB_EXR_TRY(exr_set_tile_descriptor(ctxt, part, tile_x, tile_y, EXR_TILE_MIPMAP_LEVELS, EXR_TILE_ROUND_DOWN),
                   "setting the tiles");
        SB_EXR_TRY(exr_attr_set_envmap(ctxt, part, "envmap", EXR_ENVMAP_CUBE), "setting envmap");
        for (uint32_t c = 0; c < image->channel_count; c++)
            SB_EXR_TRY(
                exr_add_channel(ctxt, part, image->channel_names[c], EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LINEAR, 1, 1),
                "adding a channel");
        for (int a = 0; a < attribute_count; a++)
            SB_EXR_TRY(exr_attr_set_string(ctxt, part, attributes[a].name, attributes[a].value),
                       "setting an attribute");
    }
    SB_EXR_TRY(exr_write_header(ctxt), "writing the header");
    for (uint32_t cube = 0; cube < image->depth && !res; cube++) {
        int part = (int)cube;
        int32_t levels_x = 0, levels_y = 0;
        SB_EXR_TRY(exr_get_tile_levels(ctxt, part, &levels_x, &levels_y), "querying levels");
        if ((uint32_t)levels_x != image->levels + CUBE_TAIL_LEVELS) {
            sb_error("%s: OpenEXR makes %d levels of a %u cube, skybake %u", path, levels_x, image->width,
                     image->levels + CUBE_TAIL_LEVELS);
            res = SB_ERR_EXR;
            goto cleanup;
        }
        int32_t count = 0;
        SB_EXR_TRY(exr_get_chunk_count(ctxt, part, &count), "querying chunks");
        struct cube_tiles tiles = {.image = image, .tile = calloc(count > 0 ? (size_t)count : 1, sizeof(*tiles.tile))};
        if (!tiles.tile) {
            res = SB_ERR_NOMEM;
            goto cleanup;
        }
        uint32_t last_width;
        cube_tail(level_base(image, cube, image->levels - 1, &last_width), image->channel_count, tiles.tail);
        /* The tiles in the file's order: level by level, row by row. */
        int32_t n = 0;
        for (uint32_t level = 0; level < (uint32_t)levels_x && !res; level++) {
            uint32_t width = 1;
            float *base = level < image->levels ? level_base(image, cube, level, &width)
                                                : tiles.tail + (level > image->levels ? 3 * image->channel_count : 0);
            int32_t tiles_x = 0, tiles_y = 0, tw = 0, th = 0;
            exr_result_t trv = tile_counts(ctxt, part, (int)level, &tiles_x, &tiles_y, &tw, &th);
            if (trv != EXR_ERR_SUCCESS)
                res = sb_exr_fail(path, "querying tiles", trv);
            for (int32_t ty = 0; ty < tiles_y && !res; ty++)
                for (int32_t tx = 0; tx < tiles_x && n < count; tx++)
                    tiles.tile[n++] = (struct cube_tile){(int32_t)level, tx, ty, base, width, tx * tw, ty * th};
        }
        if (!res && n != count) {
            sb_error("%s: OpenEXR counts %d tiles in cube %u, skybake %d", path, count, cube, n);
            res = SB_ERR_EXR;
        }
        const struct sb_exr_chunks each = {.info = tile_info, .point = point_tile, .user = &tiles};
        if (!res)
            res = sb_exr_write_chunks(ctxt, path, part, count, &each);
        free(tiles.tile);
    }
cleanup:
    rv = exr_finish(&ctxt);
    if (rv != EXR_ERR_SUCCESS && res == SB_OK) {
        sb_error("%s: finishing the EXR file: %s", path, exr_get_default_error_message(rv));
        res = SB_ERR_IO;
    }
    return res;
}

/* Part `part` must be what sb_exr_cube_write makes of a face_size cube
 * with `channels`, before anything is allocated. */
static enum sb_result check_part(exr_context_t ctxt, const char *path, int part, uint32_t face_size,
                                 const struct sb_image *channels)
{
    enum sb_result res = SB_OK;
    exr_storage_t storage;
    SB_EXR_TRY(exr_get_storage(ctxt, part, &storage), "reading the storage type");
    if (storage != EXR_STORAGE_TILED) {
        sb_error("%s: part %d: not a tiled image", path, part);
        return SB_ERR_BAD_IMAGE;
    }
    uint32_t tw = 0, th = 0;
    exr_tile_level_mode_t mode;
    exr_tile_round_mode_t round;
    SB_EXR_TRY(exr_get_tile_descriptor(ctxt, part, &tw, &th, &mode, &round), "reading the tiles");
    if (mode != EXR_TILE_MIPMAP_LEVELS || round != EXR_TILE_ROUND_DOWN || !tw || !th || tw > 4096 || th > 4096) {
        sb_error("%s: part %d: not mip-mapped with level sizes rounded down (tiles %ux%u)", path, part, tw, th);
        return SB_ERR_BAD_IMAGE;
    }
    exr_envmap_t envmap = EXR_ENVMAP_LATLONG;
    if (exr_attr_get_envmap(ctxt, part, "envmap", &envmap) != EXR_ERR_SUCCESS || envmap != EXR_ENVMAP_CUBE) {
        sb_error("%s: part %d: no envmap attribute saying cube", path, part);
        return SB_ERR_BAD_IMAGE;
    }
    exr_attr_box2i_t window;
    SB_EXR_TRY(exr_get_data_window(ctxt, part, &window), "reading the data window");
    if (window.min.x != 0 || window.min.y != 0 || (int64_t)window.max.x + 1 != face_size ||
        (int64_t)window.max.y + 1 != 6 * (int64_t)face_size) {
        sb_error("%s: part %d: data window (%d %d) - (%d %d), expected (0 0) - (%u %u)", path, part, window.min.x,
                 window.min.y, window.max.x, window.max.y, face_size - 1, 6 * face_size - 1);
        return SB_ERR_BAD_IMAGE;
    }
    int32_t levels_x = 0, levels_y = 0;
    SB_EXR_TRY(exr_get_tile_levels(ctxt, part, &levels_x, &levels_y), "reading the levels");
    if ((uint32_t)levels_x != sb_cube_levels(face_size) + CUBE_TAIL_LEVELS) {
        sb_error("%s: part %d: %d levels, expected %u", path, part, levels_x,
                 sb_cube_levels(face_size) + CUBE_TAIL_LEVELS);
        return SB_ERR_BAD_IMAGE;
    }
    const exr_attr_chlist_t *chlist = NULL;
    SB_EXR_TRY(exr_get_channels(ctxt, part, &chlist), "reading the channel list");
    if (chlist->num_channels != (int)channels->channel_count) {
        sb_error("%s: part %d: %d channels, expected %u", path, part, chlist->num_channels, channels->channel_count);
        return SB_ERR_BAD_IMAGE;
    }
    for (int c = 0; c < chlist->num_channels; c++) {
        const exr_attr_chlist_entry_t *e = &chlist->entries[c];
        if (e->x_sampling != 1 || e->y_sampling != 1 || e->pixel_type != EXR_PIXEL_FLOAT ||
            sb_exr_channel_index(channels, e->name.str) == channels->channel_count) {
            sb_error("%s: part %d: channel %s is not one of the product's FLOAT channels", path, part, e->name.str);
            return SB_ERR_BAD_IMAGE;
        }
    }
cleanup:
    return res;
}

enum sb_result sb_exr_cube_read(const char *path, const char *channel_order, uint32_t face_size, uint32_t cube_count,
                                struct sb_image *image)
{
    memset(image, 0, sizeof(*image));
    if (!face_size || (face_size & (face_size - 1)) || face_size > SB_CUBE_MAX_FACE || !cube_count ||
        cube_count > SB_CUBE_MAX_COUNT) {
        sb_error("%s: %u cubes of %u texels a face: not a shape skybake reads", path, cube_count, face_size);
        return SB_ERR_BAD_IMAGE;
    }
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = sb_exr_error_handler;
    exr_context_t ctxt = NULL;
    exr_decode_pipeline_t decoder;
    bool decoder_live = false;
    enum sb_result res = SB_OK;
    struct sb_image want = {0};
    sb_image_set_channel_names(&want, channel_order);
    while (want.channel_count < SB_IMAGE_MAX_CHANNELS && want.channel_names[want.channel_count][0])
        want.channel_count++;
    int fd;
    if ((res = sb_exr_start_read(path, &init, &ctxt, &fd)))
        return res;
    int parts = 0;
    SB_EXR_TRY(exr_get_count(ctxt, &parts), "counting parts");
    if (parts != (int)cube_count) {
        sb_error("%s: %d parts, expected %u cubes", path, parts, cube_count);
        res = SB_ERR_BAD_IMAGE;
        goto cleanup;
    }
    for (int part = 0; part < parts; part++)
        if ((res = check_part(ctxt, path, part, face_size, &want)))
            goto cleanup;
    if ((res = sb_image_init_levels(image, face_size, 6 * face_size, cube_count, want.channel_count,
                                    sb_cube_levels(face_size))))
        goto cleanup;
    memcpy(image->channel_names, want.channel_names, sizeof(want.channel_names));
    for (int part = 0; part < parts; part++) {
        float tail[4 * SB_IMAGE_MAX_CHANNELS];
        for (uint32_t level = 0; level < image->levels + CUBE_TAIL_LEVELS; level++) {
            int32_t tiles_x = 0, tiles_y = 0, tw = 0, th = 0;
            SB_EXR_TRY(tile_counts(ctxt, part, (int)level, &tiles_x, &tiles_y, &tw, &th), "counting tiles");
            uint32_t width = 1;
            float *base = level < image->levels ? level_base(image, (uint32_t)part, level, &width)
                                                : tail + (level > image->levels ? 3 * image->channel_count : 0);
            int32_t w = (int32_t)width, h = level < image->levels ? (int32_t)sb_image_level_size(image->height, level)
                                            : level == image->levels ? 3
                                                                     : 1;
            for (int32_t ty = 0; ty < tiles_y; ty++)
                for (int32_t tx = 0; tx < tiles_x; tx++) {
                    exr_chunk_info_t cinfo;
                    SB_EXR_TRY(exr_read_tile_chunk_info(ctxt, part, tx, ty, (int)level, (int)level, &cinfo),
                               "reading a tile");
                    int32_t x0 = tx * tw, y0 = ty * th;
                    if (x0 + (int32_t)cinfo.width > w || y0 + (int32_t)cinfo.height > h) {
                        sb_error("%s: part %d: tile (%d, %d) of level %u lies outside it", path, part, tx, ty, level);
                        res = SB_ERR_EXR;
                        goto cleanup;
                    }
                    bool first = !decoder_live;
                    if (decoder_live)
                        SB_EXR_TRY(exr_decoding_update(ctxt, part, &cinfo, &decoder), "updating the decoder");
                    else {
                        SB_EXR_TRY(exr_decoding_initialize(ctxt, part, &cinfo, &decoder), "starting the decoder");
                        decoder_live = true;
                    }
                    if (!sb_exr_point_channels(decoder.channels, decoder.channel_count, image, base, width, x0, y0,
                                               true)) {
                        res = SB_ERR_EXR;
                        goto cleanup;
                    }
                    if (first)
                        SB_EXR_TRY(exr_decoding_choose_default_routines(ctxt, part, &decoder), "choosing the decoder");
                    SB_EXR_TRY(exr_decoding_run(ctxt, part, &decoder), "decoding");
                }
        }
        exr_decoding_destroy(ctxt, &decoder);
        decoder_live = false;
        float expect[4 * SB_IMAGE_MAX_CHANNELS];
        uint32_t last_width;
        cube_tail(level_base(image, (uint32_t)part, image->levels - 1, &last_width), image->channel_count, expect);
        if (memcmp(expect, tail, 4 * image->channel_count * sizeof(float)) != 0) {
            sb_error("%s: part %d: the levels past the 1 x 6 cube are not the means skybake writes", path, part);
            res = SB_ERR_BAD_IMAGE;
            goto cleanup;
        }
    }
cleanup:
    if (decoder_live)
        exr_decoding_destroy(ctxt, &decoder);
    exr_finish(&ctxt);
    close(fd);
    if (res)
        sb_image_finish(image);
    return res;
}
