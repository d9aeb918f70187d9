/*
 * How skyview lights a point of its world, whether rasterised (scene.frag)
 * or traced (scene_trace.comp): the point lit by the sun and the sky, seen
 * through the air:
 * - the key light (the sun, or the moon at night: frame.glsl): its
 *   irradiance times the baked transmittance toward it, its visibility (the
 *   caller's: shadow maps or a shadow ray) and the clouds' shadow map
 *   (cloud_layer.glsl);
 * - the BRDF: GGX distribution, height-correlated Smith visibility, Schlick
 *   Fresnel, Lambert diffuse (Karis 2013; Filament);
 * - the sky: with probes (probes.glsl), the irradiance they interpolate, the
 *   sky they see and its bounce, for the normal and the mirror direction;
 *   without (or outside their grid), irradiance_ground's sky irradiance
 *   (of every light in the sky: view.glsl's sky_irradiance) on an upward
 *   surface and the ground's bounce for downward ones, blended by
 *   (1 +- n.up) / 2; Karis's analytic environment BRDF for the specular part;
 * - reflections: with the pack's reflection probes (reflections.glsl), the
 *   ambient specular is their prefiltered radiance, parallax-corrected and
 *   blended, times the DFG LUT's split sum x + f0 (y - x) and Filament's
 *   energy compensation 1 + f0 (1 / y - 1); relit for this frame's
 *   lights where the pack has their surfaces (passes/reflections.c), else,
 *   under another sun than the cubes were captured under, scaled by the
 *   sky's irradiance now over then (the sun's own specular is the analytic
 *   term above, never in the cubes);
 * - specular occlusion: the share of the sky-only cube's reflection that a
 *   point's probes see the sky in (probe_specular_occlusion); the rest is
 *   the probes' own light along the mirror direction, so the inside of a
 *   closed room stops reflecting the open sky (the cubes of scene probes
 *   hold their geometry already); and Filament's horizon occlusion for
 *   normal-mapped mirror directions that point under the surface;
 * - aerial perspective: the volume inside its range, else the same
 *   integral per fragment (cameras above the atmosphere, far geometry). */
#ifndef SB_SCENE_SHADING_GLSL
#define SB_SCENE_SHADING_GLSL

#include "view_gpu.h"

#include "view.glsl"
#include "probes.glsl"
#include "reflections.glsl"
#include "aerial.glsl"
#include "cloud_layer.glsl"

/* What the pack and the world hold, fixed when the renderer makes the
 * pipeline, so that the compiler drops what they lack: llvmpipe runs the
 * code of a branch no fragment takes (the reflection probes' cost 2 ms of 17
 * at 640x360; the materials' textures and emission, read by none of the
 * test world's fragments, 70 -> 31 ms of the scene pass). Each stands for
 * the test its data makes at run time, which stays. */
layout(constant_id = 0) const bool SB_SCENE_PROBES = true;      /* probes.grid.w > 0 */
layout(constant_id = 1) const bool SB_SCENE_REFLECTIONS = true; /* reflections.info.z > 0 */
layout(constant_id = 2) const bool SB_SCENE_TEXTURES = true;    /* the world has images (a vertex names one) */
layout(constant_id = 3) const bool SB_SCENE_EMISSION = true;    /* the world has emitting materials */

/* The radiance (times frame.aerial.y) that reaches the camera from the
 * point `offset` m from it, or the debug term frame.size.w asks for: unit
 * shading normal n (a normal map's), the surface's own ng (interpolated),
 * linear albedo, (metallic, perceptual roughness), where the
 * point is in the frame (0 to 1: the aerial perspective volume's uv) and
 * the sun's visibility there; key_part: the key light's direct share of
 * the result (0 in the debug terms), which contact shadows take back. */
