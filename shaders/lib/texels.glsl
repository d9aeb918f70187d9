// Textures held as storage buffers (vulkan/texels.h), filtered here:
// bilinear at a level, trilinear between two, sRGB decoded before the
// filter, glTF's wrap modes. An includer defines TEXELS_BINDING_RECORDS and
// TEXELS_BINDING_DATA, the bindings of the records (one uvec4 an image:
// first texel, width | height << 16, levels | wrap u << 8 | wrap v << 10 |
// srgb << 12, 0) and the texels (RGBA8 uints, each image's levels in
// turn, rows from the image's top). Texture coordinates: u right, v up
// from the image's last row.
#ifndef SB_TEXELS_GLSL
#define SB_TEXELS_GLSL

#include "config.h"

layout(std430, binding = TEXELS_BINDING_RECORDS) readonly buffer TexelRecords { uvec4 texel_records[]; };
layout(std430, binding = TEXELS_BINDING_DATA) readonly buffer TexelData { uint texel_data[]; };

float texels_srgb_to_linear(float c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

// u reduced to the wrap mode's period (coordinates stay small)
float texels_wrap_coordinate(float u, uint mode)
{
    if (mode == SB_SURFACE_WRAP_REPEAT)
        return u - floor(u);
    if (mode == SB_SURFACE_WRAP_MIRROR) {
        float m = u - 2.0 * floor(0.5 * u);
        return m <= 1.0 ? m : 2.0 - m;
    }
    return clamp(u, 0.0, 1.0);
}

// a texel index in [0, n)
int texels_wrap(int i, int n, uint mode)
{
    if (mode == SB_SURFACE_WRAP_REPEAT)
        return (i % n + n) % n;
    if (mode == SB_SURFACE_WRAP_MIRROR) {
        int m = (i % (2 * n) + 2 * n) % (2 * n);
        return m < n ? m : 2 * n - 1 - m;
    }
    return clamp(i, 0, n - 1);
}

vec4 texels_fetch(uint at, int width, int x, int y, bool srgb)
{
    vec4 c = unpackUnorm4x8(texel_data[at + uint(y * width + x)]);
    if (srgb)
        c.rgb = vec3(texels_srgb_to_linear(c.r), texels_srgb_to_linear(c.g), texels_srgb_to_linear(c.b));
    return c;
}

// Bilinear at one level of record t.
vec4 texels_bilinear(uvec4 t, uint level, vec2 uv)
{
    uint wrap_u = (t.z >> 8) & 3u, wrap_v = (t.z >> 10) & 3u;
    bool srgb = ((t.z >> 12) & 1u) != 0u;
    int w = int(t.y & 0xffffu), h = int(t.y >> 16);
    uint at = t.x;
    for (uint l = 0u; l < level; l++) {
        at += uint(w * h);
        w = max(w >> 1, 1);
        h = max(h >> 1, 1);
    }
    float x = texels_wrap_coordinate(uv.x, wrap_u) * float(w) - 0.5;
    float y = (1.0 - texels_wrap_coordinate(uv.y, wrap_v)) * float(h) - 0.5;
    int x0 = int(floor(x)), y0 = int(floor(y));
    vec2 f = vec2(x - float(x0), y - float(y0));
    int xa = texels_wrap(x0, w, wrap_u), xb = texels_wrap(x0 + 1, w, wrap_u);
    int ya = texels_wrap(y0, h, wrap_v), yb = texels_wrap(y0 + 1, h, wrap_v);
    vec4 top = mix(texels_fetch(at, w, xa, ya, srgb), texels_fetch(at, w, xb, ya, srgb), f.x);
    vec4 bottom = mix(texels_fetch(at, w, xa, yb, srgb), texels_fetch(at, w, xb, yb, srgb), f.x);
    return mix(top, bottom, f.y);
}

// The texels of image `image` per texture coordinate: width x height.
vec2 texels_size(uint image)
{
    uvec4 t = texel_records[image];
    return vec2(float(t.y & 0xffffu), float(t.y >> 16));
}

// Image `image` at uv, trilinear at level `lod` (clamped to its levels).
vec4 texels_sample(uint image, vec2 uv, float lod)
{
    uvec4 t = texel_records[image];
    float levels = float(t.z & 0xffu);
    lod = clamp(lod, 0.0, levels - 1.0);
    uint l0 = uint(lod);
    vec4 c = texels_bilinear(t, l0, uv);
    if (float(l0) < lod)
        c = mix(c, texels_bilinear(t, min(l0 + 1u, uint(levels) - 1u), uv), lod - float(l0));
    return c;
}

#endif
