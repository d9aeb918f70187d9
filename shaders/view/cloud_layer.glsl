/*
 * The volumetric cloud layer's medium and light (docs/clouds.md, "In
 * skyview"), shared by its kernels, the scene and the fog. Positions are
 * q = (world x, altitude, world z) in metres: the noise is laid on the
 * ground's plane horizontally and on the curved planet's altitude
 * vertically. Radiance is scaled like the frame (frame.aerial.y).
 *
 * Density (Schneider 2015 and 2017, Nubis), every step in fp32 and in the
 * order tests/clouds_ref.c repeats in fp64:
 * - f = (altitude - base) / thickness, in (0, 1) inside the layer;
 * - weather w at (q.xz + drift) / tile: c = clamp(w.r + 2 coverage - 1, 0, 1)
 *   (coverage 0.5 keeps the baked map), type w.b;
 * - profile(f, type): a rise over the layer's first tenth, and a fall to the
 *   type's top, mix(0.3, 1, type) of the layer, over its last 40%, each
 *   smoothstep'd: stratus stay low, cumulus fill the layer;
 * - shape s at (q + drift) / tile: base = remap(s.r, fbm(s.gba) - 1, 1)
 *   (fbm = 0.625 g + 0.25 b + 0.125 a), times the profile, then
 *   remap(base, 1 - c, 1) c;
 * - detail d at (q + curl (1 - f) curl_m + drift) / tile (curl =
 *   2 (cloud_curl - 1/2)): m = mix(fbm, 1 - fbm, clamp(10 f, 0, 1)) of
 *   fbm(d.rgb) (wispy at the base, billowy above its lowest tenth), and the
 *   density is remap(base, erosion m, 1);
 * remap(v, lo, hi) = clamp((v - lo) / max(hi - lo, 1e-3), 0, 1).
 * Extinction is the density times layer.w; scattering is albedo times that.
 *
 * Light of a point (per unit scattering):
 * - the sun: E_sun T_atm(h, mu_s) times sum over octaves i of
 *   0.5^i e^(-0.5^i tau) p_i(nu) (Wrenninge 2013; Hillaire 2016), tau the
 *   optical depth toward the sun to the layer's edge or
 *   SB_CLOUD_LIGHT_DISTANCE_M (the runtime marches it in a few pieces
 *   growing linearly), p_i the two Henyey-Greenstein lobes with their g
 *   times 0.5^i;
 * - the ambient: the sky's and the ground's irradiance (irradiance_ground's
 *   ground row, as the scene and fog read it), seen as uniform radiance over
 *   each hemisphere and scattered isotropically, the sky's weighted
 *   mix(1/2, 1, f) and the ground's mix(1, 1/2, f) for the cloud above and
 *   below the point: (E_up mix(.5, 1, f) + E_down mix(1, .5, f)) / 2pi.
 */
#ifndef SB_CLOUD_LAYER_GLSL
#define SB_CLOUD_LAYER_GLSL

#include "clouds_gpu.h"
#include "view.glsl" /* before phase.glsl: its atmosphere.glsl is skyview's */
#include "phase.glsl"
#include "view_gpu.h"

layout(std430, set = 0, binding = SB_VIEW_BINDING_CLOUDS) readonly buffer CloudBuffer {
    sb_clouds_gpu clouds;
};
layout(set = 0, binding = SB_VIEW_BINDING_CLOUD_SHAPE) uniform sampler3D cloud_shape;
layout(set = 0, binding = SB_VIEW_BINDING_CLOUD_DETAIL) uniform sampler3D cloud_detail;
layout(set = 0, binding = SB_VIEW_BINDING_CLOUD_CURL) uniform sampler2D cloud_curl;
layout(set = 0, binding = SB_VIEW_BINDING_CLOUD_WEATHER) uniform sampler2D cloud_weather;
layout(set = 0, binding = SB_VIEW_BINDING_CLOUD_SHADOW) uniform sampler2D cloud_shadow_map;

float cloud_remap(float v, float lo, float hi)
{
    return clamp((v - lo) / max(hi - lo, 1e-3), 0.0, 1.0);
}

