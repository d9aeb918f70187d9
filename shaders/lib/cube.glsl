// Cube maps as OpenEXR lays them out (its ImfEnvmap.h): face f of an
// N x 6N image is rows [f N, (f + 1) N), the faces +x, -x, +y, -y, +z, -z;
// within a face, u runs along the row and v down the rows, both in
// [-1, 1]. baker/cube.c is the C twin.
#ifndef SB_CUBE_GLSL
#define SB_CUBE_GLSL

#include "config.h"

vec3 cube_direction(uint face, vec2 uv)
{
    float u = uv.x, v = uv.y;
    switch (face) {
    case 0u: return vec3(1.0, -v, u);
    case 1u: return vec3(-1.0, -v, -u);
    case 2u: return vec3(u, 1.0, -v);
    case 3u: return vec3(u, -1.0, v);
    case 4u: return vec3(-u, -v, 1.0);
    default: return vec3(u, -v, -1.0);
    }
}

// The face a direction is in and its (u, v) there.
uint cube_face(vec3 d, out vec2 uv)
{
    vec3 a = abs(d);
    if (a.x >= a.y && a.x >= a.z) {
        uv = d.x > 0.0 ? vec2(d.z, -d.y) / a.x : vec2(-d.z, -d.y) / a.x;
        return d.x > 0.0 ? 0u : 1u;
    }
    if (a.y >= a.z) {
        uv = d.y > 0.0 ? vec2(d.x, -d.z) / a.y : vec2(d.x, d.z) / a.y;
        return d.y > 0.0 ? 2u : 3u;
    }
    uv = d.z > 0.0 ? vec2(-d.x, -d.y) / a.z : vec2(d.x, -d.y) / a.z;
    return d.z > 0.0 ? 4u : 5u;
}

/* Bilinear between texel centres within the face d falls in, clamped at
 * its edges, of a level n texels wide whose first face starts at texel
 * `level_base` of the vec4 array `texels`: out_rgb. Interpolates as
 * a + (b - a) f, exact where texels are equal (GLSL's mix is not). The C
 * twin is sb_cube_bilinear (baker/cube.h). */
#define CUBE_BILINEAR(texels, level_base, n, d, out_rgb) {                                       \
    vec2 uv_;                                                                                  \
    uint face_ = cube_face(d, uv_);                                                            \
    vec2 p_ = clamp((uv_ * 0.5 + 0.5) * float(n) - 0.5, vec2(0.0), vec2(float(n) - 1.0));      \
    uvec2 i0_ = uvec2(p_), i1_ = min(i0_ + 1u, uvec2(n - 1u));                                 \
    vec2 f_ = p_ - vec2(i0_);                                                                  \
    uint b_ = (level_base) + face_ * (n) * (n);                                                \
    vec3 t00_ = texels[b_ + i0_.y * (n) + i0_.x].rgb, t10_ = texels[b_ + i0_.y * (n) + i1_.x].rgb; \
    vec3 t01_ = texels[b_ + i1_.y * (n) + i0_.x].rgb, t11_ = texels[b_ + i1_.y * (n) + i1_.x].rgb; \
    vec3 top_ = t00_ + (t10_ - t00_) * f_.x, bottom_ = t01_ + (t11_ - t01_) * f_.x;             \
    out_rgb = top_ + (bottom_ - top_) * f_.y; }

#endif
