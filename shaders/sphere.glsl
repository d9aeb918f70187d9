/*
 * Integrals over the sphere of directions around one texel's point, spread
 * over a workgroup: one workgroup per texel, SB_SPHERE_THREADS invocations,
 * each integrating every SB_SPHERE_THREADS-th direction, then a reduction in
 * a fixed order (so the sums are deterministic). Include after atmosphere.glsl.
 *
 * Why not one invocation per texel: a GPU would get 1024 threads for a
 * 32x32 LUT, and llvmpipe (lavapipe) silently ends every loop of an
 * invocation once it has run 65535 loop iterations in all
 * (LP_MAX_TGSI_LOOP_ITERATIONS), which one invocation integrating hundreds
 * of rays exceeds. Spread over 64 invocations, each stays far below it.
 *
 * Directions: Gauss-Legendre with n_mu nodes in mu = cos(zenith) on each
 * piece of sphere_pieces() (the integrand jumps at the horizon, kinks where
 * the ray grazes an ozone corner, and peaks at the sun for Mie scattering),
 * n_phi nodes in azimuth over [0, pi], the integrands being even in azimuth
 * about the sun's vertical plane. Next to the horizon a ray integral
 * behaves like sqrt(|mu - mu_horizon|) (the path through the dense air by
 * the tangent point), so there mu = mu_horizon +- range u^2 with the nodes
 * in u, in which the integrand is smooth; next to the peak the nodes are
 * crowded the same way.
 */
#ifndef SB_SPHERE_GLSL
#define SB_SPHERE_GLSL

layout(local_size_x = SB_SPHERE_THREADS) in;

shared float sphere_node[SB_MAX_DIRECTIONS_MU];
shared float sphere_weight[SB_MAX_DIRECTIONS_MU];
shared float sphere_partial[SB_SPHERE_THREADS * SB_SPHERE_MAX_SUMS];

/*
 * The pieces of [-1, 1] in mu that get n_mu nodes each, as their lower and
 * upper ends: the ground part [-1, mu_horizon] (whole sphere only), then
 * the sky from the horizon up, cut where the ray's tangent point sits at an
 * ozone corner (the density's kinks, which make the ray integral kink as a
 * function of mu), and at `peak` (> 1 for none). Every invocation of the
 * workgroup computes the same list.
 */
struct SpherePieces {
    float lo[SB_SPHERE_MAX_PIECES];
    float hi[SB_SPHERE_MAX_PIECES];
    int count;
    int first_sky; /* index of the piece starting at the horizon */
    float peak;    /* where the pieces were cut for the phase function's peak */
};

SpherePieces sphere_pieces(float h, bool whole_sphere, float peak)
{
    SpherePieces sp;
    sp.peak = peak;
    float r = ground_radius() + h;
    float mu_horizon = whole_sphere ? -horizon_distance(h) / r : 0.0;
    sp.count = 0;
    if (whole_sphere) {
        sp.lo[0] = -1.0;
        sp.hi[0] = mu_horizon;
        sp.count = 1;
    }
    sp.first_sky = sp.count;
    float from = mu_horizon;
    for (int c = -1; c <= 1; c++) {
        float corner = atm.ozone_absorption.w + float(c) * atm.ground_albedo.w;
        if (!whole_sphere || corner <= 0.0 || corner >= h)
            continue;
        /* mu of the ray from altitude h whose tangent point is at `corner` */
        float rc = ground_radius() + corner;
        float mu_c = -sqrt(max((h - corner) * (r + rc), 0.0)) / r;
        if (mu_c > from) {
            sp.lo[sp.count] = from;
            sp.hi[sp.count] = mu_c;
            sp.count++;
            from = mu_c;
        }
    }
    sp.lo[sp.count] = from;
    sp.hi[sp.count] = 1.0;
    sp.count++;
    /* Cut the sky piece holding `peak` there (the sun's direction, where a
     * forward-scattering phase function peaks), so nodes crowd toward it. */
    for (int i = sp.first_sky; i < sp.count; i++)
        if (peak > sp.lo[i] && peak < sp.hi[i]) {
            for (int j = sp.count; j > i + 1; j--) {
                sp.lo[j] = sp.lo[j - 1];
                sp.hi[j] = sp.hi[j - 1];
            }
            sp.lo[i + 1] = peak;
            sp.hi[i + 1] = sp.hi[i];
            sp.hi[i] = peak;
            sp.count++;
            break;
        }
    return sp;
}

