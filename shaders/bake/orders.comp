#version 450
// Multiple scattering by orders (Bruneton and Neyret 2008; baker/orders.h),
// one of five stages a build (SB_ORDERS_STAGE):
// 0 single: a node an invocation, single scattering along its view without
//   the phase functions, Rayleigh's and Mie's apart (atmosphere.glsl's
//   integrate_ray, the sun read from the transmittance LUT);
// 1 views: a view (r, mu) an invocation, once for all orders: its walk by
//   atmosphere.glsl's segments, cut at the altitude levels (the density has
//   no shadow edge of its own), into the samples stage 4 integrates on:
//   their distances, cells in r and mu, and weights (the transmittance
//   times the air's scattering);
// then for each order k:
// 2 directions: a workgroup an altitude and four suns (mu_s nodes; the
//   components of a vec4), an invocation a direction about the point of
//   SB_ORDERS_DIRECTIONS (Gauss-Legendre 8 below the horizon and 16 above
//   it, 8 azimuths a side of the sun's plane): the direction and order
//   k - 1's radiance from it at each sun (the single scattering tables with
//   their phase functions for k = 2, else the last order's, plus the ground
//   lit by order k - 2 where a direction ends on it);
// 3 density: the same workgroups, an invocation a (mu, nu) node: order k's
//   scattering density at the four suns from those directions:
//   Rayleigh's and Mie's phase functions (the sun's alone, so weighed once
//   for the four) against them, Mie's normalised by its own sum (so that
//   however narrow its peak, a uniform sky is integrated exactly), kept per
//   unit of the air's scattering (it falls with the air, which the altitude
//   nodes cannot follow linearly; the scatter stage multiplies the
//   scattering back where it reads). Workgroups at the ground also
//   integrate the upper hemisphere into the ground's irradiance of order
//   k - 1;
// 4 scatter: a workgroup a view, an invocation a (mu_s, nu) node: order k
//   along the view from the density at its samples; adds it to the sum and
//   keeps the largest values.
//
// Stages 3 and 4 read what the stage before wrote as texels (compute.h's
// sb_buffer_create_texels), for llvmpipe, where most bakes run: it reads a
// storage buffer at addresses that differ per invocation, and workgroup
// memory inside any loop, one component of one invocation at a time, each
// behind a branch; a texel fetch is vector loads, and one load where all
// invocations fetch the same texel. On 2 cores the earth's orders took
// 23.4 s with a node an invocation in the scatter stage and a (r, mu_s)
// pair a workgroup reading workgroup memory in the density's; 9.0 s with
// the density as texels, a view a workgroup and four suns; 3.8 s with the
// directions and the views as texels (the density 0.87 to 0.14 s an order,
// the scatter 0.77 to 0.5). The same bytes each time.
#extension GL_GOOGLE_include_directive : require
#define SB_SUN_TRANSMITTANCE_LUT
#include "config.h"
#include "atmosphere.glsl"
#include "orders.glsl"

layout(local_size_x = SB_ORDERS_THREADS) in;

layout(std430, set = 0, binding = SB_ORDERS_BINDING_SINGLE) buffer SingleBuffer { vec4 single_table[]; };
layout(std430, set = 0, binding = SB_ORDERS_BINDING_PREVIOUS) buffer PreviousBuffer { vec4 previous_table[]; };
#if SB_ORDERS_STAGE == 4
layout(set = 0, binding = SB_ORDERS_BINDING_DENSITY) uniform samplerBuffer density_texels;
#else
layout(std430, set = 0, binding = SB_ORDERS_BINDING_DENSITY) buffer DensityBuffer { vec4 density_table[]; };
#endif
layout(std430, set = 0, binding = SB_ORDERS_BINDING_SUM) buffer SumBuffer { vec4 sum_table[]; };
layout(std430, set = 0, binding = SB_ORDERS_BINDING_GROUND) buffer GroundBuffer { vec4 ground_table[]; };
layout(std430, set = 0, binding = SB_ORDERS_BINDING_STATS) buffer StatsBuffer { uint stats[]; };
#if SB_ORDERS_STAGE == 3
layout(set = 0, binding = SB_ORDERS_BINDING_DIRECTIONS) uniform samplerBuffer directions_texels;
#else
layout(std430, set = 0, binding = SB_ORDERS_BINDING_DIRECTIONS) buffer DirectionsBuffer { vec4 directions[]; };
#endif
#if SB_ORDERS_STAGE == 4
layout(set = 0, binding = SB_ORDERS_BINDING_VIEWS) uniform samplerBuffer views_texels;
#else
layout(std430, set = 0, binding = SB_ORDERS_BINDING_VIEWS) buffer ViewsBuffer { vec4 views[]; };
#endif