float cloud_smoothstep01(float x)
{
    x = clamp(x, 0.0, 1.0);
    return x * x * (3.0 - 2.0 * x);
}

/* How much of the layer's density a cloud of `type` has at height fraction f. */
float cloud_profile(float f, float type)
{
    float top = mix(0.3, 1.0, type);
    return cloud_smoothstep01(f * 10.0) * cloud_smoothstep01((top - f) / (0.4 * top));
}

/* The density, [0, 1], at q = (world x, altitude, world z) in metres;
 * without `detail`, the shape before erosion (cheaper, never smaller). */
float cloud_density(vec3 q, bool detail)
{
    float f = (q.y - clouds.layer.x) * clouds.layer.z;
    if (f <= 0.0 || f >= 1.0)
        return 0.0;
    vec3 w = textureLod(cloud_weather, (q.xz + clouds.weather_offset.xz) * clouds.scales.x, 0.0).rgb;
    float c = clamp(w.r + 2.0 * clouds.albedo.w - 1.0, 0.0, 1.0);
    if (c <= 0.0)
        return 0.0;
    float profile = cloud_profile(f, w.b);
    if (profile <= 0.0)
        return 0.0;
    vec4 s = textureLod(cloud_shape, (q + clouds.shape_offset.xyz) * clouds.scales.y, 0.0);
    float fbm = s.g * 0.625 + s.b * 0.25 + s.a * 0.125;
    float base = cloud_remap(s.r, fbm - 1.0, 1.0) * profile;
    base = cloud_remap(base, 1.0 - c, 1.0) * c;
    if (base <= 0.0 || !detail)
        return base;
    vec3 curl = textureLod(cloud_curl, (q.xz + clouds.weather_offset.xz) * clouds.scales.w, 0.0).rgb * 2.0 - 1.0;
    vec3 p = q + curl * (clouds.erosion.y * (1.0 - f)) + clouds.detail_offset.xyz;
    vec3 d = textureLod(cloud_detail, p * clouds.scales.z, 0.0).rgb;
    float dfbm = d.r * 0.625 + d.g * 0.25 + d.b * 0.125;
    float modifier = mix(dfbm, 1.0 - dfbm, clamp(f * 10.0, 0.0, 1.0));
    return cloud_remap(base, modifier * clouds.erosion.x, 1.0);
}

/* Where a ray from radius r (km) with cosine mu meets the sphere of
 * altitude a_km, from altitude h_km: (near, far) distances in km, or
 * (-1, -1) when it misses. r^2 - R^2 is formed from the altitudes, so it
 * keeps its digits a few metres from the sphere. */
vec2 cloud_sphere_hits(float h_km, float mu, float a_km)
{
    float r = ground_radius() + h_km;
    float c = (h_km - a_km) * (r + ground_radius() + a_km);
    float b = r * mu;
    float disc = b * b - c;
    if (disc < 0.0)
        return vec2(-1.0);
    float s = sqrt(disc);
    float q = b >= 0.0 ? -(b + s) : s - b;
    float t1 = q, t2 = q != 0.0 ? c / q : 0.0;
    return vec2(min(t1, t2), max(t1, t2));
}

/* The distance (m) from altitude h_km along cosine mu to where the ray
 * leaves the layer (for a point inside it). */
float cloud_exit_m(float h_km, float mu)
{
    vec2 top = cloud_sphere_hits(h_km, mu, clouds.layer.y * 1e-3);
    vec2 base = cloud_sphere_hits(h_km, mu, clouds.layer.x * 1e-3);
    float t = top.y;
    if (base.x > 0.0)
        t = min(t, base.x);
    return max(t, 0.0) * 1e3;
}

/* The optical depth toward the key light (unit l) from q (altitude h_km, the light at
 * cosine mu_s there) to the layer's edge or SB_CLOUD_LIGHT_DISTANCE_M, over
 * `steps` pieces growing linearly (piece k is k + 1 units long: fine near
 * the point, where the light's attenuation matters most), each read at
 * `jitter` of its length (the view march's, so frames average it). */
