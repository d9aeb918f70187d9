#include "image.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <xxhash.h>

#include "io.h"

enum sb_result sb_image_init_levels(struct sb_image *image, uint32_t width, uint32_t height, uint32_t depth,
                                    uint32_t channel_count, uint32_t levels)
{
    memset(image, 0, sizeof(*image));
    if (!width || !height || !depth || !channel_count || channel_count > SB_IMAGE_MAX_CHANNELS || !levels ||
        levels > 32)
        return SB_ERR_BAD_IMAGE;
    struct sb_image shape = {
        .width = width, .height = height, .depth = depth, .channel_count = channel_count, .levels = levels};
    uint64_t count = sb_image_float_count(&shape);
    if (count > SIZE_MAX / sizeof(float) || (uint64_t)width * height * depth > (1ull << 40))
        return SB_ERR_NOMEM;
    image->data = calloc((size_t)count, sizeof(float));
    if (!image->data)
        return SB_ERR_NOMEM;
    image->width = width;
    image->height = height;
    image->depth = depth;
    image->channel_count = channel_count;
    image->levels = levels;
    return SB_OK;
}

enum sb_result sb_image_init_volume(struct sb_image *image, uint32_t width, uint32_t height, uint32_t depth,
                                    uint32_t channel_count)
{
    return sb_image_init_levels(image, width, height, depth, channel_count, 1);
}

enum sb_result sb_image_init(struct sb_image *image, uint32_t width, uint32_t height, uint32_t channel_count)
{
    return sb_image_init_volume(image, width, height, 1, channel_count);
}

void sb_image_finish(struct sb_image *image)
{
    free(image->data);
    memset(image, 0, sizeof(*image));
}

void sb_image_set_channel_names(struct sb_image *image, const char *names)
{
    uint32_t c = 0;
    while (*names && c < SB_IMAGE_MAX_CHANNELS) {
        size_t len = strcspn(names, ",");
        if (len >= SB_CHANNEL_NAME_MAX)
            len = SB_CHANNEL_NAME_MAX - 1;
        memcpy(image->channel_names[c], names, len);
        image->channel_names[c][len] = '\0';
        c++;
        names += strcspn(names, ",");
        if (*names == ',')
            names++;
    }
}

static void hex128(XXH128_hash_t h, char out[SB_HASH_HEX_SIZE])
{
    snprintf(out, SB_HASH_HEX_SIZE, "%016llx%016llx", (unsigned long long)h.high64, (unsigned long long)h.low64);
}

static void put_u32_le(XXH3_state_t *state, uint32_t v)
{
    uint8_t b[4] = {v & 0xff, (v >> 8) & 0xff, (v >> 16) & 0xff, v >> 24};
    XXH3_128bits_update(state, b, 4);
}

void sb_image_content_hash(const struct sb_image *image, char out[SB_HASH_HEX_SIZE])
{
    static const char tag[] = "skybake-content-v1";
    XXH3_state_t *state = XXH3_createState();
    XXH3_128bits_reset(state);
    XXH3_128bits_update(state, tag, sizeof(tag));
    put_u32_le(state, 1); /* element type: binary32 */
    put_u32_le(state, image->width);
    put_u32_le(state, image->height);
    put_u32_le(state, image->depth);
    put_u32_le(state, image->channel_count);
    if (image->levels > 1) /* only then: every older hash stands */
        put_u32_le(state, image->levels);
    for (uint32_t c = 0; c < image->channel_count; c++)
        XXH3_128bits_update(state, image->channel_names[c], strlen(image->channel_names[c]) + 1);
    /* Values in little-endian byte order, converted in chunks. */
    uint8_t chunk[4096];
    uint64_t n = sb_image_float_count(image);
    for (uint64_t i = 0; i < n;) {
        size_t k = 0;
        for (; k < sizeof(chunk) / 4 && i < n; k++, i++) {
            uint32_t bits;
            memcpy(&bits, &image->data[i], 4);
            chunk[4 * k + 0] = bits & 0xff;
            chunk[4 * k + 1] = (bits >> 8) & 0xff;
            chunk[4 * k + 2] = (bits >> 16) & 0xff;
            chunk[4 * k + 3] = bits >> 24;
        }
        XXH3_128bits_update(state, chunk, 4 * k);
    }
    hex128(XXH3_128bits_digest(state), out);
    XXH3_freeState(state);
}

void sb_hash_bytes(const void *data, size_t size, char out[SB_HASH_HEX_SIZE])
{
    hex128(XXH3_128bits(data, size), out);
}

