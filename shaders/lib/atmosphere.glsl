/*
 * The atmosphere model shared by every bake shader and, later, the runtime:
 * medium densities, phase functions, LUT parameterisations, and the ray
 * integrals built from them. Include after config.h.
 *
 * Units: lengths in km, coefficients in 1/km, angles as cosines. Altitudes
 * are carried instead of radii wherever they are subtracted, because r is
 * about 6360 km and fp32 keeps only ~0.5 m of it (the cancellation-free forms
 * below are what make transmittance good to 1e-5).
 *
 * The fp64 CPU reference in baker/atmosphere_ref.c implements the same model
 * independently; docs/pack.md states the definitions both follow.
 */
#ifndef SB_ATMOSPHERE_GLSL
#define SB_ATMOSPHERE_GLSL

#include "config.h"

#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require

const float PI = 3.14159265358979;

#ifdef SB_ATMOSPHERE_TEXTURES
/* skyview's: the scene's three channels in layer 0 and, with the spectral
 * products, band b's three wavelengths in layer 1 + b, of the parameters
 * and of the transmittance's and the ground irradiance's textures (view.glsl
 * draws the sky band by band: sky_radiance_rgb). A kernel that never sets
 * atm_band reads layer 0, as it did before. */
layout(std430, set = 0, binding = SB_BINDING_ATMOSPHERE) readonly buffer AtmosphereBuffer {
    sb_atmosphere_gpu atm_layers[];
};
int atm_band = 0;
#define atm atm_layers[atm_band]
#else
layout(std430, set = 0, binding = SB_BINDING_ATMOSPHERE) readonly buffer AtmosphereBuffer {
    sb_atmosphere_gpu atm;
};
#endif
/*
 * The bakes read the transmittance LUT and the lookup forms of
 * multiscattering and irradiance_ground (config.h) from storage buffers.
 * skyview (view.glsl defines SB_ATMOSPHERE_TEXTURES) binds the transmittance
 * LUT, multiscattering's refined form (SB_MULTISCATTERING_REFINED) and
 * irradiance_ground's lookup form as RGBA32F textures instead, and reads
 * their texels with texelFetch through the same arithmetic, so the values
 * are the same: llvmpipe loads a storage buffer at an index that varies
 * across a SIMD group one invocation and one component at a time, a texel
 * for the whole group at once (the sky-view LUT 39.7 -> 30.4 ms at 640 x
 * 360 on lavapipe, 0.072 -> 0.052 ms at 1920 x 1080 on an H100;
 * docs/skyview.md).
 */
#ifdef SB_ATMOSPHERE_TEXTURES
#ifndef SB_MULTISCATTERING_REFINED
#error "the refined psi_ms is the only form bound as a texture"
#endif
layout(set = 0, binding = SB_BINDING_TRANSMITTANCE) uniform sampler2DArray transmittance_texture;
layout(set = 0, binding = SB_BINDING_MULTISCATTERING) uniform sampler2D multiscattering_texture;
#else
layout(std430, set = 0, binding = SB_BINDING_TRANSMITTANCE) readonly buffer TransmittanceBuffer {
    float transmittance_lut[];
};
layout(std430, set = 0, binding = SB_BINDING_MULTISCATTERING) readonly buffer MultiscatteringBuffer {
    vec4 multiscattering_log[];
};
#endif
/* A sphere bake (sphere.glsl) built with SB_MULTISCATTERING_SHARED defined
 * before this file reads the multiscattering LUT from a copy in workgroup
 * memory, which sphere_init fills: llvmpipe loads it much faster than a
 * storage buffer (irradiance_sky's bake 10.7 -> 8.3 s), a GPU holds fewer
 * workgroups for it (baker/atmosphere.c chooses by device). */
#ifdef SB_MULTISCATTERING_SHARED
shared vec4 multiscattering_shared[SB_MULTISCATTERING_LOOKUP_TEXELS];
#define SB_MULTISCATTERING_LOG(k) multiscattering_shared[k].rgb
#else
#define SB_MULTISCATTERING_LOG(k) multiscattering_log[k].rgb
#endif
#ifdef SB_ATMOSPHERE_TEXTURES
layout(set = 0, binding = SB_BINDING_IRRADIANCE_GROUND) uniform sampler2DArray ground_irradiance_texture;
#else
layout(std430, set = 0, binding = SB_BINDING_IRRADIANCE_GROUND) readonly buffer IrradianceGroundBuffer {
    float ground_irradiance_log[];
};
#endif

float ground_radius() { return atm.radii.x; }
float top_radius() { return atm.radii.y; }
/* Distance from the ground to the horizon seen from the top. */
float horizon_top() { return atm.radii.z; }
float atmosphere_thickness() { return atm.radii.w; }

/* ---- Medium ---------------------------------------------------------------- */

struct Medium {
    vec3 scattering_rayleigh;
    vec3 scattering_mie;
    vec3 extinction;
};

float ozone_density(float h)
{
    return max(0.0, 1.0 - abs(h - atm.ozone_absorption.w) / atm.ground_albedo.w);
}

/* The ozone tent's corners, k = 0, 1, 2 from the bottom, where its density
 * kinks; they may lie outside the atmosphere. */
float ozone_corner(int k)
{
    return atm.ozone_absorption.w + float(k - 1) * atm.ground_albedo.w;
}

Medium medium_at(float h)
{
    float rayleigh = exp(-h / atm.rayleigh_scattering.w);
    float mie = exp(-h / atm.mie_scattering.w);
    Medium m;
    m.scattering_rayleigh = atm.rayleigh_scattering.rgb * rayleigh;
    m.scattering_mie = atm.mie_scattering.rgb * mie;
    m.extinction = m.scattering_rayleigh + atm.mie_extinction.rgb * mie
                 + atm.ozone_absorption.rgb * ozone_density(h);
    return m;
}

vec3 extinction_at(float h)
{
    return atm.rayleigh_scattering.rgb * exp(-h / atm.rayleigh_scattering.w)
         + atm.mie_extinction.rgb * exp(-h / atm.mie_scattering.w)
         + atm.ozone_absorption.rgb * ozone_density(h);
}

/* Phase functions, normalised over the sphere (1/sr); nu = cos(scattering angle). */
float phase_rayleigh(float nu)
{
    return 3.0 / (16.0 * PI) * (1.0 + nu * nu);
}

/* Cornette-Shanks, as in Bruneton 2017. Its denominator 1 + g^2 - 2 g nu
 * is written as (1 - |g|)^2 + 2 |g| (1 -+ nu): at its peak (nu = +-1 with
 * |g| = 0.999 it is 1e-6) the plain form cancels to fp32 rounding of 2 and
 * lost 30% of the peak, differently with and without FMA contraction. */
float phase_mie(float nu)
{
    float g = atm.mie_extinction.w, ag = abs(g);
    float k = 3.0 / (8.0 * PI) * (1.0 - g * g) / (2.0 + g * g);
    float denom = (1.0 - ag) * (1.0 - ag) + 2.0 * ag * (g >= 0.0 ? 1.0 - nu : 1.0 + nu);
    return k * (1.0 + nu * nu) / pow(max(denom, 1e-12), 1.5);
}

/* ---- Geometry ---------------------------------------------------------------- */

