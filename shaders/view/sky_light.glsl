/* The sky's radiance toward d, as the probes (probe_sky.comp) and the
 * reflection cubes (reflection_relight.comp) are relit from it, in the
 * pack's units: the sky-view LUT (a layer a light in the sky; the planet's
 * lit ground below the horizon included, the sun's and the moon's disks
 * not: a disk's light is the key light's direct light), or the same
 * integral per direction from the top of the atmosphere for a camera
 * above it (the world is on the ground: its sky seen from there). */
#ifndef SB_SKY_LIGHT_GLSL
#define SB_SKY_LIGHT_GLSL

#include "view_gpu.h"
#include "view.glsl"

layout(set = 0, binding = SB_VIEW_BINDING_SKY_VIEW) uniform sampler2DArray sky_view;

vec3 sky_light_radiance(vec3 d)
{
    vec3 up = normalize(frame.camera_km.xyz);
    bool inside = frame.camera_km.w < atmosphere_thickness();
    vec3 L = vec3(0.0);
    for (int i = 0; i < sky_light_count(); i++) {
        vec3 l = light_direction(i);
        if (inside) {
            L += textureLod(sky_view, vec3(sky_view_uv_toward(d, l), float(i)), 0.0).rgb / frame.aerial.y;
        } else {
            float mu = clamp(dot(up, d), -1.0, 1.0), mu_s = clamp(dot(up, l), -1.0, 1.0);
            L += sky_radiance_rgb(0.0, mu, mu_s, clamp(dot(d, l), -1.0, 1.0)) * light_color(i);
        }
    }
    return L;
}

#endif
