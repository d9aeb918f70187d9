// How a reflection cube's surface texel is lit, shared by the bake's
// capture (bake/reflection_capture.comp) and skyview's relight
// (view/reflection_relight.comp), so that a relit cube is the baked one
// under another sun: a Lambertian point lit by each light through the
// transmittance LUT at its altitude with a shadow ray, and by the sky
// through its transfer (config.h, SB_RELIGHT_VEC4S).
//
// The includer has included atmosphere.glsl and bvh.glsl and declared
// `vec4 sky_sh[SB_PROBE_SH]` (rgb: the sky's radiance as order-2 SH)
// before including this.
#ifndef SB_RELIGHT_GLSL
#define SB_RELIGHT_GLSL

// The lift off a surface point x (m, world) for the rays that leave it:
// 0.1 mm and 2e-6 of its coordinates' scale (their fp32 rounding).
float relight_lift(vec3 x)
{
    return 1e-4 + 2e-6 * max(abs(x.x), max(abs(x.y), abs(x.z)));
}

// The altitude (km) of a point x seen from a probe at `probe` (m, world,
// y up from the ground).
float relight_altitude(vec3 probe, vec3 x)
{
    return clamp(max(probe.y, 0.0) * 1e-3 + (x.y - probe.y) * 1e-3, 0.0, atmosphere_thickness());
}

// The irradiance a light toward unit l brings to point x (altitude h km)
// of normal n: above the atmosphere 1, through the transmittance LUT, 0
// where a caster blocks the shadow ray.
vec3 relight_light(vec3 x, vec3 n, float h, vec3 l)
{
    float nl = dot(n, l);
    if (nl <= 0.0)
        return vec3(0.0);
    vec3 t = sun_transmittance(h, clamp(l.y, -1.0, 1.0));
    float eps = relight_lift(x);
    if (max(t.r, max(t.g, t.b)) <= 0.0 || bvh_trace(x + n * eps, l, eps, 1e30, true).triangle != SB_BVH_MISS)
        return vec3(0.0);
    return atm.solar_irradiance.rgb * t * nl;
}

// The sky's irradiance through a point's transfer: sum_k T_k L_k, clamped
// at zero.
vec3 relight_sky(float transfer[SB_PROBE_SH])
{
    vec3 e = vec3(0.0);
    for (int k = 0; k < SB_PROBE_SH; k++)
        e += sky_sh[k].rgb * transfer[k];
    return max(e, vec3(0.0));
}

#endif
