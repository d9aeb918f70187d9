/*
 * EXR files of skybake products, through OpenEXR's C API: scanline images,
 * FLOAT channels, ZIP compression (lossless), plus string attributes that
 * name the product, the pack format version and the content hash.
 */
#ifndef SB_EXR_H
#define SB_EXR_H

#include "image.h"

/*
 * Write `image` to `path` (created or replaced). Channels keep the image's
 * names; EXR stores them sorted, which readers undo by name. Returns SB_OK,
 * SB_ERR_IO or SB_ERR_EXR, logging the path and OpenEXR's reason.
 */
enum sb_result sb_exr_write(const char *path, const struct sb_image *image, const struct sb_attribute *attributes,
                            int attribute_count);

/*
 * Read an EXR written by sb_exr_write (or any single-part scanline EXR of
 * FLOAT or HALF channels) into `image`, converting to fp32. If channel_order
 * is given ("r,g,b"), channels are returned in that order and every name
 * must exist; otherwise in the file's order. String attributes whose names
 * start with "skybake." are returned in `attributes` (may be NULL).
 * Refuses images larger than max_pixels (0: 64 Mpixel) before allocating.
 */
enum sb_result sb_exr_read(const char *path, const char *channel_order, uint64_t max_pixels, struct sb_image *image,
                           struct sb_attribute *attributes, int *attribute_count);

/*
 * Cube maps with their mip chains (exr_cube.c): `image` is a cube array,
 * width N (a power of two), height 6 N, depth the cube count and levels
 * log2 N + 1 (sb_cube_levels). Each cube is one part of the file ("cube.i"),
 * tiled, mip-mapped with level sizes rounded down, ZIP, FLOAT channels,
 * with the envmap attribute "cube": what exrheader and viewers read as a
 * cube-face environment map. The faces are stacked as OpenEXR's envmap
 * convention has them (+x, -x, +y, -y, +z, -z; shaders/cube.glsl maps
 * directions). The reader takes only that shape, the channels in
 * channel_order (every one, nothing else) and the size the caller expects,
 * all checked before any pixel is allocated.
 */
#define SB_CUBE_MAX_FACE 4096
#define SB_CUBE_MAX_COUNT 1024
uint32_t sb_cube_levels(uint32_t face_size);
enum sb_result sb_exr_cube_write(const char *path, const struct sb_image *image, const struct sb_attribute *attributes,
                                 int attribute_count);
enum sb_result sb_exr_cube_read(const char *path, const char *channel_order, uint32_t face_size, uint32_t cube_count,
                                struct sb_image *image);

#endif
