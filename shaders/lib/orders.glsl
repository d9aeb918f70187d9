// The grid of multiple scattering by orders (config.h's sb_orders_push;
// baker/orders_ref.h states it and holds its fp64 twin): a node's
// (r, mu, mu_s, nu), a point's continuous node coordinates, and the
// multilinear read of a table of nodes. The grid is `orders`, an
// sb_orders_push in the push constants, unless the includer defines
// SB_ORDERS_GRID_DECLARED and SB_ORDERS_GRID_SIZE, SB_ORDERS_GRID_HEIGHTS and
// SB_ORDERS_GRID_MU_S (its fields) itself.
#ifndef SB_ORDERS_GLSL
#define SB_ORDERS_GLSL

#include "config.h"
#include "atmosphere.glsl"

#ifndef SB_ORDERS_GRID_DECLARED
layout(push_constant) uniform OrdersPush { sb_orders_push orders; };
#define SB_ORDERS_GRID_SIZE orders.size
#define SB_ORDERS_GRID_HEIGHTS orders.heights
#define SB_ORDERS_GRID_MU_S orders.mu_s
#endif

uint orders_node_count()
{
    uvec4 s = SB_ORDERS_GRID_SIZE;
    return s.x * s.y * s.z * s.w;
}

/* Node (ir, imu, imus, inu) of a flat index. */
uvec4 orders_node(uint index)
{
    uvec4 s = SB_ORDERS_GRID_SIZE;
    return uvec4(index / (s.w * s.z * s.y), index / (s.w * s.z) % s.y, index / s.w % s.z, index % s.w);
}

uint orders_index(uint ir, uint imu, uint imus, uint inu)
{
    return ((ir * SB_ORDERS_GRID_SIZE.y + imu) * SB_ORDERS_GRID_SIZE.z + imus) * SB_ORDERS_GRID_SIZE.w + inu;
}

/* Altitude of r node i: h_i = Z (q^i - 1) / (q^n - 1), or uniform for q = 1. */
float orders_altitude(uint i)
{
    float n = float(SB_ORDERS_GRID_SIZE.x - 1u), Z = SB_ORDERS_GRID_HEIGHTS.w;
    if (i >= SB_ORDERS_GRID_SIZE.x - 1u)
        return Z;
    vec4 q = SB_ORDERS_GRID_HEIGHTS;
    return q.x == 1.0 ? Z * float(i) / n : Z * (exp(q.y * float(i)) - 1.0) / q.z;
}

/* The continuous r node index of altitude h. */
float orders_altitude_coord(float h)
{
    float n = float(SB_ORDERS_GRID_SIZE.x - 1u), Z = SB_ORDERS_GRID_HEIGHTS.w;
    h = clamp(h, 0.0, Z);
    vec4 q = SB_ORDERS_GRID_HEIGHTS;
    float i = q.x == 1.0 ? h / Z * n : log(1.0 + h / Z * q.z) / q.y;
    return clamp(i, 0.0, n);
}

/* The grid's top (physics.h's sb_orders_top_km), as a thickness: the
 * atmosphere's, or lower where the air above it holds under 1e-6 of its
 * column. Its rays still run to the atmosphere's top. */
float orders_thickness() { return SB_ORDERS_GRID_HEIGHTS.w; }
bool orders_below_top() { return orders_thickness() < atmosphere_thickness(); }

/* From the ground to the horizon seen from the grid's top (the
 * atmosphere's own values where the grid ends at its top: the same bits). */
float orders_horizon_top()
{
    float Z = orders_thickness();
    return orders_below_top() ? sqrt(Z * (2.0 * ground_radius() + Z)) : horizon_top();
}

/* Distance along (h, mu) to the grid's top (0 from above it). */
float orders_distance_to_top(float h, float mu)
{
    float Z = orders_thickness();
    return orders_below_top() ? distance_to_sphere(h, mu, Z, ground_radius() + Z) : distance_to_top(h, mu);
}

/* mu at node imu at altitude h: the first half of the nodes end on the
 * ground, uniform in the ray's length between straight down and the
 * horizon; the second leave the atmosphere, from straight up to the
 * horizon. */