/* atan(y / x) in (-pi, pi] to a few 1e-8: Vulkan lets atan, and acos and
 * asin with it, be 4096 ulp off, and llvmpipe's are off by up to 1e-4 or
 * so, too coarse for angles that are subtracted from each other (the ring
 * table's, sun_rings.glsl). Reduced to |u| <= tan(pi / 12) by the
 * octant and atan(t) = pi / 6 + atan((sqrt(3) t - 1) / (t + sqrt(3))), then
 * Taylor to u^13. */
float atan2_precise(float y, float x)
{
    const float tan_pi_12 = 0.2679491924311228, sqrt3 = 1.7320508075688772;
    float ax = abs(x), ay = abs(y);
    float hi = max(ax, ay), t = hi > 0.0 ? min(ax, ay) / hi : 0.0;
    bool reduced = t > tan_pi_12;
    float u = reduced ? (sqrt3 * t - 1.0) / (t + sqrt3) : t, u2 = u * u;
    float a = u * (1.0 + u2 * (-1.0 / 3.0 + u2 * (1.0 / 5.0 + u2 * (-1.0 / 7.0 + u2 * (1.0 / 9.0
                  + u2 * (-1.0 / 11.0 + u2 * (1.0 / 13.0)))))));
    if (reduced)
        a += PI / 6.0;
    if (ay > ax)
        a = 0.5 * PI - a;
    if (x < 0.0)
        a = PI - a;
    return y < 0.0 ? -a : a;
}

float acos_precise(float x)
{
    return atan2_precise(sqrt(max((1.0 - x) * (1.0 + x), 0.0)), x);
}

/* rho: distance from the point at altitude h to the ground horizon. */
float horizon_distance(float h)
{
    return sqrt(max(h * (2.0 * ground_radius() + h), 0.0));
}

bool ray_hits_ground(float h, float mu)
{
    float r = ground_radius() + h;
    return mu < 0.0 && r * r * mu * mu >= h * (2.0 * ground_radius() + h);
}

/* Distance along (h, mu) to the sphere `thickness` above the ground, of
 * radius `top` (0 from above it), without cancellation looking up. */
float distance_to_sphere(float h, float mu, float thickness, float top)
{
    float r = ground_radius() + h;
    float above = max(thickness - h, 0.0) * (top + r); /* top^2 - r^2 */
    float disc = sqrt(above + r * r * mu * mu);
    return mu >= 0.0 ? above / max(r * mu + disc, 1e-30) : disc - r * mu;
}

float distance_to_top(float h, float mu)
{
    return distance_to_sphere(h, mu, atmosphere_thickness(), top_radius());
}

float distance_to_ground(float h, float mu)
{
    float r = ground_radius() + h;
    float below = h * (2.0 * ground_radius() + h); /* r^2 - ground^2 */
    float disc = sqrt(max(r * r * mu * mu - below, 0.0));
    return below / max(disc - r * mu, 1e-30);
}

/* Altitude at distance t along a ray from altitude h0 with cosine mu. */
float altitude_along(float h0, float mu, float t)
{
    float r0 = ground_radius() + h0;
    float q = t * (t + 2.0 * r0 * mu); /* r(t)^2 - r0^2 */
    float rt = sqrt(max(r0 * r0 + q, 0.0));
    return max(h0 + q / (rt + r0), 0.0);
}

/* ---- Transmittance LUT (Hillaire 2020 / Bruneton 2017) ------------------------ */
/*
 * Texel (x, y): x_mu = (x + 0.5) / W, x_r = (y + 0.5) / H_tex; rho = H x_r,
 * d = d_min + x_mu (d_max - d_min), d_min = top - r, d_max = rho + H.
 * The integral is parameterised by e = d_max - d, which is exact near the
 * horizon where d itself would cancel.
 */

/*
 * Gauss-Legendre of order SB_TRANSMITTANCE_GL_ORDER (1 to 8, default 8) for
 * the transmittance integral: the non-negative nodes on [-1, 1] ascending and
 * their weights (an odd order's first node is 0). The order is fixed when a
 * shader is compiled, so the loops over these small tables unroll.
 */
#ifndef SB_TRANSMITTANCE_GL_ORDER
#define SB_TRANSMITTANCE_GL_ORDER 8
#endif
#define SB_GL_HALF ((SB_TRANSMITTANCE_GL_ORDER + 1) / 2)
#if SB_TRANSMITTANCE_GL_ORDER == 1
const float GL_X[1] = float[1](0.0);
const float GL_W[1] = float[1](2.0);
#elif SB_TRANSMITTANCE_GL_ORDER == 2
const float GL_X[1] = float[1](0.5773502691896258);
const float GL_W[1] = float[1](1.0);
#elif SB_TRANSMITTANCE_GL_ORDER == 3
const float GL_X[2] = float[2](0.0, 0.7745966692414834);
const float GL_W[2] = float[2](0.888888888888889, 0.5555555555555556);
#elif SB_TRANSMITTANCE_GL_ORDER == 4
const float GL_X[2] = float[2](0.3399810435848563, 0.8611363115940526);
const float GL_W[2] = float[2](0.6521451548625461, 0.3478548451374539);
#elif SB_TRANSMITTANCE_GL_ORDER == 5
const float GL_X[3] = float[3](0.0, 0.5384693101056831, 0.906179845938664);
const float GL_W[3] = float[3](0.5688888888888889, 0.4786286704993665, 0.2369268850561891);
#elif SB_TRANSMITTANCE_GL_ORDER == 6
const float GL_X[3] = float[3](0.2386191860831969, 0.6612093864662645, 0.932469514203152);
const float GL_W[3] = float[3](0.467913934572691, 0.3607615730481386, 0.1713244923791703);
#elif SB_TRANSMITTANCE_GL_ORDER == 7
const float GL_X[4] = float[4](0.0, 0.4058451513773972, 0.7415311855993943, 0.9491079123427585);
const float GL_W[4] = float[4](0.4179591836734694, 0.3818300505051189, 0.2797053914892767, 0.1294849661688697);
#elif SB_TRANSMITTANCE_GL_ORDER == 8
const float GL_X[4] = float[4](0.1834346424956498, 0.525532409916329, 0.7966664774136267, 0.9602898564975362);
const float GL_W[4] = float[4](0.362683783378362, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763);
#else
#error SB_TRANSMITTANCE_GL_ORDER must be 1 to 8
#endif

/* Altitude along an ascending path from a base point (altitude hb, radius rb)
 * whose ray has tangential offset sb >= 0: r(t)^2 = rb^2 + t^2 + 2 sb t. */
float path_altitude(float hb, float rb, float sb, float t)
{
    float q = t * (t + 2.0 * sb);
    return hb + q / (sqrt(rb * rb + q) + rb);
}

/* Distance along that path to altitude level (> hb). */
float path_distance_to_level(float hb, float sb, float level)
{
    float c = (level - hb) * (2.0 * ground_radius() + level + hb);
    return c / (sb + sqrt(sb * sb + c));
}

/* Optical depth of the path between t0 and t1 by Gauss-Legendre on each of
 * `subdivisions` equal pieces; nodes in +- pairs around each piece's middle. */