vec4 scene_shade(vec3 offset, vec3 n, vec3 ng, vec3 albedo, vec2 metallic_roughness, vec3 emitted, vec2 screen_uv,
                 float visibility, out vec3 key_part)
{
    key_part = vec3(0.0);
    vec3 v = -normalize(offset);
    vec3 l = key_direction();
    vec3 p = planet_position(offset);
    float r = length(p);
    vec3 up = p / r;
    float h = max(r - ground_radius(), 0.0);
    float mu_s = dot(up, l);

    float metallic = clamp(metallic_roughness.x, 0.0, 1.0);
    float roughness = clamp(metallic_roughness.y, 0.045, 1.0);
    float a = roughness * roughness, a2 = a * a;
    vec3 f0 = mix(vec3(0.04), albedo, metallic);
    vec3 diffuse_color = albedo * (1.0 - metallic);

    float n_dot_v = max(dot(n, v), 1e-4);
    float n_dot_l = max(dot(n, l), 0.0);
    vec3 hv = normalize(l + v);
    float n_dot_h = max(dot(n, hv), 0.0), l_dot_h = max(dot(l, hv), 0.0);
    float dd = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    float D = a2 / (PI * dd * dd);
    float V = 0.5 / (n_dot_l * sqrt(n_dot_v * n_dot_v * (1.0 - a2) + a2) +
                     n_dot_v * sqrt(n_dot_l * n_dot_l * (1.0 - a2) + a2));
    vec3 F = f0 + (1.0 - f0) * pow(max(1.0 - l_dot_h, 0.0), 5.0); /* pow of a negative is undefined */
    vec3 brdf = diffuse_color / PI + D * V * F;

    vec3 e_sun = atm.solar_irradiance.rgb * key_color() * sun_transmittance_rgb(h, mu_s);
    float clouds_t = cloud_sun_transmittance(offset + frame.camera_m.xyz);
    if (frame.size.w == SB_DEBUG_CLOUD_SHADOW)
        return vec4(vec3(clouds_t * frame.aerial.y), 1.0); /* read back divided by the scale */
    if (frame.size.w == SB_DEBUG_SUN_VISIBILITY)
        return vec4(vec3(visibility * frame.aerial.y), 1.0);
    vec3 direct = brdf * e_sun * (n_dot_l * visibility * clouds_t);
    vec3 color = direct;

    /* The world is low enough to read the ground row of irradiance_ground. */
    vec3 e_sky, e_bounce;
    sky_irradiance(up, e_sky, e_bounce);
    float n_up = dot(n, up);
    vec3 e_n = e_sky * (0.5 + 0.5 * n_up) + e_bounce * (0.5 - 0.5 * n_up);
    vec3 refl = reflect(-v, n);
    float r_up = dot(refl, up);
    vec3 l_env = (e_sky * (0.5 + 0.5 * r_up) + e_bounce * (0.5 - 0.5 * r_up)) / PI;
    float sky_seen = 1.0;
    if (SB_SCENE_PROBES) {
        probe_sample light;
        float coverage;
        probe_lookup(offset + frame.camera_m.xyz, n, refl, light, coverage);
        e_n = mix(e_n, light.e_n, coverage);
        l_env = mix(l_env, light.e_r / PI, coverage);
        sky_seen = mix(1.0, probe_specular_occlusion(light.sky, refl, roughness), coverage);
    }
    if (frame.size.w == SB_DEBUG_AMBIENT)
        return vec4(fp16_safe(e_n * frame.aerial.y), 1.0);
    const vec4 c0 = vec4(-1.0, -0.0275, -0.572, 0.022), c1 = vec4(1.0, 0.0425, 1.04, -0.04);
    vec4 rr = roughness * c0 + c1;
    float a004 = min(rr.x * rr.x, exp2(-9.28 * n_dot_v)) * rr.x + rr.y;
    vec2 env_ab = vec2(-1.04, 1.04) * a004 + rr.zw;
    vec3 specular = (f0 * env_ab.x + env_ab.y) * l_env;
    if (SB_SCENE_REFLECTIONS && reflections.info.z > 0u) {
        vec3 world_p = offset + frame.camera_m.xyz;
        float hidden;
        vec3 env = reflection_radiance(world_p, refl, roughness, sky_seen, hidden);
        vec2 dfg = reflections.info.w != 0u ? reflection_dfg(n_dot_v, roughness) : vec2(env_ab.y, env_ab.x + env_ab.y);
        vec3 energy = 1.0 + f0 * (1.0 / max(dfg.y, 1e-3) - 1.0);
        /* another sun, where nothing relights the cubes: by the sky's light now over then */
        if (reflections.baked_sun.w == 0.0 && dot(reflections.baked_sun.xyz, l) < 0.99996) {
            float then = dot(reflections.baked_sky_up.rgb, vec3(SB_LUMINANCE_RGB));
            float now = dot(e_sky, vec3(SB_LUMINANCE_RGB));
            env *= then > 0.0 ? clamp(now / then, 0.0, 16.0) : 1.0;
        }
        env += hidden * l_env; /* where the sky is hidden, the probes' light along refl */
        specular = env * (dfg.x + f0 * (dfg.y - dfg.x)) * energy;
    }
    /* Horizon occlusion (Filament): a normal map's mirror direction below
     * the surface's own horizon sees the surface, not the sky. */
    float horizon = min(1.0 + dot(refl, ng), 1.0);
    specular *= horizon * horizon;
    if (frame.size.w == SB_DEBUG_ENV_SPECULAR)
        return vec4(fp16_safe(specular * frame.aerial.y), 1.0);
    color += diffuse_color / PI * e_n + specular + emitted;

    vec3 inscatter, transmittance;
    aerial_perspective(screen_uv, offset, inscatter, transmittance);
    key_part = fp16_safe(direct * frame.aerial.y * transmittance);
    return vec4(fp16_safe(color * frame.aerial.y * transmittance + inscatter), 1.0);
}

#endif
