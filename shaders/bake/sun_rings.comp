#version 450
/* Multiscattering's ring table (sun_rings.glsl): one invocation per entry
 * (x) of each column of the LUT (y), a ring of the sun's transmittance
 * integrated by Gauss-Legendre of pc.directions_phi nodes a piece, the
 * pieces cut where the ring enters the planet's shadow (on the ground,
 * where the sun sets) and where the sun's ray grazes an ozone corner. */
#extension GL_GOOGLE_include_directive : require
#include "config.h"
#include "atmosphere.glsl"
#include "sun_rings.glsl"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
layout(push_constant) uniform Push { sb_bake_push pc; };
layout(std430, set = 0, binding = SB_BINDING_OUTPUT) writeonly buffer Output { vec4 result[]; };

shared float ring_node[SB_MAX_DIRECTIONS_PHI];
shared float ring_weight[SB_MAX_DIRECTIONS_PHI];

/* Where on [0, pi] the ring's cosine A + B cos(phi) is mu, if inside. */
void ring_add_cut(float a, float b, float mu, inout float cuts[6], inout int n)
{
    if (b <= 0.0)
        return;
    float x = (mu - a) / b;
    if (x > -1.0 && x < 1.0)
        cuts[n++] = acos_precise(x);
}

/* The mean over phi in [0, pi] of T_sun(h, A + B cos(phi)), or on the
 * ground of max(mu, 0) T_sun(0, mu). */
vec3 ring_mean(RingColumn col, float h, float w, bool ground)
{
    float R = ground_radius(), r = R + h;
    float q = 1.0 / (1.0 + w * w); /* gamma from its half-angle tangent w */
    float a = (1.0 - w * w) * q * col.mu_s, b = 2.0 * w * q * col.sin_s;
    float cuts[6];
    int n = 0;
    cuts[n++] = 0.0;
    ring_add_cut(a, b, ground ? 0.0 : -horizon_distance(h) / r, cuts, n);
    for (int k = 0; k < 3 && !ground; k++) {
        float hc = ozone_corner(k);
        if (hc > 0.0 && hc < h)
            ring_add_cut(a, b, -sqrt((h - hc) * (2.0 * R + h + hc)) / r, cuts, n);
    }
    cuts[n++] = PI;
    for (int i = 1; i < n; i++) {
        float v = cuts[i];
        int j = i - 1;
        while (j >= 0 && cuts[j] > v) {
            cuts[j + 1] = cuts[j];
            j--;
        }
        cuts[j + 1] = v;
    }
    vec3 sum = vec3(0.0);
    for (int s = 0; s + 1 < n; s++) {
        float lo = cuts[s], len = cuts[s + 1] - cuts[s];
        for (uint k = 0u; k < pc.directions_phi; k++) {
            float mu = clamp(a + b * cos(lo + len * ring_node[k]), -1.0, 1.0);
            vec3 t = sun_transmittance(h, mu);
            sum += (len * ring_weight[k] * (ground ? max(mu, 0.0) : 1.0)) * t;
        }
    }
    return sum / PI;
}

void main()
{
    uint i = gl_LocalInvocationIndex;
    for (uint k = i; k < pc.directions_phi; k += uint(SB_WORKGROUP_X * SB_WORKGROUP_Y)) {
        float x, w;
        gauss_legendre(int(k), int(pc.directions_phi), 0.0, 1.0, x, w);
        ring_node[k] = x;
        ring_weight[k] = w;
    }
    barrier();
    uint entry = gl_GlobalInvocationID.x, column = gl_GlobalInvocationID.y;
    if (entry >= uint(SB_RINGS_COLUMN) || column >= pc.height)
        return;
    RingColumn col = ring_column(2.0 * texel_unit(column, pc.height) - 1.0);
    vec3 value;
    if (entry >= uint(SB_RINGS_ROWS * SB_RINGS_ANGLES)) {
        value = ring_mean(col, 0.0, ring_ground_tan(col, int(entry) - SB_RINGS_ROWS * SB_RINGS_ANGLES), true);
    } else {
        int row = int(entry) / SB_RINGS_ANGLES, j = int(entry) % SB_RINGS_ANGLES;
        float h = ring_row_altitude(col, row);
        value = ring_mean(col, h, ring_entry_tan(col, h, j), false);
    }
    result[column * uint(SB_RINGS_COLUMN) + entry] = vec4(value, 0.0);
}