vec3 path_segment_depth(float hb, float rb, float sb, float t0, float t1, int subdivisions)
{
    const bool odd = (SB_TRANSMITTANCE_GL_ORDER & 1) != 0;
    float step = (t1 - t0) / float(subdivisions);
    vec3 sum = vec3(0.0);
    for (int k = 0; k < subdivisions; k++) {
        float half_len = 0.5 * step, mid = t0 + (float(k) + 0.5) * step;
        vec3 piece = odd ? GL_W[0] * extinction_at(path_altitude(hb, rb, sb, mid)) : vec3(0.0);
        for (int i = odd ? 1 : 0; i < SB_GL_HALF; i++) {
            float dt = half_len * GL_X[i];
            piece += GL_W[i] * (extinction_at(path_altitude(hb, rb, sb, mid - dt))
                                + extinction_at(path_altitude(hb, rb, sb, mid + dt)));
        }
        sum += piece * half_len;
    }
    return sum;
}

/*
 * A ray from inside the atmosphere to its top, as the transmittance
 * quadrature takes it: rho, its origin's horizon distance; g = H - rho
 * (H^2 - rho^2 = top^2 - r^2 = g (H + rho)); d, its length; and e = d_max -
 * d, d_max = rho + H being the horizon ray's. Each is computed where it
 * does not cancel: d and e are both kept because near the horizon d is
 * nearly d_max (only e holds the ray's place), and for a short ray from the
 * top e is nearly d_max (only d does; the top row of the LUT, where a
 * 28 km ray had lost 4 m of its fold from e alone).
 */
struct TransmittanceRay {
    float rho, g, d, e;
};

/* e = d_max - d of the ray with horizon distance rho, s = r mu and above =
 * top^2 - r^2, without the cancellation of the two near the horizon: with
 * d + s = sqrt(s^2 + H^2 - rho^2), (rho + H + s)^2 - (d + s)^2 = 2 (rho +
 * H)(rho + s), and rho + s >= 0 on the rays that miss the ground. */
float transmittance_ray_e(float rho, float s, float above)
{
    float H = horizon_top();
    return 2.0 * (rho + H) * max(rho + s, 0.0) / (rho + H + s + sqrt(s * s + above));
}

/* The ray from altitude h with view cosine mu (missing the ground). */
TransmittanceRay transmittance_ray(float h, float mu)
{
    TransmittanceRay ray;
    float r = ground_radius() + h;
    ray.rho = horizon_distance(h);
    float above = max(atmosphere_thickness() - h, 0.0) * (top_radius() + r); /* top^2 - r^2 */
    ray.g = above / (horizon_top() + ray.rho);
    ray.d = distance_to_top(h, mu);
    ray.e = transmittance_ray_e(ray.rho, r * mu, above);
    return ray;
}

/* r mu at the ray's origin, from top^2 = r^2 + 2 r mu d + d^2: in e where
 * e is the shorter (its terms cancel least there), else in d. */
float transmittance_ray_s0(TransmittanceRay ray)
{
    float H = horizon_top(), rho = ray.rho;
    float num = ray.e < ray.d ? (2.0 * (H + rho)) * (ray.e - rho) - ray.e * ray.e : ray.g * (H + rho) - ray.d * ray.d;
    return num / (2.0 * ray.d);
}

/* top - r, the shortest ray's length (looking up). */
float transmittance_ray_d_min(TransmittanceRay ray)
{
    float R = ground_radius(), H = horizon_top();
    return ray.g * (H + ray.rho) / (top_radius() + sqrt(ray.rho * ray.rho + R * R));
}

/*
 * A transmittance ray as an ascending path: a downward ray is folded at its
 * tangent point, whose altitude hb, radius rb it starts from (sb = 0) after
 * running `fold` down to it; an upward ray starts at its origin (fold 0, sb
 * = r mu). Returns the path's length above the base, t_end; the ray's
 * length is fold + t_end. Returns -1 for an empty ray (at the top, looking
 * along it or up).
 */
float transmittance_path(TransmittanceRay ray, out float hb, out float rb, out float sb, out float fold)
{
    float R = ground_radius(), H = horizon_top();
    float rho = ray.rho, d = ray.d, e = ray.e;
    float r = sqrt(rho * rho + R * R);
    hb = rb = sb = fold = 0.0;
    if (d <= 0.0)
        return -1.0;
    float s0 = transmittance_ray_s0(ray);
    if (s0 < 0.0) {
        float del = e * (ray.g + d) / (2.0 * d); /* rho + s0, exactly: (2H - e) e / (2d), 2H - e = g + d */
        float q = max((2.0 * rho - del) * del, 0.0); /* r_min^2 - R^2 */
        rb = sqrt(R * R + q);
        hb = q / (rb + R);
        fold = -s0;
        return d + s0;
    }
    hb = rho * rho / (r + R);
    rb = r;
    sb = s0;
    return d;
}

/*
 * The next altitude above a (km) where the transmittance integral is cut:
 * the ozone tent's corners (the only kinks of the integrand), and in a
 * thick atmosphere altitudes 16 H, 32 H, 64 H ... of the largest scale
 * height H, so that no piece spans more than half its altitude of an
 * exponential tail (an atmosphere as thick as its planet needs them: 1% of
 * error without; the earth's, 100 km thick with H = 8 km, has none).
 */
float next_boundary(float a)
{
    float centre = atm.ozone_absorption.w, half_width = atm.ground_albedo.w;
    float best = 3.0e38;
    for (int k = -1; k <= 1; k++) {
        float level = centre + float(k) * half_width;
        if (level > a)
            best = min(best, level);
    }
    float level = 16.0 * max(atm.rayleigh_scattering.w, atm.mie_scattering.w);
    for (int k = 0; k < 32 && level <= a; k++)
        level *= 2.0;
    return level > a ? min(best, level) : best;
}

/*
 * Optical depth to the top along a ray that does not hit the ground, by
 * Gauss-Legendre: the ascending path is cut at next_boundary's altitudes
 * and at the fold (the part below the start altitude is traversed twice),
 * each piece integrated by Gauss-Legendre of SB_TRANSMITTANCE_GL_ORDER on
 * `subdivisions` sub-pieces. On the earth the defaults (8, 1) take at most
 * 40 density samples (five pieces).
 */
vec3 optical_depth_to_top_gl(TransmittanceRay ray, int subdivisions)
{
    float hb, rb, sb, fold;
    float t_end = transmittance_path(ray, hb, rb, sb, fold);
    if (t_end < 0.0)
        return vec3(0.0);

    /* Walk up the path from boundary to boundary (next_boundary) and, for a
     * folded ray, the fold itself, taken by distance since it may lie a
     * fraction of a metre above the base. No sorting and no local arrays. */
    vec3 tau = vec3(0.0);
    float t0 = 0.0, a0 = hb;
    for (int piece = 0; piece < SB_TRANSMITTANCE_MAX_PIECES && t0 < t_end; piece++) {
        float level = next_boundary(a0);
        float t1 = level < atmosphere_thickness() ? min(path_distance_to_level(hb, sb, level), t_end) : t_end;
        if (fold > t0 && fold < t1) {
            t1 = fold;
            a0 = path_altitude(hb, rb, sb, fold);
        } else {
            a0 = level;
        }
        if (t1 > t0) {
            vec3 depth = path_segment_depth(hb, rb, sb, t0, t1, subdivisions);
            tau += t1 <= fold ? 2.0 * depth : depth;
        }
        t0 = t1;
    }
    return tau;
}

