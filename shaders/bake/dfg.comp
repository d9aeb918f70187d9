#version 450
// The DFG (split-sum) LUT (config.h): one invocation a texel. The half
// vector's polar angle is drawn through GGX's inverse CDF (midpoints), so
// D (n.h) dw_h is the measure; l = reflect(-v, h) and dw_l = 4 (v.h) dw_h
// turn the integral of D Vis (n.l) dw_l into the mean of
// Vis (n.l) 4 (v.h) / (n.h). At each polar angle the azimuths that give
// n.l > 0 and v.h > 0 are an interval |phi| < phi_max (v lies in the xz
// plane), integrated over phi = phi_max (1 - s^2), s at midpoints: nodes
// crowd toward n.l = 0, where at grazing n.v the integrand turns within
// a layer of width ~ n.v.
#extension GL_GOOGLE_include_directive : require
#include "config.h"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
layout(std430, binding = SB_DFG_BINDING_OUT) writeonly buffer Out { float results[]; };
layout(push_constant) uniform Push { sb_dfg_push pc; };

float visibility(float n_v, float n_l, float a2)
{
    float gv = n_l * sqrt(n_v * n_v * (1.0 - a2) + a2);
    float gl = n_v * sqrt(n_l * n_l * (1.0 - a2) + a2);
    return 0.5 / (gv + gl);
}

/* The largest azimuth with n.l > 0 and v.h > 0 at this polar angle of h
 * (v = (sin_v, 0, n_v)); 0: none; pi: all. */
float dfg_phi_max(float sin_v, float n_v, float sin_h, float n_h)
{
    float den = sin_v * sin_h;
    float c0 = n_v * (1.0 - 2.0 * n_h * n_h), c1 = -n_v * n_h; /* n.l > 0: den cos > c0 / 2 n_h; v.h > 0 */
    if (den <= 1e-20)
        return (n_v * (2.0 * n_h * n_h - 1.0) > 0.0 && n_v * n_h > 0.0) ? 3.141592653589793 : 0.0;
    float c = max(c0 / (2.0 * n_h * den), c1 / den);
    return c >= 1.0 ? 0.0 : acos(max(c, -1.0));
}

void main()
{
    uvec2 texel = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(texel, uvec2(pc.size))))
        return;
    float n_v = (float(texel.x) + 0.5) / float(pc.size);
    float rough = (float(texel.y) + 0.5) / float(pc.size);
    float a = rough * rough, a2 = a * a;
    vec3 v = vec3(sqrt(1.0 - n_v * n_v), 0.0, n_v);
    float x = 0.0, y = 0.0;
    float inv = 1.0 / float(pc.samples_side);
    /* h past theta_v / 2 + pi / 4 sends l below the horizon at every
     * azimuth: the CDF's end there, xi = xi_max (1 - t^2), t at midpoints
     * (the azimuth interval closes like a square root there) */
    /* in q = 1 - xi, without cancellation: cos^2 theta_h = q / (a2 + q (1 - a2)) */
    float c_max = cos(0.5 * acos(n_v) + 0.7853981633974483), c2 = c_max * c_max;
    float den_max = 1.0 - c2 + c2 * a2, xi_max = (1.0 - c2) / den_max, q_min = c2 * a2 / den_max;
    for (uint i = 0u; i < pc.samples_side; i++) {
        float t = (float(i) + 0.5) * inv;
        float t3 = t * t * t, q = q_min + xi_max * t3 * t;
        float den = a2 + q * (1.0 - a2);
        float n_h = sqrt(q / den), sin_h = sqrt(a2 * max(1.0 - q, 0.0) / den);
        float phi_max = dfg_phi_max(v.x, n_v, sin_h, n_h);
        if (phi_max <= 0.0)
            continue;
        float row_x = 0.0, row_y = 0.0;
        for (uint j = 0u; j < pc.samples_side; j++) {
            float s = (float(j) + 0.5) * inv;
            float phi = phi_max * (1.0 - s * s);
            vec3 h = vec3(sin_h * cos(phi), sin_h * sin(phi), n_h);
            float v_h = dot(v, h);
            float n_l = 2.0 * v_h * n_h - n_v;
            if (n_l <= 0.0 || v_h <= 0.0)
                continue;
            float g = visibility(n_v, n_l, a2) * 4.0 * n_l * v_h / n_h * s;
            float m = max(1.0 - v_h, 0.0), m2 = m * m; /* pow of a negative is undefined (NaN on NVIDIA) */
            float f = m2 * m2 * m;
            row_x += f * g;
            row_y += g;
        }
        /* d phi = 2 phi_max s ds, both signs of phi, over 2 pi; d xi = 2 xi_max t dt */
        x += row_x * phi_max * t3;
        y += row_y * phi_max * t3;
    }
    uint at = 2u * (texel.y * pc.size + texel.x);
    float w = 8.0 * xi_max / 3.141592653589793 * inv * inv;
    results[at] = x * w;
    results[at + 1u] = y * w;
}
