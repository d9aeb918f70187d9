/*
 * An image of fp32 channels, 2D or 3D, interleaved, x fastest, then y, then
 * z (texel (x, y, z) at data[((z * height + y) * width + x) * channel_count];
 * rows from y = 0 upward). The shape of every product, what EXR and VDB
 * files and content hashes are made of.
 *
 * An image may carry a mip chain (levels > 1: a 2D image array, the
 * reflection cubes): level l is max(width >> l, 1) x max(height >> l, 1) x
 * depth, stored after level l - 1 in the same order (sb_image_level_offset).
 */
#ifndef SB_IMAGE_H
#define SB_IMAGE_H

#include <stddef.h>
#include <stdint.h>

#include "result.h"

#define SB_IMAGE_MAX_CHANNELS 192 /* sky_bounce has 184 */
#define SB_CHANNEL_NAME_MAX 32

struct sb_image {
    uint32_t width;
    uint32_t height;
    uint32_t depth; /* 1 for a 2D image */
    uint32_t channel_count;
    uint32_t levels; /* mip levels; 0 or 1: none but the image */
    char channel_names[SB_IMAGE_MAX_CHANNELS][SB_CHANNEL_NAME_MAX];
    float *data; /* owned: width * height * channel_count floats */
};

/* Allocate zeroed data for the given shape; names are set by the caller. */
enum sb_result sb_image_init(struct sb_image *image, uint32_t width, uint32_t height, uint32_t channel_count);
enum sb_result sb_image_init_volume(struct sb_image *image, uint32_t width, uint32_t height, uint32_t depth,
                                    uint32_t channel_count);
/* A mip-mapped 2D image array (see above), levels >= 1. */
enum sb_result sb_image_init_levels(struct sb_image *image, uint32_t width, uint32_t height, uint32_t depth,
                                    uint32_t channel_count, uint32_t levels);
/* Free the data; accepts a zeroed or already finished image. */
void sb_image_finish(struct sb_image *image);

/* Level l's width or height from the image's. */
static inline uint32_t sb_image_level_size(uint32_t size, uint32_t level)
{
    return size >> level ? size >> level : 1;
}

/* Floats before level `level` (every level's when level == levels). */
static inline uint64_t sb_image_level_offset(const struct sb_image *image, uint32_t level)
{
    uint64_t n = 0;
    for (uint32_t l = 0; l < level; l++)
        n += (uint64_t)sb_image_level_size(image->width, l) * sb_image_level_size(image->height, l);
    return n * image->depth * image->channel_count;
}

/* Number of floats in the image, every level included. */
static inline uint64_t sb_image_float_count(const struct sb_image *image)
{
    return sb_image_level_offset(image, image->levels > 1 ? image->levels : 1);
}

/* Set channel names from one comma-separated list ("r,g,b"). */
void sb_image_set_channel_names(struct sb_image *image, const char *names);

/* A "skybake.*" string attribute of a file (EXR header, VDB metadata). */
#define SB_FILE_MAX_ATTRIBUTES 8
struct sb_attribute {
    char name[48];
    char value[128];
};

/*
 * Content hash: XXH3-128 over the canonical content (a tag, the element type,
 * width, height, depth, channel count, the level count where it is above 1,
 * the NUL-terminated channel names, then the values, every level's, as
 * little-endian IEEE binary32), written as 32 lowercase hex digits plus NUL. It does not depend on the file that holds the image.
 */
#define SB_HASH_HEX_SIZE 33
void sb_image_content_hash(const struct sb_image *image, char out[SB_HASH_HEX_SIZE]);

/* 128-bit XXH3 of bytes as hex (for scenes and other canonical text). */
void sb_hash_bytes(const void *data, size_t size, char out[SB_HASH_HEX_SIZE]);

/* The same of the bytes of file `name` in directory dir_fd (AT_FDCWD, or an
 * open directory), not following a final symbolic link: a manifest's
 * file_hash. SB_ERR_IO (errno set) when it cannot be read. */
enum sb_result sb_hash_file(int dir_fd, const char *name, char out[SB_HASH_HEX_SIZE]);

/* First NaN or infinite value, as a float index, or -1 when all are finite. */
int64_t sb_image_find_nonfinite(const struct sb_image *image);

/* IEEE binary16 (half): fp32 to the nearest half, ties to even (subnormals
 * kept, beyond 65504 infinity, NaN quiet), and back (exact). */
uint16_t sb_half_from_float(float value);
float sb_half_to_float(uint16_t half);

/*
 * Round every value to the nearest binary16, as a file stored as half holds
 * it. Refuses (SB_ERR_NUMERIC, values unchanged) when a finite value would
 * become infinite; returns the first such value's index in *bad (may be NULL).
 * First value not a binary16 value: sb_image_find_not_half (-1: none).
 */
enum sb_result sb_image_round_to_half(struct sb_image *image, int64_t *bad);
int64_t sb_image_find_not_half(const struct sb_image *image);

#endif