vec3 optical_depth_to_top(TransmittanceRay ray)
{
    return optical_depth_to_top_gl(ray, 1);
}

/*
 * The same by a rule of `steps` equally spaced samples over the whole ray
 * (length fold + t_end), as the published bakes integrate it: sampled at
 * `offset` of each step (Hillaire 2020: 0.3, 40 steps; the midpoint rule:
 * 0.5), or by the trapezoidal rule when `trapezoid` (Bruneton 2017: 500
 * steps). Positions come from the same folded path, so only the quadrature
 * differs from optical_depth_to_top_gl.
 */
vec3 optical_depth_to_top_uniform(TransmittanceRay ray, int steps, float offset, bool trapezoid)
{
    float hb, rb, sb, fold;
    float t_end = transmittance_path(ray, hb, rb, sb, fold);
    if (t_end < 0.0)
        return vec3(0.0);
    float length_ = fold + t_end, dt = length_ / float(steps);
    vec3 sum = vec3(0.0);
    int count = trapezoid ? steps + 1 : steps;
    for (int i = 0; i < count; i++) {
        float t = trapezoid ? float(i) * dt : (float(i) + offset) * dt;
        float weight = trapezoid && (i == 0 || i == steps) ? 0.5 : 1.0;
        sum += weight * extinction_at(path_altitude(hb, rb, sb, abs(t - fold)));
    }
    return sum * dt;
}

/* The transmittance LUT's coordinates in unit range for a point and direction
 * whose ray does not hit the ground: x_r = rho / H (Bruneton's), and x_mu =
 * 1 - sqrt((d_max - d) / (d_max - d_min)), which crowds the texels toward
 * the horizon (x_mu = 1), where the optical depth climbs fastest: Bruneton's
 * linear x_mu = (d - d_min) / (d_max - d_min) left the 256 x 64 LUT 3.7e-2
 * off between texels there, this 1.1e-2 (docs/accuracy.md). */
vec2 transmittance_unit_coords(float h, float mu)
{
    /* e and d_max - d_min alone: every lookup of the runtime's comes here */
    float H = horizon_top(), r = ground_radius() + h, rho = horizon_distance(h);
    float above = max(atmosphere_thickness() - h, 0.0) * (top_radius() + r); /* top^2 - r^2 */
    float e = transmittance_ray_e(rho, r * mu, above);
    float span = rho + H - above / (top_radius() + r); /* d_max - d_min, d_min = top - r */
    float x_mu = 1.0 - sqrt(clamp(e / max(span, 1e-30), 0.0, 1.0));
    return vec2(x_mu, rho / H);
}

/* The ray of the transmittance LUT at unit coordinates x, given with their
 * complements xc = 1 - x: e = xc_mu^2 (d_max - d_min), d = d_min + x_mu (1
 * + xc_mu) (d_max - d_min), rho = H x_r, g = H xc_r. A texel's complements
 * come exact from its integers: 1 - x rounded from a rounded x lost up to
 * 2.4e-6 of 1 - x_mu at the LUT's last columns, and that much of e moved a
 * grazing ray's optical depth by 1.3e-5 in the thick atmosphere. */
TransmittanceRay transmittance_unit_ray_split(vec2 x, vec2 xc)
{
    TransmittanceRay ray;
    float H = horizon_top();
    ray.rho = H * x.y;
    ray.g = H * xc.y;
    float d_min = transmittance_ray_d_min(ray), span = ray.rho + H - d_min;
    ray.e = xc.x * xc.x * span;
    ray.d = d_min + x.x * (1.0 + xc.x) * span;
    return ray;
}

TransmittanceRay transmittance_unit_ray(vec2 x)
{
    return transmittance_unit_ray_split(x, 1.0 - x);
}

/* The same ray as altitude and view cosine (the inverse of transmittance_unit_coords). */
void transmittance_unit_geometry(vec2 x, out float h, out float mu)
{
    TransmittanceRay ray = transmittance_unit_ray(x);
    float R = ground_radius(), H = horizon_top();
    float r = sqrt(ray.rho * ray.rho + R * R);
    h = ray.rho * ray.rho / (r + R);
    mu = ray.d > 0.0 ? clamp(transmittance_ray_s0(ray) / r, -1.0, 1.0) : 1.0;
}

/* Exact transmittance to the top by the quadrature above. */
vec3 transmittance_to_top(float h, float mu)
{
    return exp(-optical_depth_to_top(transmittance_ray(h, mu)));
}

/* The optical depth at texel (x, y) of the transmittance LUT, its lookup
 * form (physics.h): skyview's texture, or the bakes' interleaved buffer. */
vec3 transmittance_depth_texel(int x, int y)
{
#ifdef SB_ATMOSPHERE_TEXTURES
    return texelFetch(transmittance_texture, ivec3(x, y, atm_band), 0).rgb;
#else
    int k = (y * SB_TRANSMITTANCE_WIDTH + x) * 3;
    return vec3(transmittance_lut[k], transmittance_lut[k + 1], transmittance_lut[k + 2]);
#endif
}

/* The transmittance LUT read bilinearly in its optical depth (then one
 * exponential), texel i of n at i / (n - 1): the first and last on the
 * domain's edges, the horizon and the ground among them. Bilinear in T
 * itself, which falls exponentially toward the horizon, was 3.3e-2 off
 * between texels where this is 5.8e-3 (docs/accuracy.md). */
vec3 transmittance_lut_sample(float h, float mu)
{
    const ivec2 size = ivec2(SB_TRANSMITTANCE_WIDTH, SB_TRANSMITTANCE_HEIGHT);
    vec2 s = clamp(transmittance_unit_coords(h, mu) * vec2(size - 1), vec2(0.0), vec2(size - 1));
    ivec2 i = min(ivec2(s), size - 2);
    vec2 a = s - vec2(i);
    return exp(-mix(mix(transmittance_depth_texel(i.x, i.y), transmittance_depth_texel(i.x + 1, i.y), a.x),
                    mix(transmittance_depth_texel(i.x, i.y + 1), transmittance_depth_texel(i.x + 1, i.y + 1), a.x),
                    a.y));
}

/* ---- Multiple-scattering LUT and irradiance LUTs -------------------------------- */
/*
 * Both use Bruneton's sub-texel mapping: texel i of n sits at x = i / (n - 1),
 * so the first and last texels hold the domain's edges exactly.
 * Multiple scattering: mu_s = 2 x_u - 1, h = x_v (top - ground).
 * Irradiance (ground and sky): mu_s = 2 x_u - 1, h = x_v (top - ground).
 */
float texel_unit(uint i, uint n)
{
    return float(i) / float(n - 1u);
}

/* (h, mu_s) of texel `texel` of a size.x by size.y sub-texel LUT. */
vec2 subtexel_geometry(uvec2 texel, uvec2 size)
{
    return vec2(atmosphere_thickness() * texel_unit(texel.y, size.y), 2.0 * texel_unit(texel.x, size.x) - 1.0);
}

/* Continuous texel coordinates of (h, mu_s) in such a LUT (texel i at i). */
vec2 subtexel_coords(float h, float mu_s, uvec2 size)
{
    return vec2((mu_s * 0.5 + 0.5) * float(size.x - 1u), h / atmosphere_thickness() * float(size.y - 1u));
}

