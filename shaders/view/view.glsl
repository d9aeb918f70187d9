/*
 * What skyview's passes share: the frame's constants, the sky-view LUT's
 * mapping, the sun's and the moon's disks, the sky's irradiance, and the atmosphere read from the pack (the baked
 * transmittance for the sun, see SB_SUN_TRANSMITTANCE_LUT; psi_ms from its
 * refined form, SB_MULTISCATTERING_REFINED in config.h; both as textures,
 * SB_ATMOSPHERE_TEXTURES in atmosphere.glsl).
 */
#ifndef SB_VIEW_GLSL
#define SB_VIEW_GLSL

#include "view_gpu.h"

#define SB_SUN_TRANSMITTANCE_LUT
#define SB_MULTISCATTERING_REFINED
#define SB_ATMOSPHERE_TEXTURES
#define SB_ORDERS_TEXTURE
#include "atmosphere.glsl"

/* True when the pack has the orders product (runtime/pass.c specializes
 * every kernel): orders 2 and up come from it, not from psi_ms. */
layout(constant_id = SB_VIEW_CONSTANT_ORDERS) const bool SB_VIEW_ORDERS = false;
bool orders_present() { return SB_VIEW_ORDERS; }
/* True when it has the spectral products too (they come with the orders):
 * the sky is drawn at their 12 wavelengths (sky_radiance_rgb). */
layout(constant_id = SB_VIEW_CONSTANT_BANDS) const bool SB_VIEW_BANDS = false;

#include "sky_radiance.glsl"

#include "frame.glsl"

/* The orders product (config.h; baker/orders.h), its grid in the frame's
 * constants (orders.glsl). */
#define SB_ORDERS_GRID_DECLARED
#define SB_ORDERS_GRID_SIZE frame.orders_size
#define SB_ORDERS_GRID_HEIGHTS frame.orders_heights
#define SB_ORDERS_GRID_MU_S frame.orders_mu_s
#include "orders.glsl"

layout(set = 0, binding = SB_VIEW_BINDING_ORDERS) uniform sampler2DArray orders_texture;

vec3 orders_texel(uint i)
{
    uint w = SB_ORDERS_GRID_SIZE.z * SB_ORDERS_GRID_SIZE.w;
    return texelFetch(orders_texture, ivec3(int(i % w), int(i / w), atm_band), 0).rgb;
}

SB_ORDERS_READ(orders_read_texels, orders_texel)

/* The weights of the SB_ORDERS_NU_DUST azimuth nodes (the runtime's grid:
 * runtime/atmosphere.c) at the sun's azimuth phi in the trigonometric
 * interpolation through them (baker/orders_ref.c's azimuth_weights): the
 * cardinal functions of 2 (n - 1) points about the circle, a node counting
 * for its mirror image too; cos(m phi) by Chebyshev's recurrence, the
 * nodes' cosines constants. */
void orders_azimuth_weights(float phi, out float w[SB_ORDERS_NU_DUST])
{
    const uint n = SB_ORDERS_NU_DUST, M = 2u * (n - 1u);
    float cm[M / 2u + 1u];
    cm[0] = 1.0;
    cm[1] = cos(phi);
    for (uint m = 2u; m <= M / 2u; m++)
        cm[m] = 2.0 * cm[1] * cm[m - 1u] - cm[m - 2u];
    for (uint j = 0u; j < n; j++) {
        float d = 1.0 + cm[M / 2u] * cos(PI * float(M / 2u * j) / float(n - 1u));
        for (uint m = 1u; m < M / 2u; m++)
            d += 2.0 * cm[m] * cos(PI * float(m * j) / float(n - 1u));
        w[j] = (j == 0u || j == n - 1u ? 1.0 : 2.0) * d / float(M);
    }
}

/* By day, the table at texel position p (in texels; the sampler filters
 * across whatever fraction p holds, mu's and nu's or mu's alone) of cell
 * c's lower r and mu_s nodes, linear in r and mu_s over the cell: 4 reads. */