/* Stages 1 and 4: each view's samples (config.h's SB_ORDERS_VIEW_SAMPLES):
 * their count, then three vec4s each: the distance, r and mu there and the
 * fraction in r; the transmittance times the air's scattering times the
 * quadrature's weight, and the fraction in mu; the view cell's node. */
#define SAMPLES SB_ORDERS_VIEW_SAMPLES
#if SB_RAY_CUT_LEVELS != SB_MAX_LEVELS
#error "a view is cut at the atmosphere's levels alone"
#endif
uint views_index(uint ir, uint imu)
{
    return (ir * orders.size.y + imu) * (1u + 3u * SAMPLES);
}

/* Stages 2 and 3: a workgroup's directions about the point, four vec4s
 * each: the direction (cos(zenith), sin(zenith), azimuth from the sun's,
 * weight), then the radiance from it, a channel a vec4, the workgroup's
 * four suns in its components. */
#define DIRECTIONS SB_ORDERS_DIRECTIONS
uint directions_index(uint d, uint c)
{
    return ((gl_WorkGroupID.x * gl_NumWorkGroups.y + gl_WorkGroupID.y) * DIRECTIONS + d) * 4u + c;
}

/* Stages 2 to 4 share a workgroup's items (directions or nodes) among
 * the workgroups along z: a GPU wants an invocation an item, llvmpipe
 * hardly minds. */
uint first_item() { return gl_WorkGroupID.z * SB_ORDERS_THREADS + gl_LocalInvocationID.x; }
uint item_stride() { return gl_NumWorkGroups.z * SB_ORDERS_THREADS; }

/* A node's view. */
void node_view(uint index, out float h, out float mu, out float mu_s, out float nu, out bool ground)
{
    uvec4 n = orders_node(index);
    h = orders_altitude(n.x);
    mu = orders_mu(h, n.y);
    mu_s = orders_mu_s(n.z);
    nu = orders_nu(mu, mu_s, orders_node_phi(n.w));
    ground = n.y < orders.size.y / 2u;
}

#if SB_ORDERS_STAGE == 0

void main()
{
    uint i = gl_GlobalInvocationID.x, n = orders_node_count();
    if (i >= n)
        return;
    float h, mu, mu_s, nu;
    bool ground;
    node_view(i, h, mu, mu_s, nu, ground);
    vec3 rayleigh = vec3(0.0), mie = vec3(0.0);
    if (!(ground && h <= 0.0)) { /* on the ground looking into it: no air */
        RayIntegrals ri = integrate_ray(h, mu, mu_s, nu, ground, false);
        rayleigh = ri.sun_rayleigh * atm.solar_irradiance.rgb;
        mie = ri.sun_mie * atm.solar_irradiance.rgb;
    }
    single_table[i] = vec4(rayleigh, 0.0);
    single_table[n + i] = vec4(mie, 0.0);
}