/*
 * The LUTs a bake reads (psi_ms along rays, ground irradiance for the ground
 * seen from the air) are read by Catmull-Rom of their logarithm (floored at
 * 1e-30) in each axis, the edge texels repeated; the logarithms come
 * precomputed (config.h). C1, because the kinks of a bilinear lookup slow
 * the sphere quadratures down; in log space, because at twilight these LUTs
 * fall by a factor 5 to 7 per texel, where a linear lookup overestimates
 * them by up to 2x. The multiscattering LUT's ghost texels (config.h) stand
 * for the repeated edges; the ground irradiance's rows are clamped.
 */
/* The same weights and taps as physics.c's sb_catmull_rom and
 * sb_cubic_taps: test_atmosphere holds multiscattering_lut_sample to the
 * fp64 lookup built on those (sb_ref_multiscattering_lookup) within 1e-5. */
void catmull_rom(float t, out float w[4])
{
    float t2 = t * t, t3 = t2 * t;
    w[0] = 0.5 * (-t3 + 2.0 * t2 - t);
    w[1] = 0.5 * (3.0 * t3 - 5.0 * t2 + 2.0);
    w[2] = 0.5 * (-3.0 * t3 + 4.0 * t2 + t);
    w[3] = 0.5 * (t3 - t2);
}

/* First of the four texels around continuous texel coordinate f on n texels. */
int cubic_taps(float f, int n, out float w[4])
{
    f = clamp(f, 0.0, float(n - 1));
    int i = min(int(f), n - 2);
    catmull_rom(f - float(i), w);
    return i - 1;
}

vec3 multiscattering_lut_sample(float h, float mu_s)
{
    const int n = SB_MULTISCATTERING_SIZE;
    vec2 f = subtexel_coords(h, mu_s, uvec2(n));
#ifdef SB_MULTISCATTERING_REFINED
    /* skyview's form (config.h): bilinear between the refined nodes. */
    const int m = SB_MULTISCATTERING_REFINED_SIZE;
    vec2 fr = clamp(f * float(SB_MULTISCATTERING_REFINE), vec2(0.0), vec2(float(m - 1)));
    ivec2 i = min(ivec2(fr), ivec2(m - 2));
    vec2 w = fr - vec2(i);
    vec3 lo = mix(texelFetch(multiscattering_texture, i, 0).rgb,
                  texelFetch(multiscattering_texture, i + ivec2(1, 0), 0).rgb, w.x);
    vec3 hi = mix(texelFetch(multiscattering_texture, i + ivec2(0, 1), 0).rgb,
                  texelFetch(multiscattering_texture, i + 1, 0).rgb, w.x);
    return exp(mix(lo, hi, w.y));
#else
    const int stride = n + 2;
    float wx[4], wy[4];
    int x0 = cubic_taps(f.x, n, wx), y0 = cubic_taps(f.y, n, wy);
    int k = (y0 + 1) * stride + x0 + 1; /* the ghost texels sit at -1 and n */
    vec3 sum = vec3(0.0);
    for (int j = 0; j < 4; j++, k += stride)
        sum += wy[j] * (wx[0] * SB_MULTISCATTERING_LOG(k) + wx[1] * SB_MULTISCATTERING_LOG(k + 1)
                        + wx[2] * SB_MULTISCATTERING_LOG(k + 2) + wx[3] * SB_MULTISCATTERING_LOG(k + 3));
    return exp(sum);
#endif
}

/* Row `row` of the ground irradiance lookup (physics.h) at sun cosine mu_s. */
vec3 ground_irradiance_row(int row, float mu_s)
{
    const int n = SB_IRRADIANCE_WIDTH;
    float w[4];
    int x0 = cubic_taps(subtexel_coords(0.0, mu_s, uvec2(n, SB_IRRADIANCE_HEIGHT)).x, n, w);
    vec3 sum = vec3(0.0);
    for (int i = 0; i < 4; i++) {
#ifdef SB_ATMOSPHERE_TEXTURES
        sum += w[i] * texelFetch(ground_irradiance_texture, ivec3(clamp(x0 + i, 0, n - 1), row, atm_band), 0).rgb;
#else
        int k = (row * n + clamp(x0 + i, 0, n - 1)) * 3;
        sum += w[i] * vec3(ground_irradiance_log[k], ground_irradiance_log[k + 1], ground_irradiance_log[k + 2]);
#endif
    }
    return exp(sum);
}

/* Total (direct + sky) irradiance on the ground at sun cosine mu_s. */
vec3 ground_irradiance_sample(float mu_s)
{
    return ground_irradiance_row(0, mu_s);
}

/* Irradiance from the sky alone (no direct sun) on the ground. */
vec3 ground_sky_irradiance_sample(float mu_s)
{
    return ground_irradiance_row(1, mu_s);
}

/* ---- Ray integrals for scattering ---------------------------------------------- */
/*
 * A ray from altitude h0 with cosine mu is cut where it crosses the altitude
 * levels of the atmosphere (geometric in the smallest scale height, see
 * sb_atmosphere_gpu_pack), so each segment spans at most a factor ~2 of
 * density. Each segment is integrated by Gauss-Legendre 4; the transmittance
 * from the ray's origin to each node comes from the same node values through
 * the Gauss-Legendre collocation (integration) matrix, exact for cubic
 * extinction within the segment.
 */
const float GL4_X[4] = float[4](-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526);
const float GL4_W[4] = float[4](0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538);
/* GL4_S[i][j] = integral from -1 to x_i of the j-th Lagrange basis polynomial. */
const float GL4_S[16] = float[16](
    0.1739274225687270, -0.0532083601699975, 0.0252549253788094, -0.0071102993715914,
    0.3762362349997362, 0.3260725774312730, -0.0557608572049417, 0.0134710011890763,
    0.3343838439483776, 0.7079060120674879, 0.3260725774312732, -0.0283813898622823,
    0.3549651445090452, 0.6268902294837367, 0.7053535150325437, 0.1739274225687269);

/* ---- The sun's optical depth in the scattering bakes ---------------------------- */
/*
 * The scattering bakes need the transmittance toward the sun at every node
 * of every ray: integrating it there (40 density samples) was most of their
 * time, and bilinear lookups of the 256x64 LUT are off by up to ~1e-2 near
 * the horizon, which they cannot afford. So they read a table built for
 * them (sun_columns.comp), parameterised by the line the sun's ray lies on
 * rather than by (h, mu), and good to about 1e-5 in optical depth wherever
 * the sun's light counts (docs/accuracy.md):
 *
 * tau = beta_R N_R + beta_M,ext N_M + beta_O N_O, with N the columns of the
 * three constituents' densities from the point to the top. A line of closest
 * radius rc = R + hc to the planet's centre, walked from an origin at
 * altitude hb where its distance to the closest point is sb, is a path of
 * path_altitude: the closest point itself (hb = hc, sb = 0) when the line
 * passes above the ground (hc >= 0, the upper region), else the point where
 * it leaves the ground (hb = 0, sb = g = sqrt(R^2 - rc^2), the lower
 * region). The table holds N_R / rho_R and N_M / rho_M at nodes t along each
 * path, normalised by the densities at the node, which leaves smooth
 * "airmasses" that Catmull-Rom reads to fourth order:
 * - across paths: x = sqrt(hc / thickness) (upper), x = sqrt(g / R) (lower),
 *   so that the grazing paths, where the columns change fastest, are
 *   crowded, and both are even functions of x (the ghost row at x < 0 is the
 *   mirror of x > 0);
 * - along a path: u = asinh(t / sigma) / asinh(t_end / sigma), sigma four
 *   of the smallest scale height, from the origin (u = 0) to the top (1).
 * A ray that sets off toward the closest point (mu < 0 on an upper line)
 * has N = 2 N(closest point) - N(its mirror image). Ozone, whose tent kinks,
 * is integrated exactly instead: Gauss-Legendre 4 on the path's pieces
 * between the tent's corners, where it is a linear function of the
 * altitude. Lines that miss the atmosphere are never looked up.
 */
