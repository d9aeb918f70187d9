// Cube maps as OpenEXR lays them out (its ImfEnvmap.h): face f of an
// N x 6N image is rows [f N, (f + 1) N), the faces +x, -x, +y, -y, +z, -z;
// within a face, u runs along the row and v down the rows, both in
// [-1, 1]. baker/cube.c is the C twin.
#ifndef SB_CUBE_GLSL
#define SB_CUBE_GLSL

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

#endif