/* Gauss-Legendre nodes and weights on [-1, 1], ascending; every invocation
 * of the workgroup must call it. */
void sphere_init(uint n_mu)
{
    uint i = gl_LocalInvocationIndex;
    if (i < n_mu) {
        float x, w;
        gauss_legendre(int(i), int(n_mu), -1.0, 1.0, x, w);
        sphere_node[i] = x;
        sphere_weight[i] = w;
    }
    barrier();
}

struct SphereDirection {
    float mu;            /* cosine of the zenith angle */
    float cos_phi;       /* azimuth from the sun's vertical plane */
    float weight;        /* solid angle, both azimuth halves included */
    bool toward_ground;  /* below the horizon */
};

uint sphere_direction_count(SpherePieces sp, uint n_mu, uint n_phi)
{
    return uint(sp.count) * n_mu * n_phi;
}

SphereDirection sphere_direction(SpherePieces sp, uint d, uint n_mu, uint n_phi)
{
    uint piece = d / (n_mu * n_phi), k = (d / n_phi) % n_mu, p = d % n_phi;
    SphereDirection s;
    s.toward_ground = int(piece) < sp.first_sky;
    float u = 0.5 + 0.5 * sphere_node[k], w_u = 0.5 * sphere_weight[k];
    float lo = sp.lo[piece], hi = sp.hi[piece];
    /* Crowd the nodes toward an end at the horizon or at the peak. */
    bool at_lo = int(piece) == sp.first_sky || lo == sp.peak;
    bool at_hi = s.toward_ground || hi == sp.peak;
    float x = u, dx = 1.0;
    if (at_lo && at_hi) {
        x = u * u * (3.0 - 2.0 * u);
        dx = 6.0 * u * (1.0 - u);
    } else if (at_lo) {
        x = u * u;
        dx = 2.0 * u;
    } else if (at_hi) {
        x = 1.0 - (1.0 - u) * (1.0 - u);
        dx = 2.0 * (1.0 - u);
    }
    s.mu = lo + (hi - lo) * x;
    /* Azimuth: midpoint rule in v; with a peak, phi = pi (v - sin(2 pi v) /
     * (2 pi)), which crowds the nodes toward the sun's side (phi = 0, where
     * the Mie peak is) and keeps the rule's accuracy on the even, periodic
     * integrand. */
    float v = (float(p) + 0.5) / float(n_phi);
    bool crowd = sp.peak <= 1.0;
    float phi = crowd ? PI * (v - sin(2.0 * PI * v) / (2.0 * PI)) : PI * v;
    float dphi = crowd ? PI * (1.0 - cos(2.0 * PI * v)) : PI;
    s.cos_phi = cos(phi);
    s.weight = (hi - lo) * dx * w_u * 2.0 * dphi / float(n_phi);
    return s;
}

/* Sum `count` values per invocation, stored at sphere_partial[i *
 * SB_SPHERE_MAX_SUMS + c], into sphere_partial[c]; a fixed pairwise tree. */
void sphere_reduce(uint count)
{
    uint i = gl_LocalInvocationIndex;
    for (uint stride = SB_SPHERE_THREADS / 2u; stride > 0u; stride >>= 1u) {
        barrier();
        if (i < stride)
            for (uint c = 0u; c < count; c++)
                sphere_partial[i * SB_SPHERE_MAX_SUMS + c] += sphere_partial[(i + stride) * SB_SPHERE_MAX_SUMS + c];
    }
    barrier();
}

void sphere_store(uint c, float value)
{
    sphere_partial[gl_LocalInvocationIndex * SB_SPHERE_MAX_SUMS + c] = value;
}

void sphere_store3(uint c, vec3 value)
{
    sphere_store(c, value.r);
    sphere_store(c + 1u, value.g);
    sphere_store(c + 2u, value.b);
}

vec3 sphere_sum3(uint c)
{
    return vec3(sphere_partial[c], sphere_partial[c + 1u], sphere_partial[c + 2u]);
}

#endif