vec3 orders_day_texels(OrdersCell c, vec2 p)
{
    uvec4 s = SB_ORDERS_GRID_SIZE;
    vec2 texel = 1.0 / vec2(textureSize(orders_texture, 0).xy);
    vec2 step_s = vec2(float(s.w), 0.0), step_r = vec2(0.0, float(s.y));
    float layer = float(atm_band);
    vec3 v0 = mix(textureLod(orders_texture, vec3(p * texel, layer), 0.0).rgb,
                  textureLod(orders_texture, vec3((p + step_r) * texel, layer), 0.0).rgb, c.a.x);
    vec3 v1 = mix(textureLod(orders_texture, vec3((p + step_s) * texel, layer), 0.0).rgb,
                  textureLod(orders_texture, vec3((p + step_s + step_r) * texel, layer), 0.0).rgb, c.a.x);
    return mix(v0, v1, c.as); /* by day orders_blend is this */
}

/* By day where the grid says so (orders_mu_s.z: sb_orders_log_azimuth, a
 * peaked dust's forward peak), the sun's azimuth log-trigonometrically through
 * every azimuth node, kept between the two about it, linearly where a node
 * is not positive (orders_ref.h): the sampler filters mu alone, 4 reads a
 * node. */
vec3 orders_sky_log_azimuth(OrdersCell c)
{
    uvec4 s = SB_ORDERS_GRID_SIZE, n = orders_node(c.base);
    float y = float(n.x * s.y + n.y) + c.a.y + 0.5;
    float w[SB_ORDERS_NU_DUST];
    orders_azimuth_weights((float(n.w) + c.a.z) * PI / float(SB_ORDERS_NU_DUST - 1u), w);
    vec3 lg = vec3(0.0), a = vec3(0.0), b = vec3(0.0);
    bvec3 positive = bvec3(true);
    for (uint j = 0u; j < SB_ORDERS_NU_DUST; j++) {
        vec3 u = orders_day_texels(c, vec2(float(n.z * s.w + j) + 0.5, y));
        positive = bvec3(uvec3(positive) & uvec3(greaterThan(u, vec3(0.0))));
        lg += w[j] * log(max(u, vec3(1e-30)));
        a = j == n.w ? u : a;
        b = j == n.w + 1u ? u : b;
    }
    return mix(mix(a, b, c.a.z), clamp(exp(lg), min(a, b), max(a, b)), positive);
}

/* The table's read (orders.glsl's SB_ORDERS_READ); by day with the
 * sampler's bilinear filter doing mu and nu (adjacent texels of a node's
 * row and column; the sampler is linear): 4 reads instead of 16. The
 * filter's weights are fixed-point on some GPUs (8 bits on NVIDIA's):
 * within 1/512 of a step between neighbours. At twilight nu is geometric,
 * which the filter cannot do: 16 reads; so is a peaked dust's day
 * (orders_sky_log_azimuth). */
vec3 orders_sky(float h, float mu, float mu_s, float nu, bool ground)
{
    if (orders_below_top() && h > orders_thickness()) { /* from above the grid: where the view enters it */
        float Z = orders_thickness(), r = ground_radius() + h, top = ground_radius() + Z;
        float b = r * mu, c2 = (r - top) * (r + top), disc = b * b - c2;
        if (mu >= 0.0 || disc < 0.0)
            return vec3(0.0);
        float t = c2 / (-b + sqrt(disc));
        mu = clamp((r * mu + t) / top, -1.0, 1.0);
        mu_s = clamp((r * mu_s + t * nu) / top, -1.0, 1.0);
        h = Z;
    }
    OrdersCell c = orders_cell(h, mu, mu_s, nu, ground);
    if (c.twilight)
        return orders_read_texels(c);
    if (SB_ORDERS_GRID_MU_S.z > 0.5)
        return orders_sky_log_azimuth(c);
    uvec4 s = SB_ORDERS_GRID_SIZE, n = orders_node(c.base);
    return orders_day_texels(c, vec2(float(n.z * s.w + n.w) + c.a.z + 0.5, float(n.x * s.y + n.y) + c.a.y + 0.5));
}