#ifndef SB_SUN_TRANSMITTANCE_LUT
layout(std430, set = 0, binding = SB_BINDING_SUN_COLUMNS) readonly buffer SunColumnsBuffer {
    vec2 sun_columns[];
};

float sun_columns_sigma()
{
    return 4.0 * min(atm.rayleigh_scattering.w, atm.mie_scattering.w);
}

/* A line's path as an origin (hb, rb = R + hb, sb) and its length to the top. */
struct SunPath {
    float hb, rb, sb, t_end;
};

/* Upper region: the line whose closest point is at altitude hc >= 0; lower
 * region: the line leaving the ground at distance g from its closest point. */
SunPath sun_path(bool lower, float hc_or_g)
{
    SunPath p;
    p.hb = lower ? 0.0 : hc_or_g;
    p.rb = ground_radius() + p.hb;
    p.sb = lower ? hc_or_g : 0.0;
    p.t_end = path_distance_to_level(p.hb, p.sb, atmosphere_thickness());
    return p;
}

/* The table's unit coordinate along a path, and its inverse. */
float sun_columns_u(float t, float t_end)
{
    float sigma = sun_columns_sigma();
    return t_end > 0.0 ? asinh(t / sigma) / asinh(t_end / sigma) : 0.0;
}

float sun_columns_t(float u, float t_end)
{
    float sigma = sun_columns_sigma();
    return sigma * sinh(u * asinh(t_end / sigma));
}

/* Index of node (i, j) of region `lower`, ghosts at -1 and X or U. */
int sun_columns_index(bool lower, int i, int j)
{
    return ((lower ? SB_SUN_COLUMNS_X + 2 : 0) + i + 1) * (SB_SUN_COLUMNS_U + 2) + j + 1;
}

/* Catmull-Rom of the table at unit coordinates (x, u) of a region. */
vec2 sun_columns_sample(bool lower, float x, float u)
{
    float fx = clamp(x, 0.0, 1.0) * float(SB_SUN_COLUMNS_X - 1);
    float fu = clamp(u, 0.0, 1.0) * float(SB_SUN_COLUMNS_U - 1);
    int i0 = min(int(fx), SB_SUN_COLUMNS_X - 2), j0 = min(int(fu), SB_SUN_COLUMNS_U - 2);
    float wx[4], wu[4];
    catmull_rom(fx - float(i0), wx);
    catmull_rom(fu - float(j0), wu);
    vec2 sum = vec2(0.0);
    for (int a = 0; a < 4; a++) {
        vec2 row = vec2(0.0);
        for (int b = 0; b < 4; b++)
            row += wu[b] * sun_columns[sun_columns_index(lower, i0 - 1 + a, j0 - 1 + b)];
        sum += wx[a] * row;
    }
    return sum;
}

/* Rayleigh and Mie densities relative to the ground's. */
vec2 sun_columns_density(float h)
{
    return exp(-h / vec2(atm.rayleigh_scattering.w, atm.mie_scattering.w));
}

/* Distance along a path to where it reaches altitude `level`, within [0, t_end]. */
float sun_path_distance(SunPath p, float level)
{
    if (level <= p.hb)
        return 0.0;
    return level < atmosphere_thickness() ? min(path_distance_to_level(p.hb, p.sb, level), p.t_end) : p.t_end;
}

/* The ozone column of a path from t0 to its top: Gauss-Legendre 4 on the
 * two halves of the tent, where the density is linear in the altitude. The
 * path climbs all the way, so the rest of it, below the tent's lower corner
 * and above its upper one, holds no ozone. */
float sun_ozone_column(SunPath p, float t0)
{
    float centre = atm.ozone_absorption.w, half_width = atm.ground_albedo.w;
    float sum = 0.0, a = max(t0, sun_path_distance(p, centre - half_width));
    for (int k = 0; k < 2; k++) {
        float b = sun_path_distance(p, centre + float(k) * half_width);
        if (b <= a)
            continue;
        float half_len = 0.5 * (b - a), mid = 0.5 * (a + b), piece = 0.0;
        for (int i = 0; i < 4; i++)
            piece += GL4_W[i] * ozone_density(path_altitude(p.hb, p.rb, p.sb, mid + half_len * GL4_X[i]));
        sum += piece * half_len;
        a = b;
    }
    return sum;
}

/* Optical depth toward the sun from altitude h along cosine mu, for a ray
 * that does not hit the ground, from the table. */
vec3 sun_optical_depth(float h, float mu)
{
    float R = ground_radius(), r = R + h, s = r * mu;
    float sin_v = sqrt(max(1.0 - mu * mu, 0.0));
    /* hc = r sin - R without cancelling; a ray setting off downward that
     * rounding puts under the ground grazes it */
    float hc = (h * (2.0 * R + h) - s * s) / (r * sin_v + R);
    /* One lookup for both regions, so that rays of either run it together. */
    bool lower = hc < 0.0 && s >= 0.0;
    float g = lower ? sqrt(-hc * (2.0 * R + hc)) : 0.0; /* sqrt(R^2 - rc^2) */
    hc = max(hc, 0.0);
    SunPath p = sun_path(lower, lower ? g : hc);
    float x = lower ? sqrt(g / R) : sqrt(hc / atmosphere_thickness());
    float t = lower ? h * (2.0 * R + h) / (s + g) : abs(s); /* lower: s - g without cancelling */
    vec2 n = sun_columns_sample(lower, x, sun_columns_u(t, p.t_end)) * sun_columns_density(h);
    float ozone = sun_ozone_column(p, t);
    if (s < 0.0) {
        n = 2.0 * sun_columns_sample(false, x, 0.0) * sun_columns_density(hc) - n;
        ozone = 2.0 * sun_ozone_column(p, 0.0) - ozone;
    }
    return atm.rayleigh_scattering.rgb * max(n.x, 0.0) + atm.mie_extinction.rgb * max(n.y, 0.0)
         + atm.ozone_absorption.rgb * max(ozone, 0.0);
}

#endif /* !SB_SUN_TRANSMITTANCE_LUT */

/* Transmittance toward the sun from altitude h; zero when the planet hides
 * it. The runtime defines SB_SUN_TRANSMITTANCE_LUT and reads the baked LUT,
 * which is what a pack is for; the bakes read their own table (above). */
vec3 sun_transmittance(float h, float mu_s)
{
    if (ray_hits_ground(h, mu_s))
        return vec3(0.0);
#ifdef SB_SUN_TRANSMITTANCE_LUT
    return transmittance_lut_sample(h, mu_s);
#else
    return exp(-sun_optical_depth(h, mu_s));
#endif
}

