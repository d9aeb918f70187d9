/*
 * The images a material reads (base colour, normal, metallic-roughness,
 * emissive), decoded to RGBA8 by libpng and libjpeg-turbo. Only the
 * mesh import's helper process decodes (mesh.h: a decoder meets hostile
 * bytes there, under the helper's limits); the baker and skyview receive
 * the texels and build the mips on the GPU.
 *
 * Every size is checked before anything is allocated: a file over
 * SB_TEXTURE_MAX_FILE_BYTES, a side over SB_TEXTURE_MAX_SIDE (read from the
 * header), more than SB_MESH_MAX_TEXTURES images or SB_MESH_MAX_TEXEL_BYTES
 * decoded bytes a mesh file. An image file must lie inside its model's
 * folder (no absolute path, no ".." or link leading out of it) and be a
 * regular file.
 */
#ifndef SB_GEOMETRY_MESH_TEXTURE_H
#define SB_GEOMETRY_MESH_TEXTURE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "result.h"

#define SB_TEXTURE_MAX_SIDE 8192u
#define SB_TEXTURE_MAX_FILE_BYTES (64u << 20)
#define SB_MESH_MAX_TEXTURES 256u
#define SB_MESH_MAX_TEXEL_BYTES (1ull << 30)
#define SB_TEXTURE_NAME_MAX 128

/* What a material reads from which image (glTF's maps). */
enum sb_texture_slot {
    SB_TEXTURE_BASE_COLOR,         /* sRGB; multiplies the material's albedo */
    SB_TEXTURE_NORMAL,             /* tangent space, linear */
    SB_TEXTURE_METALLIC_ROUGHNESS, /* linear: roughness in G, metallic in B */
    SB_TEXTURE_EMISSIVE,           /* sRGB */
    SB_TEXTURE_SLOT_COUNT,
};

/* How coordinates outside [0, 1] read (glTF's sampler wrap modes). */
enum sb_texture_wrap {
    SB_TEXTURE_REPEAT,
    SB_TEXTURE_CLAMP,
    SB_TEXTURE_MIRROR,
};

struct sb_mesh_texture {
    char name[SB_TEXTURE_NAME_MAX]; /* the image's path in its model, or "*N" for the file's N-th embedded image */
    uint32_t width, height;
    uint32_t wrap[2];               /* enum sb_texture_wrap, along u and v */
    uint32_t srgb;                  /* 1: the texels are sRGB-encoded (base colour, emissive) */
    uint32_t pad;
    uint8_t *rgba;                  /* owned: 4 x width x height bytes, rows from the image's top */
};

/*
 * Decode a PNG or JPEG held in memory into *texture (name, width, height
 * and rgba; the caller sets the rest). `model` and texture->name name the
 * image in messages. Refuses, with SB_ERR_IO or SB_ERR_TOO_LARGE and a
 * message naming both: bytes that are neither, a side past
 * SB_TEXTURE_MAX_SIDE or zero, a channel layout the decoder does not know,
 * and a truncated or corrupt image.
 */
enum sb_result sb_texture_decode(const void *bytes, size_t size, const char *model, struct sb_mesh_texture *texture);

/*
 * Read and decode the image `image` that the model at `model_path` names,
 * relative to the model's folder, into *texture (name set to `image`).
 * Refuses a path that leaves the folder (SB_ERR_UNSAFE_PATH), one that is
 * not a regular file or is too large, then as sb_texture_decode.
 */
enum sb_result sb_texture_read(const char *model_path, const char *image, struct sb_mesh_texture *texture);

/* The texel bytes of a texture. */
static inline size_t sb_texture_bytes(const struct sb_mesh_texture *t)
{
    return (size_t)4 * t->width * t->height;
}

#endif