enum sb_result sb_hash_file(int dir_fd, const char *name, char out[SB_HASH_HEX_SIZE])
{
    int fd = sb_open_regular(dir_fd, name, false, NULL);
    if (fd < 0)
        return SB_ERR_IO;
    XXH3_state_t *state = XXH3_createState();
    if (!state) {
        close(fd);
        return SB_ERR_NOMEM;
    }
    XXH3_128bits_reset(state);
    static _Thread_local unsigned char chunk[1 << 16];
    ssize_t n;
    while ((n = read(fd, chunk, sizeof(chunk))) > 0 || (n < 0 && errno == EINTR))
        if (n > 0)
            XXH3_128bits_update(state, chunk, (size_t)n);
    int err = errno;
    close(fd);
    if (n == 0)
        hex128(XXH3_128bits_digest(state), out);
    XXH3_freeState(state);
    errno = err;
    return n == 0 ? SB_OK : SB_ERR_IO;
}

int64_t sb_image_find_nonfinite(const struct sb_image *image)
{
    uint64_t n = sb_image_float_count(image);
    for (uint64_t i = 0; i < n; i++)
        if (!isfinite(image->data[i]))
            return (int64_t)i;
    return -1;
}

uint16_t sb_half_from_float(float value)
{
    uint32_t bits;
    memcpy(&bits, &value, 4);
    uint16_t sign = (uint16_t)((bits >> 16) & 0x8000u);
    uint32_t magnitude = bits & 0x7fffffffu;
    if (magnitude > 0x7f800000u)
        return sign | 0x7e00u;                                /* NaN, quiet */
    int32_t exponent = (int32_t)(magnitude >> 23) - 127 + 15; /* the half's biased exponent */
    uint32_t mantissa = magnitude & 0x7fffffu;
    if (exponent >= 31)
        return sign | 0x7c00u; /* too large, or infinite */
    /* The value as an integer q of half units plus a remainder of `shift`
     * bits, rounded to nearest, ties to even. A carry out of the mantissa
     * moves to the next binade (or to infinity), as it should. */
    uint32_t q, remainder, shift;
    if (exponent > 0) {
        shift = 13;
        q = ((uint32_t)exponent << 10) | (mantissa >> shift);
        remainder = mantissa & 0x1fffu;
    } else {
        if (magnitude < 0x33000000u) /* below half the smallest subnormal, 2^-25 (or zero) */
            return sign;
        uint32_t significand = mantissa | 0x800000u;
        shift = (uint32_t)(14 - exponent); /* 14 .. 24 */
        q = significand >> shift;
        remainder = significand & ((1u << shift) - 1);
    }
    uint32_t halfway = 1u << (shift - 1);
    if (remainder > halfway || (remainder == halfway && (q & 1)))
        q++;
    return (uint16_t)(sign | q);
}

float sb_half_to_float(uint16_t half)
{
    uint32_t sign = (uint32_t)(half & 0x8000u) << 16, exponent = (half >> 10) & 0x1fu, mantissa = half & 0x3ffu;
    uint32_t bits;
    if (exponent == 31) {
        bits = sign | 0x7f800000u | (mantissa << 13);
    } else if (exponent) {
        bits = sign | ((exponent + 127 - 15) << 23) | (mantissa << 13);
    } else if (!mantissa) {
        bits = sign;
    } else {
        /* Subnormal: normalise (mantissa 2^-24 units, at most 10 bits). */
        int32_t e = 127 - 15 + 1;
        while (!(mantissa & 0x400u)) {
            mantissa <<= 1;
            e--;
        }
        bits = sign | ((uint32_t)e << 23) | ((mantissa & 0x3ffu) << 13);
    }
    float value;
    memcpy(&value, &bits, 4);
    return value;
}

enum sb_result sb_image_round_to_half(struct sb_image *image, int64_t *bad)
{
    uint64_t n = sb_image_float_count(image);
    for (uint64_t i = 0; i < n; i++)
        if (isfinite(image->data[i]) && !isfinite(sb_half_to_float(sb_half_from_float(image->data[i])))) {
            if (bad)
                *bad = (int64_t)i;
            return SB_ERR_NUMERIC;
        }
    for (uint64_t i = 0; i < n; i++)
        image->data[i] = sb_half_to_float(sb_half_from_float(image->data[i]));
    if (bad)
        *bad = -1;
    return SB_OK;
}

int64_t sb_image_find_not_half(const struct sb_image *image)
{
    uint64_t n = sb_image_float_count(image);
    for (uint64_t i = 0; i < n; i++) {
        float v = image->data[i];
        float h = sb_half_to_float(sb_half_from_float(v));
        if (memcmp(&v, &h, 4) != 0 && !(isnan(v) && isnan(h)))
            return (int64_t)i;
    }
    return -1;
}
