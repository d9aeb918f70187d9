#include "image.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

enum sb_result sb_image_init(struct sb_image *image, uint32_t width, uint32_t height, uint32_t channel_count)
{
    memset(image, 0, sizeof(*image));
    if (!width || !height || !channel_count || channel_count > SB_IMAGE_MAX_CHANNELS)
        return SB_ERR_BAD_IMAGE;
    image->data = calloc((size_t)width * height * channel_count, sizeof(float));
    if (!image->data)
        return SB_ERR_NOMEM;
    image->width = width;
    image->height = height;
    image->channel_count = channel_count;
    return SB_OK;
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
    put_u32_le(state, 1); /* depth */
    put_u32_le(state, image->channel_count);
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

int64_t sb_image_find_nonfinite(const struct sb_image *image)
{
    uint64_t n = sb_image_float_count(image);
    for (uint64_t i = 0; i < n; i++)
        if (!isfinite(image->data[i]))
            return (int64_t)i;
    return -1;
}
