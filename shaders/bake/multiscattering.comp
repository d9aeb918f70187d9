#version 450
/* Hillaire 2020's multiple-scattering transfer psi_ms(h, mu_s), 32x32 RGB,
 * including the ground bounce:
 *   L2  = 1/(4 pi) * integral over the sphere of L'(x, w) dw,
 *   L'  = integral of T(x,y) sigma_s(y) T_sun(y) / (4 pi) dt
 *         + [ray hits ground] T(x,p) albedo/pi max(mu_s(p), 0) T_sun(p),
 *   f   = 1/(4 pi) * integral over the sphere of integral of T(x,y) sigma_s(y) dt dw,
 *   psi = E_sun L2 / (1 - f).
 * The azimuth is integrated first, in the ring table (sun_rings.glsl): one
 * ray per zenith direction, pc.directions_mu Gauss-Legendre nodes a piece of
 * the zenith grid (sphere.glsl): a workgroup a texel on a CPU device, a ray
 * an invocation on a GPU (SB_SPHERE_RAYS). */
#extension GL_GOOGLE_include_directive : require
#include "config.h"
#define SB_RAY_OZONE_CORNERS
#define SB_RAY_LEVELS_DOUBLING /* with the corners, no less accurate: a quarter faster */
#include "atmosphere.glsl"
#define SB_SPHERE_BY_COLUMN
#include "sphere.glsl"
#include "sun_rings.glsl"

layout(std430, set = 0, binding = SB_BINDING_OUTPUT) writeonly buffer Output { float result[]; };

void main()
{
    uvec2 texel = sphere_texel();
    vec2 geometry = subtexel_geometry(texel, uvec2(pc.width, pc.height));
    float h = geometry.x, mu_s = geometry.y;
    RingColumn col = ring_column(mu_s);
    sphere_init(pc.directions_mu, 0u, false);
    SpherePieces pieces = sphere_pieces(h, true, mu_s, false);

    sphere_begin();
    uint count = uint(pieces.count) * pc.directions_mu;
    for (uint d = sphere_first_direction(); d < sphere_end_direction(count); d += SB_SPHERE_THREADS) {
        SphereZenith z = sphere_zenith(pieces, d / pc.directions_mu, d % pc.directions_mu);
        float sin_v = sqrt(max(1.0 - z.mu * z.mu, 0.0));
        float t_end = z.toward_ground ? distance_to_ground(h, z.mu) : distance_to_top(h, z.mu);
        RayCuts cuts = ring_cuts(h, z.mu, col);
        /* The phase is isotropic: Rayleigh and Mie are summed per node. */
        vec3 tau = vec3(0.0), lit = vec3(0.0), scattered = vec3(0.0);
        for (float t0 = 0.0; t0 < t_end;) {
            float t1 = ray_next_cut(cuts, t0, t_end);
            float half_len = 0.5 * (t1 - t0);
            float tn[4], hs[4];
            Medium m[4];
            ray_segment_nodes(h, z.mu, t0, t1, tn, hs, m);
            t0 = t1;
            vec3 tw[4]; /* the nodes' exponentials before their table reads: 6% faster than interleaved */
            ray_node_weights(tau, half_len, m, tw);
            for (int i = 0; i < 4; i++) {
                vec3 scattering = tw[i] * (m[i].scattering_rayleigh + m[i].scattering_mie);
                lit += scattering * ring_table_sample(texel.x, col, hs[i], ring_tan_along(h, z.mu, sin_v, tn[i], hs[i]));
                scattered += scattering;
            }
            ray_advance(tau, half_len, m);
        }
        vec3 lp = lit / (4.0 * PI);
        if (z.toward_ground)
            lp += exp(-tau) * atm.ground_albedo.rgb / PI
                * ring_ground_sample(texel.x, col, ring_tan_along(h, z.mu, sin_v, t_end, 0.0));
        float weight = 2.0 * PI * z.weight; /* both halves of the azimuth */
        sphere_add3(0u, weight * lp);
        sphere_add3(3u, weight * scattered);
    }
    if (!sphere_finish(6u) || gl_LocalInvocationIndex != 0u)
        return;
    vec3 l2 = sphere_sum3(0u) / (4.0 * PI);
    vec3 f = sphere_sum3(3u) / (4.0 * PI);
    vec3 psi = atm.solar_irradiance.rgb * l2 / (1.0 - f);
    uint i = (texel.y * pc.width + texel.x) * 3u;
    result[i + 0u] = psi.r;
    result[i + 1u] = psi.g;
    result[i + 2u] = psi.b;
}