#elif SB_ORDERS_STAGE == 1

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= orders.size.x * orders.size.y)
        return;
    uint ir = i / orders.size.y, imu = i % orders.size.y, at = views_index(ir, imu), n = 0u;
    float h = orders_altitude(ir), mu = orders_mu(h, imu), r0 = ground_radius() + h;
    bool ground = imu < orders.size.y / 2u;
    if (!(ground && h <= 0.0)) { /* on the ground looking into it: no air */
        float t_end = ground ? distance_to_ground(h, mu) : distance_to_top(h, mu);
        RayCuts cuts = ray_level_cuts(h, mu); /* the density has no shadow edge of its own */
        vec3 tau = vec3(0.0);
        for (float t0 = 0.0; t0 < t_end && n + 4u <= SAMPLES;) {
            float t1 = ray_next_cut(cuts, t0, t_end), half_len = 0.5 * (t1 - t0);
            float ts[4], hs[4];
            Medium m[4];
            vec3 tw[4];
            ray_segment_nodes(h, mu, t0, t1, ts, hs, m);
            ray_node_weights(tau, half_len, m, tw);
            for (int k = 0; k < 4; k++, n++) {
                float r = ground_radius() + hs[k];
                float mu_k = clamp((r0 * mu + ts[k]) / r, -1.0, 1.0);
                OrdersViewCell v = orders_view_cell(hs[k], mu_k, ground);
                views[at + 1u + 3u * n] = vec4(ts[k], r, mu_k, v.a.x);
                views[at + 2u + 3u * n] = vec4(tw[k] * (m[k].scattering_rayleigh + m[k].scattering_mie), v.a.y);
                views[at + 3u + 3u * n] = vec4(float(v.base), 0.0, 0.0, 0.0);
            }
            ray_advance(tau, half_len, m);
            t0 = t1;
        }
    }
    views[at] = vec4(float(n), 0.0, 0.0, 0.0);
}

#elif SB_ORDERS_STAGE == 2

#define SINGLE_RAYLEIGH(i) single_table[i].rgb
#define SINGLE_MIE(i) single_table[orders_node_count() + (i)].rgb
#define PREVIOUS(i) previous_table[i].rgb
SB_ORDERS_READ(read_single_rayleigh, SINGLE_RAYLEIGH)
SB_ORDERS_READ(read_single_mie, SINGLE_MIE)
SB_ORDERS_READ(read_previous, PREVIOUS)

/* The ground's irradiance of order j at sun cosine mu_s (j = 0: the sun's). */
vec3 ground_irradiance(uint j, float mu_s)
{
    if (j == 0u)
        return atm.solar_irradiance.rgb * sun_transmittance(0.0, mu_s) * max(mu_s, 0.0);
    OrdersMuS c = orders_mu_s_cell(mu_s);
    uint k = j * orders.size.z + c.i;
    return orders_blend(ground_table[k].rgb, ground_table[k + 1u].rgb, c.f, c.twilight);
}

/* Transmittance from altitude h along mu (ending on the ground) to the ground. */
vec3 transmittance_to_ground(float h, float mu, float d)
{
    float r = ground_radius() + h;
    float mu_g = clamp((r * mu + d) / ground_radius(), -1.0, 1.0);
    /* the reversed ray from the ground point up through x, over the one from x up */
    vec3 a = transmittance_lut_sample(0.0, -mu_g), b = transmittance_lut_sample(h, -mu);
    return min(a / max(b, vec3(1e-30)), vec3(1.0));
}

/* Order k - 1's radiance reaching altitude h from direction (mu_in, nu_in). */
vec3 previous_radiance(float h, float mu_in, float mu_s, float nu_in)
{
    bool ground = ray_hits_ground(h, mu_in);
    OrdersCell c = orders_cell(h, mu_in, mu_s, nu_in, ground);
    vec3 L;
    if (orders.order == 2u)
        L = phase_rayleigh(nu_in) * read_single_rayleigh(c) + phase_mie(nu_in) * read_single_mie(c);
    else
        L = read_previous(c);
    if (ground) {
        float d = distance_to_ground(h, mu_in), r = ground_radius() + h;
        float mu_s_g = clamp((r * mu_s + d * nu_in) / ground_radius(), -1.0, 1.0);
        L += transmittance_to_ground(h, mu_in, d) * atm.ground_albedo.rgb / PI
           * ground_irradiance(orders.order - 2u, mu_s_g);
    }
    return L;
}