float orders_mu(float h, uint imu)
{
    uint half_count = SB_ORDERS_GRID_SIZE.y / 2u;
    float R = ground_radius(), r = R + h, rho = horizon_distance(h), H = orders_horizon_top();
    if (imu < half_count) {
        float x = float(imu) / float(half_count - 1u), d = h + x * (rho - h);
        return d <= 0.0 ? -1.0 : clamp(-(rho * rho + d * d) / (2.0 * r * d), -1.0, 1.0);
    }
    float x = float(imu - half_count) / float(half_count - 1u), d_min = orders_thickness() - h;
    float d = d_min + x * (rho + H - d_min);
    return d <= 0.0 ? 1.0 : clamp((H * H - rho * rho - d * d) / (2.0 * r * d), -1.0, 1.0);
}

/* The continuous mu node index of (h, mu) in the half `ground` says. */
float orders_mu_coord(float h, float mu, bool ground)
{
    float half_count = float(SB_ORDERS_GRID_SIZE.y / 2u);
    float rho = horizon_distance(h), H = orders_horizon_top();
    if (ground) {
        float d_min = h, d_max = rho, d = distance_to_ground(h, mu);
        float x = d_max > d_min ? (d - d_min) / (d_max - d_min) : 0.0;
        return clamp(x, 0.0, 1.0) * (half_count - 1.0);
    }
    float d_min = max(orders_thickness() - h, 0.0), d_max = rho + H, d = orders_distance_to_top(h, mu);
    float x = d_max > d_min ? (d - d_min) / (d_max - d_min) : 0.0;
    return half_count + clamp(x, 0.0, 1.0) * (half_count - 1.0);
}

/* mu_s at node imus: half the nodes from the lowest (below it no point of
 * the grid sees the sun) to SB_ORDERS_MU_S_SPLIT, the rest on to 1. */
float orders_mu_s(uint imus)
{
    uint low = SB_ORDERS_GRID_SIZE.z / 2u;
    float lo = SB_ORDERS_GRID_MU_S.x, split = SB_ORDERS_GRID_MU_S.y;
    if (imus <= low)
        return lo + (split - lo) * float(imus) / float(low);
    return split + (1.0 - split) * float(imus - low) / float(SB_ORDERS_GRID_SIZE.z - 1u - low);
}

float orders_mu_s_coord(float mu_s)
{
    uint low = SB_ORDERS_GRID_SIZE.z / 2u;
    float lo = SB_ORDERS_GRID_MU_S.x, split = SB_ORDERS_GRID_MU_S.y;
    mu_s = clamp(mu_s, lo, 1.0);
    if (mu_s <= split)
        return (mu_s - lo) / (split - lo) * float(low);
    return float(low) + (mu_s - split) / (1.0 - split) * float(SB_ORDERS_GRID_SIZE.z - 1u - low);
}

/* The sun's azimuth about the vertical from the view's, in [0, pi]. */
float orders_phi(float mu, float mu_s, float nu)
{
    float s = sqrt(max((1.0 - mu * mu) * (1.0 - mu_s * mu_s), 0.0));
    return s > 1e-6 ? acos_precise(clamp((nu - mu * mu_s) / s, -1.0, 1.0)) : 0.0;
}

float orders_nu(float mu, float mu_s, float phi)
{
    return clamp(mu * mu_s + sqrt(max((1.0 - mu * mu) * (1.0 - mu_s * mu_s), 0.0)) * cos(phi), -1.0, 1.0);
}

/* The sun's azimuth at nu node inu: pi x^p, x = inu / (n - 1), p the grid's
 * (SB_ORDERS_GRID_MU_S.w; 1 where views read it log-trigonometrically). */
float orders_node_phi(uint inu)
{
    float n = float(SB_ORDERS_GRID_SIZE.w - 1u), p = SB_ORDERS_GRID_MU_S.w;
    return p == 1.0 ? PI * float(inu) / n : PI * pow(float(inu) / n, p);
}

/* The continuous nu node index of the sun's azimuth phi. */
float orders_phi_coord(float phi)
{
    float n = float(SB_ORDERS_GRID_SIZE.w - 1u), p = SB_ORDERS_GRID_MU_S.w, x = clamp(phi / PI, 0.0, 1.0);
    return n * (p == 1.0 ? x : pow(x, 1.0 / p));
}

/* Between two nodes in mu_s or nu: linear by day; geometric at twilight
 * (both mu_s nodes below the horizon) where both are positive: twilight
 * falls exponentially with the sun's depth and, seen through the limb,
 * with its azimuth, and a line between nodes would lift it (from space at
 * -4 degrees the limb read 23% rms high, with geometric azimuths 2.3%). */