/* The ground's irradiance from the sky (the table's last row). */
vec3 orders_ground_sky(float mu_s)
{
    OrdersMuS c = orders_mu_s_cell(mu_s);
    uint k = orders_node_count() + c.i * SB_ORDERS_GRID_SIZE.w; /* a row of nu texels a mu_s node */
    return orders_blend(orders_texel(k), orders_texel(k + SB_ORDERS_GRID_SIZE.w), c.f, c.twilight);
}

/* Orders 2 and up scattered into the view from altitude h (cosine mu, the
 * light's mu_s and nu) between the eye and distance t on it, whose
 * transmittance is t_to: the whole view's (at_eye, orders_eye's) minus what
 * lies beyond t, seen through it (Bruneton's). */
vec3 orders_eye(float h, float mu, float mu_s, float nu)
{
    return orders_sky(h, mu, mu_s, nu, ray_hits_ground(h, mu));
}

vec3 orders_between(vec3 at_eye, float h, float mu, float mu_s, float nu, float t, vec3 t_to)
{
    float r0 = ground_radius() + h, h1 = altitude_along(h, mu, t), r1 = ground_radius() + h1;
    float mu1 = clamp((r0 * mu + t) / r1, -1.0, 1.0), mu_s1 = clamp((r0 * mu_s + t * nu) / r1, -1.0, 1.0);
    return max(at_eye - t_to * orders_sky(h1, mu1, mu_s1, nu, ray_hits_ground(h, mu)), vec3(0.0));
}

/* ---- The sky at 12 wavelengths (the spectral products) ----------------------- */
/* Band b's (0 to 3) three wavelengths to linear Rec.709 (the frame's
 * spectral_rgb): a band's radiance, computed as a scene's three channels
 * are, adds M L to the colour. */
mat3 band_to_rgb(int b)
{
    return mat3(frame.spectral_rgb[3 * b].rgb, frame.spectral_rgb[3 * b + 1].rgb, frame.spectral_rgb[3 * b + 2].rgb);
}

/* sky_radiance as the frame shows it, linear Rec.709 in the scene's units:
 * the scene's three channels, or with the spectral products each band's
 * sky (its medium, transmittance, ground and orders: layer 1 + b) summed
 * through band_to_rgb. */
vec3 sky_radiance_rgb(float h, float mu, float mu_s, float nu)
{
    if (!SB_VIEW_BANDS)
        return sky_radiance(h, mu, mu_s, nu);
    vec3 L = vec3(0.0);
    for (int b = 0; b < SB_SPECTRAL_BANDS; b++) {
        atm_band = 1 + b;
        L += band_to_rgb(b) * sky_radiance(h, mu, mu_s, nu);
    }
    atm_band = 0;
    return L;
}

/* A transmittance as a colour: what white light (the scene's sun) keeps of
 * each channel, given T at each band (band_t[b], layer 1 + b's): the sun's
 * spectrum through the bands, read as Rec.709, over the sun's colour. */
vec3 bands_transmittance_rgb(vec3 band_t[SB_SPECTRAL_BANDS])
{
    vec3 rgb = vec3(0.0);
    for (int b = 0; b < SB_SPECTRAL_BANDS; b++)
        rgb += band_to_rgb(b) * (band_t[b] * atm_layers[1 + b].solar_irradiance.rgb);
    return rgb / max(atm_layers[0].solar_irradiance.rgb, vec3(1e-30));
}

