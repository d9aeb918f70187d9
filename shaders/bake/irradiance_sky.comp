#version 450
/* Sky light reaching a point in the air, for lighting clouds and haze:
 * the mean radiance over the whole sphere, (1/4pi) * integral of L(x, w) dw,
 * at altitude h with the sun at mu_s, 64x16, nine channels split by what
 * sent the light last:
 *   rayleigh = from Rayleigh scattering: E_sun T_sun sigma_R P_R(nu) + sigma_R psi_ms
 *   mie      = from Mie scattering:      E_sun T_sun sigma_M P_M(nu) + sigma_M psi_ms
 *   ground   = the ground seen directly: T(x,p) albedo/pi E_ground(p)
 * each integrated along the ray with T(x,y). The direct sun is excluded.
 * For an isotropic scatterer, in-scattered radiance = sigma_s * (sum of the
 * three); the runtime may weight them separately. One workgroup per texel
 * (sphere.glsl); by day a quarter of the azimuths, the phase functions
 * weighted by product integration (sphere_azimuths). */
#extension GL_GOOGLE_include_directive : require
#include "config.h"
#include "atmosphere.glsl"
#define SB_SPHERE_BY_COLUMN
#include "sphere.glsl"

layout(std430, set = 0, binding = SB_BINDING_OUTPUT) writeonly buffer Output { float result[]; };

void main()
{
    uvec2 texel = sphere_texel();
    vec2 geometry = subtexel_geometry(texel, uvec2(pc.width, pc.height));
    float h = geometry.x, mu_s = geometry.y;
    float r = ground_radius() + h;
    vec3 sun = atm.solar_irradiance.rgb;
    float sin_s = sqrt(max(1.0 - mu_s * mu_s, 0.0));
    sphere_init(pc.directions_mu, pc.directions_phi, true);
    SpherePieces pieces = sphere_pieces(h, true, mu_s, true);
    SphereCap cap = sphere_cap(h, true, mu_s);

    sphere_begin();
    SphereAzimuths az = sphere_azimuths(h, mu_s, pc.directions_phi);
    uint count = sphere_direction_count(pieces, pc.directions_mu, az.n);
    uint total = count + sphere_cap_direction_count(cap, pc.directions_mu, pc.directions_phi);
    /* One integrate_ray for both grids, so that the invocations integrating
     * the cap's directions and those on the zenith grid run it together. */
    for (uint d = sphere_first_direction(); d < sphere_end_direction(total); d += SB_SPHERE_THREADS) {
        bool on_cap = d >= count; /* Mie single scattering's peak */
        SphereDirection s;
        float nu;
        AzimuthWeights aw;
        if (on_cap) {
            CapDirection cd = sphere_cap_direction(cap, d - count, pc.directions_mu, pc.directions_phi);
            if (cd.phase_weight <= 0.0)
                continue;
            s.mu = cd.mu;
            s.weight = cd.phase_weight;
            s.toward_ground = cd.toward_ground;
            nu = cd.nu;
        } else {
            uint p = d % az.n;
            SphereZenith z = sphere_zenith(pieces, d / (pc.directions_mu * az.n), (d / az.n) % pc.directions_mu);
            s.mu = z.mu;
            s.toward_ground = z.toward_ground;
            s.weight = 2.0 * z.weight;
            float sin_v = sqrt(max(1.0 - s.mu * s.mu, 0.0));
            aw = sphere_azimuth_weights(s.mu * mu_s, sin_v * sin_s, p, az);
            s.cos_phi = aw.cos_phi;
            nu = clamp(sin_v * sin_s * s.cos_phi + s.mu * mu_s, -1.0, 1.0);
        }
        RayIntegrals ri = integrate_ray(h, s.mu, mu_s, nu, s.toward_ground, !on_cap);
        if (on_cap) {
            sphere_add3(3u, s.weight * sun * ri.sun_mie);
            continue;
        }
        sphere_add3(0u, s.weight * (sun * ri.sun_rayleigh * aw.rayleigh + ri.ms_rayleigh * aw.iso));
        sphere_add3(3u, s.weight * (sun * ri.sun_mie * aw.mie + ri.ms_mie * aw.iso));
        if (s.toward_ground) {
            float mu_sp = clamp((r * mu_s + ri.t_end * nu) / ground_radius(), -1.0, 1.0);
            sphere_add3(6u, s.weight * aw.iso * ri.transmittance * atm.ground_albedo.rgb / PI * ground_irradiance_sample(mu_sp));
        }
    }
    if (!sphere_finish(9u) || gl_LocalInvocationIndex != 0u)
        return;
    float norm = 1.0 / (4.0 * PI);
    uint i = (texel.y * pc.width + texel.x) * 9u;
    for (uint c = 0u; c < 9u; c++)
        result[i + c] = sphere_partial[c] * norm;
}