float level_at(int i)
{
    return i < 4 ? atm.levels_a[i] : (i < 8 ? atm.levels_b[i - 4] : (i < 12 ? atm.levels_c[i - 8] : atm.levels_d[i - 12]));
}

/* Where the ray from altitude h0 with s0 = (R + h0) mu crosses altitude
 * `level`: t1 < t2, or -1 where it does not. */
void ray_level_crossing(float h0, float s0, float level, out float t1, out float t2)
{
    float R = ground_radius();
    float c = (level - h0) * (2.0 * R + level + h0);
    float disc = s0 * s0 + c;
    t1 = t2 = -1.0;
    if (c > 0.0) {
        t1 = s0 >= 0.0 ? c / (s0 + sqrt(disc)) : sqrt(disc) - s0;
    } else if (c < 0.0 && s0 < 0.0 && disc > 0.0) {
        float root = sqrt(disc);
        t1 = -c / (root - s0);
        t2 = root - s0;
    }
}

/*
 * Where a ray is cut into the segments it is integrated on: where it
 * crosses the levels (below), and where what the kernel reads along it
 * jumps or kinks: the planet's shadow and the sun's ozone tangencies
 * (ray_cuts), or the rings' (ring_cuts, sun_rings.glsl). The cuts are kept
 * by what makes them, unsorted, -1 where there is none, past the ray's end
 * where they fall there, and walked in order by ray_next_cut. Every loop
 * over them has a constant count, so the compiler unrolls it and the cuts
 * live in registers. Sorted into an array indexed at run time, which
 * llvmpipe keeps in memory, they made the scattering bakes 11 to 16% slower
 * there and 7 to 18% on an H100 (docs/accuracy.md, "A ray's cuts in
 * registers").
 *
 * The levels a ray is cut at: the geometric ones and, where the shader
 * defines SB_RAY_OZONE_CORNERS, the ozone tent's corners, where the density
 * kinks. Gauss-Legendre 4 across such a kink was the scattering bakes'
 * largest error (2.2e-4 of multiscattering at 16 x 12 directions, 9.2e-5
 * with the cuts; docs/accuracy.md). The runtime's rays go without: their
 * frame time counts more than that error.
 *
 * A shader that defines SB_RAY_LEVELS_DOUBLING is cut at levels a factor 2
 * apart instead (every second one of the atmosphere's on the earth), from
 * the same first level up to SB_RAY_DOUBLING_LEVELS of them: 2^9 of it is
 * 256 of the smallest scale height, past where any air counts (the
 * atmosphere's own levels stop at SB_MAX_LEVELS, which in one as thick as
 * its planet leaves a last segment thousands of kilometres long, too long
 * at a factor 2). With the ozone corners, multiscattering's rings lose no
 * accuracy that way (docs/accuracy.md, "Levels a factor 2 apart").
 */
#ifdef SB_RAY_LEVELS_DOUBLING
#define SB_RAY_DOUBLING_LEVELS 10
#define SB_RAY_GEOMETRIC_LEVELS SB_RAY_DOUBLING_LEVELS
#else
#define SB_RAY_GEOMETRIC_LEVELS SB_MAX_LEVELS
#endif
#ifdef SB_RAY_OZONE_CORNERS
#define SB_RAY_CUT_LEVELS (SB_RAY_GEOMETRIC_LEVELS + 3)
#else
#define SB_RAY_CUT_LEVELS SB_RAY_GEOMETRIC_LEVELS
#endif

/* Geometric level i a ray is cut at, or a negative altitude where there is none. */
float ray_geometric_level(int i)
{
#ifdef SB_RAY_LEVELS_DOUBLING
    float level = level_at(0) * exp2(float(i)); /* exact: a power of two */
    return level < atmosphere_thickness() ? level : -1.0;
#else
    return i < int(atm.level_count.x) ? level_at(i) : -1.0;
#endif
}
/* two per shadow cylinder (ray_cuts), or the closest point and four per
 * cylinder (ring_cuts); the ground and the three ozone corners */
#define SB_RAY_EXTRA_CUTS 17

struct RayCuts {
    float level[2 * SB_RAY_CUT_LEVELS];
    float extra[SB_RAY_EXTRA_CUTS];
};

/* The ray's level crossings, and no other cuts yet. */
RayCuts ray_level_cuts(float h0, float mu)
{
    RayCuts cuts;
    float s0 = (ground_radius() + h0) * mu;
    [[unroll]] for (int i = 0; i < SB_RAY_CUT_LEVELS; i++) {
        float t1, t2;
        float level = i < SB_RAY_GEOMETRIC_LEVELS ? ray_geometric_level(i) : ozone_corner(i - SB_RAY_GEOMETRIC_LEVELS);
        ray_level_crossing(h0, s0, level, t1, t2);
        /* a corner outside the atmosphere crosses no ray inside it */
        bool used = i >= SB_RAY_GEOMETRIC_LEVELS || level >= 0.0;
        cuts.level[2 * i] = used ? t1 : -1.0;
        cuts.level[2 * i + 1] = used ? t2 : -1.0;
    }
    [[unroll]] for (int i = 0; i < SB_RAY_EXTRA_CUTS; i++)
        cuts.extra[i] = -1.0;
    return cuts;
}

/* The cuts of the ray from altitude h0 with cosine mu, sun cosine mu_s and
 * cosine nu between the ray and the sun: its levels, and where the planet's
 * shadow starts or ends along it (the sun's transmittance jumps there) and
 * the sun's ray grazes an ozone corner (it kinks there; at twilight these
 * cuts follow its steep rise out of the shadow). */
RayCuts ray_cuts(float h0, float mu, float mu_s, float nu)
{
    RayCuts cuts = ray_level_cuts(h0, mu);
    /* The sun's ray from the point at t has its tangent point at altitude
     * hc where |y|^2 - (y.s)^2 = (R + hc)^2 with y.s = r0 mu_s + t nu < 0
     * (the ray goes down first): a quadratic in t per cylinder. hc = 0 is
     * the shadow's edge. */
    float R = ground_radius(), r0 = R + h0, a = r0 * mu_s;
    float qa = 1.0 - nu * nu, qb = 2.0 * (r0 * mu - a * nu);
    [[unroll]] for (int k = -1; k < 3; k++) {
        float hc = k < 0 ? 0.0 : ozone_corner(k);
        float qc = (h0 - hc) * (2.0 * R + h0 + hc) - a * a; /* r0^2 - (R + hc)^2 - a^2 */
        float roots[2] = float[2](-1.0, -1.0);
        if (qa > 1e-6) {
            float disc = qb * qb - 4.0 * qa * qc;
            if (disc >= 0.0) {
                float q = -0.5 * (qb + (qb >= 0.0 ? sqrt(disc) : -sqrt(disc)));
                roots[0] = q / qa;
                roots[1] = q != 0.0 ? qc / q : -1.0;
            }
        } else if (abs(qb) > 1e-6) {
            roots[0] = -qc / qb;
        }
        bool used = k < 0 || (hc > 0.0 && hc < atmosphere_thickness());
        [[unroll]] for (int i = 0; i < 2; i++)
            cuts.extra[2 * (k + 1) + i] = used && roots[i] > 0.0 && a + nu * roots[i] < 0.0 ? roots[i] : -1.0;
    }
    return cuts;
}