vec3 orders_blend(vec3 a, vec3 b, float f, bool twilight)
{
    vec3 lin = mix(a, b, f);
    if (!twilight)
        return lin;
    /* a select, not arithmetic: where a node is 0 the power is not a number */
    bvec3 pos = greaterThan(min(a, b), vec3(0.0));
    vec3 geo = a * pow(max(b, vec3(1e-30)) / max(a, vec3(1e-30)), vec3(f));
    return mix(lin, geo, pos);
}

/* Where mu_s falls between two nodes: the lower node, the fraction to the
 * next, and whether both lie below the horizon (orders_blend). */
struct OrdersMuS {
    uint i;
    float f;
    bool twilight;
};

OrdersMuS orders_mu_s_cell(float mu_s)
{
    float fs = orders_mu_s_coord(mu_s);
    uint i = min(uint(fs), SB_ORDERS_GRID_SIZE.z - 2u);
    return OrdersMuS(i, fs - float(i), orders_mu_s(i + 1u) <= 0.0);
}

/* The corner nodes and weights of the multilinear read at (h, mu, mu_s, nu). */
struct OrdersCell {
    uint base; /* node (ir, im, ims, inu) */
    vec3 a;    /* fractions in r, mu, nu */
    float as;  /* fraction in mu_s */
    bool twilight;
};

/* The part of a cell the view alone gives (r and mu): what every sun a
 * node of that view has shares. */
struct OrdersViewCell {
    uint base; /* node (ir, im, 0, 0) */
    vec2 a;    /* fractions in r and mu */
};

OrdersViewCell orders_view_cell(float h, float mu, bool ground)
{
    uvec4 s = SB_ORDERS_GRID_SIZE;
    if (orders_below_top()) /* above the grid (a density along a ray): its top's */
        h = min(h, orders_thickness());
    float fr = orders_altitude_coord(h);
    uint ir = min(uint(fr), s.x - 2u);
    uint lo = ground ? 0u : s.y / 2u;
    float fm = orders_mu_coord(h, mu, ground);
    uint im = min(uint(fm), lo + s.y / 2u - 2u);
    return OrdersViewCell(orders_index(ir, im, 0u, 0u), vec2(fr - float(ir), fm - float(im)));
}

/* The cell of view cell v (at the view's cosine mu) for the sun at (mu_s, nu). */
OrdersCell orders_sun_cell(OrdersViewCell v, float mu, float mu_s, float nu)
{
    OrdersMuS ms = orders_mu_s_cell(mu_s);
    float fn = orders_phi_coord(orders_phi(mu, mu_s, nu));
    uint inu = min(uint(fn), SB_ORDERS_GRID_SIZE.w - 2u);
    OrdersCell c;
    c.base = v.base + ms.i * SB_ORDERS_GRID_SIZE.w + inu;
    c.a = vec3(v.a, fn - float(inu));
    c.as = ms.f;
    c.twilight = ms.twilight;
    return c;
}

OrdersCell orders_cell(float h, float mu, float mu_s, float nu, bool ground)
{
    return orders_sun_cell(orders_view_cell(h, mu, ground), mu, mu_s, nu);
}

/* A function `name`(OrdersCell) reading a table of nodes through TABLE(i)
 * (a vec3 at node i): linear in r and mu, in mu_s and nu by orders_blend. */
#define SB_ORDERS_READ(name, TABLE)                                                              \
    vec3 name(OrdersCell c)                                                                      \
    {                                                                                            \
        uvec4 s = SB_ORDERS_GRID_SIZE;                                                           \
        uint sr = s.y * s.z * s.w, sm = s.z * s.w, ss = s.w;                                     \
        vec3 out_value = vec3(0.0);                                                              \
        for (uint dr = 0u; dr < 2u; dr++)                                                        \
            for (uint dm = 0u; dm < 2u; dm++) {                                                  \
                float w = (dr == 1u ? c.a.x : 1.0 - c.a.x) * (dm == 1u ? c.a.y : 1.0 - c.a.y);   \
                uint i = c.base + dr * sr + dm * sm;                                             \
                vec3 v0 = orders_blend(TABLE(i), TABLE(i + ss), c.as, c.twilight);               \
                vec3 v1 = orders_blend(TABLE(i + 1u), TABLE(i + 1u + ss), c.as, c.twilight);     \
                out_value += w * orders_blend(v0, v1, c.a.z, c.twilight);                        \
            }                                                                                    \
        return out_value;                                                                        \
    }

#endif