/* The transmittance LUT read as the frame shows it (as sky_radiance_rgb). */
vec3 transmittance_rgb(float h, float mu)
{
    if (!SB_VIEW_BANDS)
        return transmittance_lut_sample(h, mu);
    vec3 band_t[SB_SPECTRAL_BANDS];
    for (int b = 0; b < SB_SPECTRAL_BANDS; b++) {
        atm_band = 1 + b;
        band_t[b] = transmittance_lut_sample(h, mu);
    }
    atm_band = 0;
    return bands_transmittance_rgb(band_t);
}

/* The sun's transmittance to altitude h (cosine mu_s), as the frame shows
 * it: what lights the world, the fog and the clouds. */
vec3 sun_transmittance_rgb(float h, float mu_s)
{
    if (!SB_VIEW_BANDS)
        return sun_transmittance(h, mu_s);
    /* sun_transmittance's, band by band (SB_SUN_TRANSMITTANCE_LUT) */
    return ray_hits_ground(h, mu_s) ? vec3(0.0) : transmittance_rgb(h, mu_s);
}

layout(push_constant) uniform ViewPush {
    sb_view_push pc;
};

/* Interleaved gradient noise (Jimenez 2014) of a pixel, in [0, 1): a
 * different value for each neighbour, their mean over any 3 x 3 near 1/2. */
float interleaved_noise(vec2 pixel)
{
    return fract(52.9829189 * fract(dot(floor(pixel), vec2(0.06711056, 0.00583715))));
}

/* The unit view ray from the camera through uv of the frame (0 to 1, x
 * right, y down; a pixel's centre is at (pixel + 0.5) / size). */
vec3 view_ray(vec2 uv)
{
    vec4 point = frame.inv_view_proj * vec4(uv * 2.0 - 1.0, 0.5, 1.0);
    return normalize(point.xyz / point.w);
}

/* Planet-centred position (km) of a camera-relative world offset (m). */
vec3 planet_position(vec3 offset_m)
{
    return frame.camera_km.xyz + offset_m * 1e-3;
}

/* The sky-view LUT (after Hillaire 2020): u is the azimuth from the sun,
 * phi = pi u^2, dense toward the sun; v is the zenith angle, split at the
 * horizon (the ray that grazes the planet) with a square law on each side,
 * so rows crowd toward the horizon from above and below. */
float horizon_zenith_angle(float h)
{
    /* pi/2 plus the horizon's dip, atan(rho / R): pi - asin(R / r) would
     * lose the dip to rounding a few metres above the ground. */
    return 0.5 * PI + atan(horizon_distance(h), ground_radius());
}

/* (azimuth from the sun, zenith angle) of LUT coordinates uv at altitude h. */
vec2 sky_view_angles(vec2 uv, float h)
{
    float theta_h = horizon_zenith_angle(h);
    float theta;
    if (uv.y < 0.5) {
        float c = 1.0 - 2.0 * uv.y;
        theta = theta_h * (1.0 - c * c);
    } else {
        float c = 2.0 * uv.y - 1.0;
        theta = theta_h + (PI - theta_h) * c * c;
    }
    return vec2(PI * uv.x * uv.x, theta);
}

vec2 sky_view_uv(float phi, float theta, float h)
{
    float theta_h = horizon_zenith_angle(h);
    float v = theta < theta_h ? 0.5 * (1.0 - sqrt(max(1.0 - theta / theta_h, 0.0)))
                              : 0.5 * (1.0 + sqrt(max((theta - theta_h) / (PI - theta_h), 0.0)));
    return vec2(sqrt(clamp(phi / PI, 0.0, 1.0)), v);
}

/* Where the sky-view LUT of the light toward l (its layer: frame.glsl's
 * lights) holds direction d from the camera (inside the atmosphere): the
 * azimuth from the light about the zenith, the zenith angle, at the
 * camera's altitude. */