/* The first cut past t, or t_end. */
float ray_next_cut(RayCuts cuts, float t, float t_end)
{
    float next = t_end;
    [[unroll]] for (int i = 0; i < 2 * SB_RAY_CUT_LEVELS; i++)
        if (cuts.level[i] > t)
            next = min(next, cuts.level[i]);
    [[unroll]] for (int i = 0; i < SB_RAY_EXTRA_CUTS; i++)
        if (cuts.extra[i] > t)
            next = min(next, cuts.extra[i]);
    return next;
}

struct RayIntegrals {
    vec3 sun_rayleigh; /* integral of T(x,y) sigma_s,R(y) T_sun(y) dt */
    vec3 sun_mie;      /* integral of T(x,y) sigma_s,M(y) T_sun(y) dt */
    vec3 ms_rayleigh;  /* integral of T(x,y) sigma_s,R(y) psi_ms(y) dt (when asked) */
    vec3 ms_mie;       /* integral of T(x,y) sigma_s,M(y) psi_ms(y) dt (when asked) */
    vec3 scattering;   /* integral of T(x,y) sigma_s(y) dt */
    vec3 transmittance; /* T(x, end of ray) */
    float t_end;
    vec3 tau;          /* optical depth from x to the end of what was integrated */
};

RayIntegrals ray_integrals_begin()
{
    RayIntegrals o;
    o.sun_rayleigh = o.sun_mie = o.ms_rayleigh = o.ms_mie = o.scattering = o.tau = vec3(0.0);
    o.transmittance = vec3(1.0);
    o.t_end = 0.0;
    return o;
}

/* The nodes of Gauss-Legendre 4 on the segment [t0, t1] of the ray from
 * altitude h0 with cosine mu: their distances, altitudes and media.
 * Altitudes under the ground (a straight ray through the runtime's flat
 * world) read the ground's medium. */
void ray_segment_nodes(float h0, float mu, float t0, float t1, out float ts[4], out float hs[4], out Medium m[4])
{
    float half_len = 0.5 * (t1 - t0), mid = 0.5 * (t1 + t0);
    for (int j = 0; j < 4; j++) {
        ts[j] = mid + half_len * GL4_X[j];
        hs[j] = max(altitude_along(h0, mu, ts[j]), 0.0);
        m[j] = medium_at(hs[j]);
    }
}

/* The weights of a segment's nodes (length 2 half_len, from their media)
 * along the ray: T(x, node) times the node's quadrature weight, tau being
 * the optical depth from x to the segment's start. */
void ray_node_weights(vec3 tau, float half_len, Medium m[4], out vec3 tw[4])
{
    for (int i = 0; i < 4; i++) {
        vec3 depth = tau;
        for (int j = 0; j < 4; j++)
            depth += half_len * GL4_S[i * 4 + j] * m[j].extinction;
        tw[i] = exp(-depth) * (half_len * GL4_W[i]);
    }
}

/* The optical depth tau past that segment. */
void ray_advance(inout vec3 tau, float half_len, Medium m[4])
{
    for (int j = 0; j < 4; j++)
        tau += half_len * GL4_W[j] * m[j].extinction;
}

/* Add the segment [t0, t1] of the ray from altitude h0 with cosine mu (sun
 * cosine mu_s, cosine nu between the ray and the sun) by Gauss-Legendre 4;
 * the segments must come in order along the ray. o.transmittance is left
 * as it was: the caller takes exp(-o.tau) when it needs it (integrate_ray_to
 * does at the ray's end), not three exponentials a segment of which only
 * the last were read. */
void integrate_segment(inout RayIntegrals o, float h0, float mu, float mu_s, float nu, float t0, float t1, bool want_ms)
{
    float half_len = 0.5 * (t1 - t0);
    if (half_len <= 0.0)
        return;
    float r0 = ground_radius() + h0;
    float ts[4], hs[4];
    Medium m[4];
    ray_segment_nodes(h0, mu, t0, t1, ts, hs, m);
    /* The nodes' exponentials before the tables' reads: irradiance_ground
     * 7% faster on the H100 than with the reads first. */
    vec3 tw[4];
    ray_node_weights(o.tau, half_len, m, tw);
    for (int i = 0; i < 4; i++) {
        float mus = clamp((r0 * mu_s + ts[i] * nu) / (ground_radius() + hs[i]), -1.0, 1.0);
        vec3 sun = sun_transmittance(hs[i], mus);
        o.sun_rayleigh += tw[i] * m[i].scattering_rayleigh * sun;
        o.sun_mie += tw[i] * m[i].scattering_mie * sun;
        o.scattering += tw[i] * (m[i].scattering_rayleigh + m[i].scattering_mie);
        if (want_ms) {
            vec3 psi = multiscattering_lut_sample(hs[i], mus);
            o.ms_rayleigh += tw[i] * m[i].scattering_rayleigh * psi;
            o.ms_mie += tw[i] * m[i].scattering_mie * psi;
        }
    }
    ray_advance(o.tau, half_len, m);
    o.t_end = t1;
}

/* Add the ray from altitude h0 with cosine mu from x to t_end, segment by
 * segment between its cuts. */
void integrate_ray_to(inout RayIntegrals o, float h0, float mu, float mu_s, float nu, float t_end, bool want_ms)
{
    RayCuts cuts = ray_cuts(h0, mu, mu_s, nu);
    for (float t0 = 0.0; t0 < t_end;) {
        float t1 = ray_next_cut(cuts, t0, t_end);
        integrate_segment(o, h0, mu, mu_s, nu, t0, t1, want_ms);
        t0 = t1;
    }
    o.transmittance = exp(-o.tau);
}

/* nu: cosine between the ray and the sun; toward_ground: the ray ends on the ground. */
RayIntegrals integrate_ray(float h0, float mu, float mu_s, float nu, bool toward_ground, bool want_ms)
{
    RayIntegrals o = ray_integrals_begin();
    float t_end = toward_ground ? distance_to_ground(h0, mu) : distance_to_top(h0, mu);
    integrate_ray_to(o, h0, mu, mu_s, nu, t_end, want_ms);
    o.t_end = t_end;
    return o;
}

/* Gauss-Legendre node k of n on [a, b] (Golub-Welsch is overkill for n <= 64:
 * Newton on the Legendre recurrence in fp32 converges to a few ulp). */
void gauss_legendre(int k, int n, float a, float b, out float x, out float w)
{
    float z = cos(PI * (float(k) + 0.75) / (float(n) + 0.5));
    float dp = 1.0;
    for (int it = 0; it < 8; it++) {
        float p0 = 1.0, p1 = 0.0;
        for (int j = 1; j <= n; j++) {
            float p2 = p1;
            p1 = p0;
            p0 = ((2.0 * float(j) - 1.0) * z * p1 - (float(j) - 1.0) * p2) / float(j);
        }
        dp = float(n) * (z * p0 - p1) / (z * z - 1.0);
        z -= p0 / dp;
    }
    x = 0.5 * (a + b) - 0.5 * (b - a) * z; /* ascending in k */
    w = (b - a) / ((1.0 - z * z) * dp * dp);
}

#endif