float cloud_light_depth(vec3 q, vec3 l, float h_km, float mu_s, int steps, float jitter)
{
    float reach = min(cloud_exit_m(h_km, mu_s), SB_CLOUD_LIGHT_DISTANCE_M);
    float unit = reach / (0.5 * float(steps) * float(steps + 1));
    float tau = 0.0;
    for (int k = 0; k < steps; k++) {
        float length_m = unit * float(k + 1);
        float s = unit * (0.5 * float(k) * float(k + 1)) + jitter * length_m;
        vec3 p = vec3(q.x + l.x * s, altitude_along(h_km, mu_s, s * 1e-3) * 1e3, q.z + l.z * s);
        tau += cloud_density(p, true) * length_m;
    }
    return tau * clouds.layer.w;
}

/* The light a point scatters toward the viewer per unit scattering
 * (albedo included), scaled like the frame: `up` is its local vertical,
 * l and key the key light's direction and irradiance above the atmosphere
 * (the frame's, read once by the caller), h_km its altitude, f its height
 * fraction, nu the cosine between the view ray and the light; jitter places
 * the light march's samples. */
vec3 cloud_light(vec3 q, vec3 up, vec3 l, vec3 key, float h_km, float f, float nu, int light_steps, float jitter)
{
    float mu_s = dot(up, l);
    vec3 sun = key * sun_transmittance_rgb(h_km, mu_s);
    float octaves = 0.0;
    if (max(sun.r, max(sun.g, sun.b)) > 0.0) {
        float tau = cloud_light_depth(q, l, h_km, mu_s, light_steps, jitter);
        float a = 1.0;
        for (int i = 0; i < int(clouds.phase.w); i++) {
            float p = mix(phase_hg(clouds.phase.y * a, nu), phase_hg(clouds.phase.x * a, nu), clouds.phase.z);
            octaves += a * exp(-a * tau) * p;
            a *= 0.5;
        }
    }
    vec3 e_up, e_down;
    sky_irradiance(up, e_up, e_down);
    vec3 ambient = (e_up * mix(0.5, 1.0, f) + e_down * mix(1.0, 0.5, f)) / (2.0 * PI);
    return clouds.albedo.rgb * (sun * octaves + ambient) * frame.aerial.y;
}

/* The part of the view ray along unit d (world) inside the layer, in
 * metres from the camera: from below, the base's exit to the top's; from
 * inside, to the first exit; from above, the top's entry to the base's
 * entry or the top's exit. (A ray that leaves the layer and comes back,
 * grazing the base from inside or above it, is cut at the first exit.)
 * False when it misses the layer or meets the ground first. */
bool cloud_segment(vec3 d, out float t0, out float t1)
{
    float h = frame.camera_km.w, base = clouds.layer.x * 1e-3, top = clouds.layer.y * 1e-3;
    float mu = dot(normalize(frame.camera_km.xyz), d);
    vec2 hb = cloud_sphere_hits(h, mu, base), ht = cloud_sphere_hits(h, mu, top);
    t0 = 0.0;
    t1 = 0.0;
    if (h < base) {
        if (ray_hits_ground(h, mu))
            return false;
        t0 = hb.y;
        t1 = ht.y;
    } else if (h < top) {
        t1 = hb.x > 0.0 ? min(ht.y, hb.x) : ht.y;
    } else {
        if (ht.x <= 0.0)
            return false;
        t0 = ht.x;
        t1 = hb.x > 0.0 ? hb.x : ht.y;
    }
    t0 *= 1e3;
    t1 *= 1e3;
    return t1 > t0;
}

/* The clouds' transmittance toward the sun for a world point p (m) under
 * the layer: the shadow map read where the sun's ray through p meets the
 * ground's plane. 1 without clouds. */
float cloud_sun_transmittance(vec3 p)
{
    if (clouds.erosion.z == 0.0)
        return 1.0;
    vec3 l = key_direction();
    vec2 g = p.xz - l.xz * (p.y / max(l.y, 0.02));
    vec2 uv = (g - clouds.shadow.xy) / clouds.shadow.z + 0.5;
    return exp(-textureLod(cloud_shadow_map, uv, 0.0).r);
}

#endif