void main()
{
    uint ir = gl_WorkGroupID.x, ims0 = gl_WorkGroupID.y * SB_ORDERS_DENSITY_SUNS, t = gl_LocalInvocationID.x;
    uint suns = min(orders.size.z - ims0, uint(SB_ORDERS_DENSITY_SUNS));
    float h = orders_altitude(ir), r = ground_radius() + h;
    float horizon = -horizon_distance(h) / r;
    for (uint d = first_item(); d < DIRECTIONS; d += item_stride()) {
        uint q = d / SB_ORDERS_DIRECTIONS_PHI, f = d % SB_ORDERS_DIRECTIONS_PHI;
        bool sky = q >= SB_ORDERS_DIRECTIONS_GROUND;
        float mu_in, w_mu;
        if (sky)
            gauss_legendre(int(q - SB_ORDERS_DIRECTIONS_GROUND), SB_ORDERS_DIRECTIONS_SKY, horizon, 1.0, mu_in, w_mu);
        else
            gauss_legendre(int(q), SB_ORDERS_DIRECTIONS_GROUND, -1.0, horizon, mu_in, w_mu);
        float phi = PI * (float(f) + 0.5) / float(SB_ORDERS_DIRECTIONS_PHI);
        float s_in = sqrt(max(1.0 - mu_in * mu_in, 0.0));
        directions[directions_index(d, 0u)] = vec4(mu_in, s_in, phi, w_mu * PI / float(SB_ORDERS_DIRECTIONS_PHI));
        vec4 red = vec4(0.0), green = vec4(0.0), blue = vec4(0.0);
        for (uint m = 0u; m < suns; m++) {
            float mu_s = orders_mu_s(ims0 + m), ss = sqrt(max(1.0 - mu_s * mu_s, 0.0));
            float nu_in = clamp(mu_in * mu_s + s_in * ss * cos(phi), -1.0, 1.0);
            vec3 L = previous_radiance(h, mu_in, mu_s, nu_in);
            red[m] = L.r;
            green[m] = L.g;
            blue[m] = L.b;
        }
        directions[directions_index(d, 1u)] = red;
        directions[directions_index(d, 2u)] = green;
        directions[directions_index(d, 3u)] = blue;
    }
}

#elif SB_ORDERS_STAGE == 3

/* Cornette-Shanks without pow: k (1 + c^2) d^-1.5 (phase_mie's form). */
float phase_mie_fast(float c, float g, float ag, float k)
{
    float d = max((1.0 - ag) * (1.0 - ag) + 2.0 * ag * (g >= 0.0 ? 1.0 - c : 1.0 + c), 1e-12);
    return k * (1.0 + c * c) * inversesqrt(d) / d;
}

