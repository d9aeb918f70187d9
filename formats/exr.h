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

#endif