vec2 sky_view_uv_toward(vec3 d, vec3 l)
{
    vec3 up = normalize(frame.camera_km.xyz);
    float h = clamp(frame.camera_km.w, 0.0, atmosphere_thickness()); /* as the LUT was made */
    float mu = clamp(dot(up, d), -1.0, 1.0), mu_s = clamp(dot(up, l), -1.0, 1.0);
    vec3 d_flat = d - up * mu, l_flat = l - up * mu_s;
    float len = length(d_flat) * length(l_flat);
    float cos_phi = len > 1e-7 ? clamp(dot(d_flat, l_flat) / len, -1.0, 1.0) : 1.0;
    return sky_view_uv(acos(cos_phi), acos(mu), h);
}

/* The sun's disk along a view direction at angle cos_angle from its centre:
 * radiance with limb darkening I(m)/I(1) = 1 - u (1 - m), u = 0.6 (a
 * visible-band value), normalised so the disk delivers the solar
 * irradiance; zero outside the disk. Multiply by the transmittance toward it. */
vec3 sun_disk(float cos_angle)
{
    float alpha = frame.sun_direction.w;
    if (cos_angle < frame.camera_forward.w)
        return vec3(0.0);
    float s = sqrt(max(1.0 - cos_angle * cos_angle, 0.0)) / sin(alpha);
    float m = sqrt(max(1.0 - s * s, 0.0));
    const float u = 0.6;
    float darkening = (1.0 - u * (1.0 - m)) / (1.0 - u / 3.0);
    return atm.solar_irradiance.rgb / (PI * alpha * alpha) * darkening;
}

/* The moon's disk along view direction d: radiance where d meets it, zero
 * elsewhere. Its surface scatters as the lunar regolith does, by Lommel and
 * Seeliger's mu0 / (mu0 + mu) (mu0: the cosine to the sun, mu: to the
 * viewer), lit where the sun reaches it, so its phase shows; normalised
 * (frame.moon_light.w, renderer.c) so the disk delivers the moon's
 * irradiance. Multiply by the transmittance toward it. */
vec3 moon_disk(vec3 d)
{
    vec3 m = frame.moon_direction.xyz;
    float alpha = frame.moon_direction.w, c = dot(d, m);
    if (alpha == 0.0 || c < cos(alpha))
        return vec3(0.0);
    vec3 x = (d - m * c) / sin(alpha); /* on the disk, its radius 1 */
    float mu = sqrt(max(1.0 - dot(x, x), 0.0));
    float mu0 = dot(x - m * mu, frame.sun_direction.xyz);
    float shading = mu0 > 0.0 ? mu0 / (mu0 + mu) : 0.0;
    return atm.solar_irradiance.rgb * frame.moon_light.rgb * (shading * frame.moon_light.w);
}

/* The sky's irradiance at the ground under every light in the sky, on a
 * surface facing up (e_up) and, from the lit ground, one facing down
 * (e_down), for local vertical `up`: irradiance_ground's rows, read at each
 * light's height. */
void sky_irradiance(vec3 up, out vec3 e_up, out vec3 e_down)
{
    float mu = dot(up, frame.sun_direction.xyz);
    e_up = ground_sky_irradiance_sample(mu);
    e_down = ground_irradiance_sample(mu);
    for (int i = 0; i < moon_lights(); i++) {
        mu = dot(up, frame.moon_direction.xyz);
        e_up += frame.moon_light.rgb * ground_sky_irradiance_sample(mu);
        e_down += frame.moon_light.rgb * ground_irradiance_sample(mu);
    }
    e_down *= atm.ground_albedo.rgb;
}

/* Where a ray from planet-centred p along unit d enters the atmosphere
 * (0 when p is inside); -1 when it misses the atmosphere. */
float atmosphere_entry(vec3 p, vec3 d)
{
    float r2 = dot(p, p), top = top_radius();
    if (r2 <= top * top)
        return 0.0;
    float b = dot(p, d);
    float disc = b * b - (r2 - top * top);
    if (b >= 0.0 || disc < 0.0)
        return -1.0;
    return -b - sqrt(disc);
}

/* Keep stored radiance finite in fp16 (65504). */
vec3 fp16_safe(vec3 c)
{
    return min(c, vec3(65000.0));
}

#endif