void main()
{
    uint ir = gl_WorkGroupID.x, ims0 = gl_WorkGroupID.y * SB_ORDERS_DENSITY_SUNS, t = gl_LocalInvocationID.x;
    uint suns = min(orders.size.z - ims0, uint(SB_ORDERS_DENSITY_SUNS));
    float h = orders_altitude(ir);
    /* the ground's irradiance of order k - 1, from the upper hemisphere
     * (the horizon is at mu = 0 there); both mirror images */
    if (ir == 0u && gl_WorkGroupID.z == 0u && t < suns) {
        vec3 e = vec3(0.0);
        for (uint d = SB_ORDERS_DIRECTIONS_GROUND * SB_ORDERS_DIRECTIONS_PHI; d < DIRECTIONS; d++) {
            vec4 v = texelFetch(directions_texels, int(directions_index(d, 0u)));
            vec3 L = vec3(texelFetch(directions_texels, int(directions_index(d, 1u)))[t],
                          texelFetch(directions_texels, int(directions_index(d, 2u)))[t],
                          texelFetch(directions_texels, int(directions_index(d, 3u)))[t]);
            e += 2.0 * v.w * v.x * L;
        }
        ground_table[(orders.order - 1u) * orders.size.z + ims0 + t] = vec4(e, 0.0);
    }
    Medium m = medium_at(h);
    float g = atm.mie_extinction.w, ag = abs(g), k_mie = 3.0 / (8.0 * PI) * (1.0 - g * g) / (2.0 + g * g);
    uint per_slice = orders.size.y * orders.size.w;
    for (uint j = first_item(); j < per_slice; j += item_stride()) {
        uint imu = j / orders.size.w, inu = j % orders.size.w;
        float mu = orders_mu(h, imu), sv = sqrt(max(1.0 - mu * mu, 0.0));
        float phi_s = orders_node_phi(inu);
        /* the phase functions are the sun's alone: once for all the suns */
        vec4 rayleigh_r = vec4(0.0), rayleigh_g = vec4(0.0), rayleigh_b = vec4(0.0);
        vec4 mie_r = vec4(0.0), mie_g = vec4(0.0), mie_b = vec4(0.0);
        float mie_weight = 0.0;
        for (uint d = 0u; d < DIRECTIONS; d++) {
            vec4 v = texelFetch(directions_texels, int(directions_index(d, 0u)));
            float a = mu * v.x, b = sv * v.y;
            float c_plus = clamp(a + b * cos(v.z - phi_s), -1.0, 1.0);
            float c_minus = clamp(a + b * cos(v.z + phi_s), -1.0, 1.0);
            float pr = phase_rayleigh(c_plus) + phase_rayleigh(c_minus);
            float pm = phase_mie_fast(c_plus, g, ag, k_mie) + phase_mie_fast(c_minus, g, ag, k_mie);
            vec4 red = texelFetch(directions_texels, int(directions_index(d, 1u)));
            vec4 green = texelFetch(directions_texels, int(directions_index(d, 2u)));
            vec4 blue = texelFetch(directions_texels, int(directions_index(d, 3u)));
            rayleigh_r += (v.w * pr) * red;
            rayleigh_g += (v.w * pr) * green;
            rayleigh_b += (v.w * pr) * blue;
            mie_r += (v.w * pm) * red;
            mie_g += (v.w * pm) * green;
            mie_b += (v.w * pm) * blue;
            mie_weight += v.w * pm;
        }
        /* per unit of scattering (the reference's density_per_scattering):
         * the scatter stage multiplies by the air's scattering where it reads */
        vec3 s = m.scattering_rayleigh + m.scattering_mie;
        for (uint k = 0u; k < suns; k++) {
            vec3 rayleigh = vec3(rayleigh_r[k], rayleigh_g[k], rayleigh_b[k]), mie = vec3(mie_r[k], mie_g[k], mie_b[k]);
            vec3 J = m.scattering_rayleigh * rayleigh + m.scattering_mie * mie / max(mie_weight, 1e-30);
            J = mix(0.5 * (rayleigh + mie / max(mie_weight, 1e-30)), J / max(s, vec3(1e-30)),
                    greaterThan(s, vec3(0.0)));
            density_table[orders_index(ir, imu, ims0 + k, inu)] = vec4(J, 0.0);
        }
    }
}

#else

#define DENSITY(i) texelFetch(density_texels, int(i)).rgb
SB_ORDERS_READ(read_density, DENSITY)

void main()
{
    uint ir = gl_WorkGroupID.y, imu = gl_WorkGroupID.x, t = gl_LocalInvocationID.x, at = views_index(ir, imu);
    float h = orders_altitude(ir), mu = orders_mu(h, imu), r0 = ground_radius() + h;
    uint n = uint(texelFetch(views_texels, int(at)).x), per_view = orders.size.z * orders.size.w;
    for (uint j = first_item(); j < per_view; j += item_stride()) {
        uint ims = j / orders.size.w, inu = j % orders.size.w;
        float mu_s = orders_mu_s(ims), nu = orders_nu(mu, mu_s, orders_node_phi(inu));
        vec3 L = vec3(0.0);
        for (uint k = 0u; k < n; k++) {
            vec4 p = texelFetch(views_texels, int(at + 1u + 3u * k));
            vec4 w = texelFetch(views_texels, int(at + 2u + 3u * k));
            uint base = uint(texelFetch(views_texels, int(at + 3u + 3u * k)).x);
            float mu_s_k = clamp((r0 * mu_s + p.x * nu) / p.y, -1.0, 1.0);
            L += w.rgb * read_density(orders_sun_cell(OrdersViewCell(base, vec2(p.w, w.w)), p.z, mu_s_k, nu));
        }
        uint i = orders_index(ir, imu, ims, inu);
        previous_table[i] = vec4(L, 0.0);
        vec3 sum = sum_table[i].rgb + L;
        sum_table[i] = vec4(sum, 0.0);
        atomicMax(stats[0], floatBitsToUint(max(L.r, max(L.g, L.b))));
        atomicMax(stats[1], floatBitsToUint(max(sum.r, max(sum.g, sum.b))));
    }
}

#endif
