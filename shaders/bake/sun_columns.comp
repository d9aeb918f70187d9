#version 450
/* The scattering bakes' sun table (atmosphere.glsl, "The sun's optical depth
 * in the scattering bakes"): at each node of each region, the Rayleigh and
 * Mie columns from the node to the top along its path, over the densities
 * at the node. One invocation per node, in two dispatches: the nodes inside
 * the table, then (built with SB_SUN_COLUMNS_GHOSTS) the ghosts around it
 * from those: the row at x < 0 mirrors x > 0 (both regions' columns are
 * even in x), the other ghosts extrapolate their four neighbours by a
 * cubic. Computed in one dispatch, a corner ghost integrated sixteen
 * paths, and the whole table waited for it (0.08 ms on an H100). */
#extension GL_GOOGLE_include_directive : require
#include "config.h"
#include "atmosphere.glsl"

layout(local_size_x = SB_WORKGROUP_X, local_size_y = SB_WORKGROUP_Y) in;
layout(push_constant) uniform Push { sb_bake_push pc; };
#ifdef SB_SUN_COLUMNS_GHOSTS
layout(std430, set = 0, binding = SB_BINDING_OUTPUT) buffer Output { vec2 result[]; };
#else
layout(std430, set = 0, binding = SB_BINDING_OUTPUT) writeonly buffer Output { vec2 result[]; };
#endif

/* The columns from t0 to the top of path p over the densities at t0: Gauss-
 * Legendre of SB_TRANSMITTANCE_GL_ORDER on pieces cut where the altitude has
 * risen by half the smallest scale height times 1, 2, 4 ... above t0's, so
 * that no piece spans more than half its height of the densities' fall. */
vec2 path_columns(SunPath p, float t0)
{
    const bool odd = (SB_TRANSMITTANCE_GL_ORDER & 1) != 0;
    float h0 = path_altitude(p.hb, p.rb, p.sb, t0);
    float step = 0.5 * min(atm.rayleigh_scattering.w, atm.mie_scattering.w);
    vec2 sum = vec2(0.0);
    float a = t0;
    for (int k = 0; k < 64 && a < p.t_end; k++) {
        float level = h0 + step * exp2(float(k));
        float b = level < atmosphere_thickness() ? min(path_distance_to_level(p.hb, p.sb, level), p.t_end) : p.t_end;
        b = max(b, a);
        float half_len = 0.5 * (b - a), mid = 0.5 * (a + b);
        vec2 piece = odd ? GL_W[0] * sun_columns_density(path_altitude(p.hb, p.rb, p.sb, mid) - h0) : vec2(0.0);
        for (int i = odd ? 1 : 0; i < SB_GL_HALF; i++) {
            float dt = half_len * GL_X[i];
            piece += GL_W[i] * (sun_columns_density(path_altitude(p.hb, p.rb, p.sb, mid - dt) - h0)
                                + sun_columns_density(path_altitude(p.hb, p.rb, p.sb, mid + dt) - h0));
        }
        sum += piece * half_len;
        a = b;
    }
    return sum;
}

vec2 interior_node(bool lower, int i, int j)
{
    float x = float(i) / float(SB_SUN_COLUMNS_X - 1), u = float(j) / float(SB_SUN_COLUMNS_U - 1);
    SunPath p = sun_path(lower, x * x * (lower ? ground_radius() : atmosphere_thickness()));
    return path_columns(p, sun_columns_t(u, p.t_end));
}

/* Node (i, j) inside the table: integrated, or read back for the ghosts. */
vec2 inside_node(bool lower, int i, int j)
{
#ifdef SB_SUN_COLUMNS_GHOSTS
    return result[sun_columns_index(lower, i, j)];
#else
    return interior_node(lower, i, j);
#endif
}

vec2 cubic_ghost(vec2 a, vec2 b, vec2 c, vec2 d)
{
    return 4.0 * a - 6.0 * b + 4.0 * c - d;
}

/* Node (i, j) of a row inside the table, j from -1 to SB_SUN_COLUMNS_U. */
vec2 row_node(bool lower, int i, int j)
{
    const int n = SB_SUN_COLUMNS_U;
    if (j < 0)
        return cubic_ghost(inside_node(lower, i, 0), inside_node(lower, i, 1), inside_node(lower, i, 2),
                           inside_node(lower, i, 3));
    if (j >= n)
        return cubic_ghost(inside_node(lower, i, n - 1), inside_node(lower, i, n - 2), inside_node(lower, i, n - 3),
                           inside_node(lower, i, n - 4));
    return inside_node(lower, i, j);
}

void main()
{
    const int n = SB_SUN_COLUMNS_X;
    if (gl_GlobalInvocationID.x >= uint(n + 2) || gl_GlobalInvocationID.y >= uint(2 * (SB_SUN_COLUMNS_U + 2)))
        return;
    int i = int(gl_GlobalInvocationID.x) - 1, row = int(gl_GlobalInvocationID.y);
    bool lower = row >= SB_SUN_COLUMNS_U + 2;
    int j = row - (lower ? SB_SUN_COLUMNS_U + 2 : 0) - 1;
    bool ghost = i < 0 || i >= n || j < 0 || j >= SB_SUN_COLUMNS_U;
#ifdef SB_SUN_COLUMNS_GHOSTS
    if (!ghost)
        return;
#else
    if (ghost)
        return;
#endif
    vec2 v = i >= n ? cubic_ghost(row_node(lower, n - 1, j), row_node(lower, n - 2, j), row_node(lower, n - 3, j),
                                  row_node(lower, n - 4, j))
                    : row_node(lower, abs(i), j);
    result[sun_columns_index(lower, i, j)] = v;
}
