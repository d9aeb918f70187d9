/*
 * Integrals over the sphere of directions around one texel's point, spread
 * over a workgroup: one workgroup per texel, SB_SPHERE_THREADS invocations,
 * each integrating every SB_SPHERE_THREADS-th direction, then a reduction in
 * a fixed order (so the sums are deterministic). Include after atmosphere.glsl.
 *
 * Why not one invocation per texel: a GPU would get 1024 threads for a
 * 32x32 LUT, and llvmpipe (lavapipe) silently ends every loop of an
 * invocation once it has run 65535 loop iterations in all
 * (LP_MAX_TGSI_LOOP_ITERATIONS, one budget per shader invocation, spent by
 * every loop that is not unrolled), which one invocation integrating
 * hundreds of rays exceeds. Spread over 64 invocations, and over passes of
 * SB_SPHERE_STEPS_PER_PASS directions per invocation (the partial sums wait
 * in the scratch buffer between passes, accumulated in the same order as in
 * one pass, so the result does not depend on the split), each stays far
 * below it, whatever the direction counts. Should a pass still run out, a
 * sentinel loop at its end notices (sphere_finish) and the baker fails
 * instead of returning short sums.
 *
 * A product's kernel: sphere_begin(), then for each of its directions
 * d = sphere_first_direction(), ... < sphere_end_direction(count), step
 * SB_SPHERE_THREADS, sphere_add3() its values, then sphere_finish(), which
 * returns true on the last pass with the sums in sphere_sum3().
 *
 * A GPU may run the same kernel another way instead. Built with
 * SB_SPHERE_RAYS, each invocation integrates one direction, in workgroups
 * of SB_SPHERE_RAY_GROUP, the host dispatching pc.direction_slots /
 * SB_SPHERE_RAY_GROUP of them a texel along z, and sphere_finish() stores
 * the direction's values in the scratch buffer. The texel's workgroup that
 * finishes last (a counter per texel in the scratch buffer) then sums the
 * stored directions as a workgroup of SB_SPHERE_THREADS_CPU would,
 * invocation i those of d = i, i + SB_SPHERE_THREADS_CPU, ... in order,
 * and reduces as above. That is the CPU layout's order to the last
 * operation, so the two layouts differ only where the compilers contract
 * differently. (The sums were a second dispatch before, 0.012 ms of the
 * H200's 0.262 for multiscattering at 12x4; summed by the last workgroups
 * the bake took 0.253.) Why:
 * a workgroup per texel holds a GPU's registers for its widest invocation
 * and its longest ray; multiscattering's one ray a zenith direction (80 to
 * 128 a texel) leaves a quarter of 128 invocations idle, and a walk along a
 * ray is a long chain of dependent work, so what counts is how many rays
 * are walked at once.
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

#include "config.h"
#include "atmosphere.glsl"

layout(local_size_x = SB_SPHERE_THREADS) in;
layout(push_constant) uniform Push { sb_bake_push pc; };

shared float sphere_node[SB_MAX_DIRECTIONS_MU];
shared float sphere_weight[SB_MAX_DIRECTIONS_MU];
shared float sphere_phi_node[SB_MAX_DIRECTIONS_PHI]; /* Gauss-Legendre on [0, 1], for the cap */
shared float sphere_phi_weight[SB_MAX_DIRECTIONS_PHI];
#ifdef SB_SPHERE_RAYS
/* the sums of SB_SPHERE_THREADS_CPU invocations, which the last workgroup of a texel emulates */
#define SB_SPHERE_REDUCED SB_SPHERE_THREADS_CPU
#define SB_SPHERE_SCRATCH_QUALIFIER coherent
#else
#define SB_SPHERE_REDUCED SB_SPHERE_THREADS
#define SB_SPHERE_SCRATCH_QUALIFIER
#endif
shared float sphere_partial[SB_SPHERE_REDUCED * SB_SPHERE_MAX_SUMS];

/* The sums are kept as their bits, so that the texels' counters of
 * SB_SPHERE_RAYS (after every texel's sums) can be atomic. */
layout(std430, set = 0, binding = SB_BINDING_SCRATCH) SB_SPHERE_SCRATCH_QUALIFIER buffer SphereScratch {
    uint sphere_truncated;    /* set when a pass ran out of loop iterations */
    uint sphere_sentinel[3];  /* 1, 1, 0, written by the host */
    uint sphere_partials[];   /* per texel, invocation and sum, between passes; then a counter per texel */
};

float sphere_acc[SB_SPHERE_MAX_SUMS]; /* this invocation's sums */
#ifdef SB_SPHERE_RAYS
uint sphere_count;        /* the texel's directions, as sphere_end_direction saw them */
shared bool sphere_last;  /* this workgroup is the texel's last to finish */
#endif

/*
 * The pieces of [-1, 1] in mu (of [0, 1] for the upper hemisphere) that get
 * n_mu nodes each, as their lower and upper ends, cut where the integrand
 * is not smooth or changes scale:
 * - the horizon (whole sphere): below it rays end on the ground;
 * - below the horizon, two depths of the ray's virtual tangent point (see
 *   sphere_pieces);
 * - above it, where the ray's tangent point sits at an ozone corner (the
 *   density's kinks make the ray integral kink as a function of mu);
 * - above those, where the ray's tangent altitude z is 25 largest scale
 *   heights: the light of the air fades as exp(-z / H), and from high up
 *   a piece reaching the zenith would be too long for that fade;
 * - at the sun's mirror image in the horizontal plane, mu = -mu_s: there
 *   the azimuthal integral kinks, since the rays that start out parallel to
 *   the planet's shadow boundary (mu = mu_s nu) reach azimuth pi there;
 * - for a peaked phase function, at the sun, where the nodes crowd.
 * Every invocation of the workgroup computes the same list.
 */
struct SpherePieces {
    float lo[SB_SPHERE_MAX_PIECES];
    float hi[SB_SPHERE_MAX_PIECES];
    int count;
    int first_sky; /* index of the piece starting at the horizon */
    float peak;    /* mu_s for a peaked phase function, else 2 */
};

/* Cut the piece that strictly contains `mu` there. */
void sphere_split(inout SpherePieces sp, float mu)
{
    for (int i = 0; i < sp.count; i++)
        if (mu > sp.lo[i] && mu < sp.hi[i]) {
            for (int j = sp.count; j > i + 1; j--) {
                sp.lo[j] = sp.lo[j - 1];
                sp.hi[j] = sp.hi[j - 1];
            }
            sp.lo[i + 1] = mu;
            sp.hi[i + 1] = sp.hi[i];
            sp.hi[i] = mu;
            sp.count++;
            if (i < sp.first_sky)
                sp.first_sky++;
            return;
        }
}

SpherePieces sphere_pieces(float h, bool whole_sphere, float mu_s, bool peaked)
{
    SpherePieces sp;
    sp.peak = peaked ? mu_s : 2.0;
    float r = ground_radius() + h;
    float mu_horizon = whole_sphere ? -horizon_distance(h) / r : 0.0;
    sp.count = 0;
    if (whole_sphere) {
        /* Ground rays change character over a few scale heights of
         * virtual depth (R - r sqrt(1 - mu^2), how far below the ground
         * the ray's tangent point lies): from a grazing path through the
         * densest air to a slant one. Cut at a decade either side of the
         * smallest scale height. */
        float depth_scale = min(atm.rayleigh_scattering.w, atm.mie_scattering.w);
        float lower = -1.0;
        for (int k = 1; k >= 0; k--) {
            float depth = (k == 1 ? 25.0 : 2.5) * depth_scale;
            float rc = ground_radius() - depth; /* the tangent point's radius */
            float mu = -sqrt(max((r - rc) * (r + rc), 0.0)) / r;
            if (rc > 0.0 && mu > lower && mu < mu_horizon) {
                sp.lo[sp.count] = lower;
                sp.hi[sp.count] = mu;
                sp.count++;
                lower = mu;
            }
        }
        sp.lo[sp.count] = lower;
        sp.hi[sp.count] = mu_horizon;
        sp.count++;
    }
    sp.first_sky = sp.count;
    float from = mu_horizon;
    for (int c = -1; c <= 1; c++) {
        float corner = ozone_corner(c + 1);
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
    /* Above those cuts, the light of the air fades as exp(-z / H) with the
     * ray's tangent altitude z: from high up, cut where it has faded. */
    float z_fade = 25.0 * max(atm.rayleigh_scattering.w, atm.mie_scattering.w);
    if (whole_sphere && z_fade < h)
        sphere_split(sp, -sqrt(max((h - z_fade) * (r + ground_radius() + z_fade), 0.0)) / r);
    sphere_split(sp, -mu_s);
    if (peaked)
        sphere_split(sp, mu_s);
    return sp;
}

/* Gauss-Legendre nodes and weights, ascending: n_mu on [-1, 1] and, with
 * `cap`, n_phi on [0, 1], and the workgroup's copy of the multiscattering
 * LUT where the shader asked for one (atmosphere.glsl); every invocation of
 * the workgroup must call it. */
void sphere_init(uint n_mu, uint n_phi, bool cap)
{
    uint i = gl_LocalInvocationIndex;
    for (uint k = i; k < n_mu; k += SB_SPHERE_THREADS) {
        float x, w;
        gauss_legendre(int(k), int(n_mu), -1.0, 1.0, x, w);
        sphere_node[k] = x;
        sphere_weight[k] = w;
    }
#ifdef SB_MULTISCATTERING_SHARED
    for (uint k = i; k < uint(SB_MULTISCATTERING_LOOKUP_TEXELS); k += SB_SPHERE_THREADS)
        multiscattering_shared[k] = multiscattering_log[k];
#endif
    for (uint k = i; cap && k < n_phi; k += SB_SPHERE_THREADS) {
        float x, w;
        gauss_legendre(int(k), int(n_phi), 0.0, 1.0, x, w);
        sphere_phi_node[k] = x;
        sphere_phi_weight[k] = w;
    }
    barrier();
}

/* Nodes crowded toward an end of [0, 1], or both: x(u) with dx = x'(u), flat
 * (as u^2) at a crowded end. */
float sphere_crowd(float u, bool lo, bool hi, out float dx)
{
    dx = 1.0;
    if (lo && hi) {
        dx = 6.0 * u * (1.0 - u);
        return u * u * (3.0 - 2.0 * u);
    }
    if (lo) {
        dx = 2.0 * u;
        return u * u;
    }
    if (hi) {
        dx = 2.0 * (1.0 - u);
        return 1.0 - (1.0 - u) * (1.0 - u);
    }
    return u;
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

struct SphereZenith {
    float mu;            /* cosine of the zenith angle */
    float weight;        /* its weight in mu */
    bool toward_ground;  /* below the horizon */
};

/* Node k of the n_mu on a piece of the zenith grid. */
SphereZenith sphere_zenith(SpherePieces sp, uint piece, uint k)
{
    SphereZenith z;
    z.toward_ground = int(piece) < sp.first_sky;
    float u = 0.5 + 0.5 * sphere_node[k], w_u = 0.5 * sphere_weight[k];
    float lo = sp.lo[piece], hi = sp.hi[piece];
    /* Crowd the nodes toward the horizon and toward the peak: a sky piece
     * toward its end on the peak's side, since the peak (Mie's, about 1 - g
     * wide) reaches well beyond the pieces that touch it. */
    bool peaked = sp.peak <= 1.0;
    bool at_lo = int(piece) == sp.first_sky || (peaked && !z.toward_ground && lo >= sp.peak);
    bool at_hi = int(piece) + 1 == sp.first_sky || (peaked && !z.toward_ground && hi <= sp.peak);
    float dx;
    float x = sphere_crowd(u, at_lo, at_hi, dx);
    z.mu = lo + (hi - lo) * x;
    z.weight = (hi - lo) * dx * w_u;
    return z;
}

/* Azimuth node at v in (0, 1) of the midpoint rule, and dphi/dv: phi = pi v,
 * or, crowded, pi (v - sin(2 pi v) / (2 pi)). */
float sphere_azimuth(float v, bool crowded, out float dphi)
{
    dphi = crowded ? PI * (1.0 - cos(2.0 * PI * v)) : PI;
    return crowded ? PI * (v - sin(2.0 * PI * v) / (2.0 * PI)) : PI * v;
}

SphereDirection sphere_direction(SpherePieces sp, uint d, uint n_mu, uint n_phi)
{
    uint piece = d / (n_mu * n_phi), k = (d / n_phi) % n_mu, p = d % n_phi;
    SphereZenith z = sphere_zenith(sp, piece, k);
    SphereDirection s;
    s.toward_ground = z.toward_ground;
    s.mu = z.mu;
    /* Azimuth: midpoint rule in v; with a peak, phi = pi (v - sin(2 pi v) /
     * (2 pi)), which crowds the nodes toward the sun's side (phi = 0, where
     * the Mie peak is) and keeps the rule's accuracy on the even, periodic
     * integrand. */
    float dphi;
    s.cos_phi = cos(sphere_azimuth((float(p) + 0.5) / float(n_phi), sp.peak <= 1.0, dphi));
    s.weight = z.weight * 2.0 * dphi / float(n_phi);
    return s;
}

/*
 * Mie single scattering's peak, at the sun (at the anti-sun for g < 0),
 * about 1 - |g| wide: its own grid, a cap around that axis (the fp64
 * reference, cap_directions in baker/atmosphere_ref.c, explains it). A
 * product integrates P_M (1 - alpha) S on the zenith grid above and
 * P_M alpha S on the cap, alpha = sphere_cap_window. Over a hemisphere the
 * cap is the whole of it (alpha = 1); over the sphere it has radius
 * SB_CAP_THETA, alpha falling to 0 at twice that, and only for |g| >=
 * SB_CAP_MIN_G (below it the zenith grid resolves the peak).
 *
 * Angles from the axis are held as o = 1 - nu' (nu' = sign(g) nu), exact
 * near the peak where nu itself is not in fp32. A ring's nodes are even in
 * t = ln((1 - |g|)^2 + 2 |g| o), in which Henyey-Greenstein's peak is an
 * exponential: P_M do = k (1 + nu^2) dt / (2 |g| sqrt(e^t)).
 */
struct SphereCap {
    float o_lo[3], o_hi[3]; /* pieces in o, from the axis out */
    bool crowd_lo[3], crowd_hi[3];
    int count;
    uint side_first, side_end; /* sides of the horizon: 0 sky, 1 ground */
    float mu_a, sin_a, mu_h, sign, g;
    bool whole_sphere;
};

/* o at the window's ends (constant expressions: folded at compile time) */
const float SPHERE_CAP_O_1 = 2.0 * sin(0.5 * SB_CAP_THETA) * sin(0.5 * SB_CAP_THETA);
const float SPHERE_CAP_O_2 = 2.0 * sin(SB_CAP_THETA) * sin(SB_CAP_THETA);

bool sphere_cap_active(bool whole_sphere)
{
    return !whole_sphere || abs(atm.mie_extinction.w) >= SB_CAP_MIN_G;
}

float sphere_cap_window_o(bool whole_sphere, float o)
{
    if (!sphere_cap_active(whole_sphere))
        return 0.0;
    if (!whole_sphere)
        return 1.0;
    float x = clamp((SPHERE_CAP_O_2 - o) / (SPHERE_CAP_O_2 - SPHERE_CAP_O_1), 0.0, 1.0);
    return x * x * (3.0 - 2.0 * x);
}

/* alpha at a zenith-grid direction with sun cosine nu. */
float sphere_cap_window(bool whole_sphere, float nu)
{
    return sphere_cap_window_o(whole_sphere, 1.0 - (atm.mie_extinction.w < 0.0 ? -nu : nu));
}

/*
 * irradiance_sky's azimuths. A ray's integrals f(phi) depend on the azimuth
 * only through the sun's transmittance along the ray; the phase functions
 * multiply them, and Mie's at g = 0.8 is a peak some 0.2 rad wide that the
 * crowded midpoint rule of sphere_direction resolves only at n = 16 nodes.
 * Where the sun stands above the horizontal of every point of the air the
 * texel sees (sphere_azimuths), f is smooth in phi, and a quarter of the
 * nodes, evenly spread, do by product integration: f interpolated through
 * them by its cosine series (cardinal function l_p(phi) = (1 + 2 sum_{m <
 * n} cos(m phi_p) cos(m phi)) / n), the integral over phi in [0, pi] of
 * P(nu(phi)) f(phi) is sum_p f(phi_p) W_p, W_p the integral of P l_p,
 * which needs no ray: a dense midpoint rule of the phase functions alone,
 * exact for f of n harmonics whatever P's peak. At twilight and at night f
 * has the shadow's structure, toward the sun, and the texel keeps the n
 * crowded nodes and the plain rule; product weights on those nodes (f
 * interpolated in v) took 16x16 from 5.9e-4 to 5.1e-4 only, at 9% more
 * time on llvmpipe (docs/accuracy.md, "A quarter of the azimuths by day").
 * nu = a + b cos phi.
 */
struct SphereAzimuths {
    uint n;
    bool crowded;
};

/* Every point the rays from (h, mu_s) reach inside the atmosphere (at most
 * acos(R / r) + acos(R / r_top) away at the planet's centre) has the sun
 * SB_AZIMUTH_DAY_MARGIN above its horizontal. */
SphereAzimuths sphere_azimuths(float h, float mu_s, uint n_phi)
{
    float R = ground_radius();
    float reach = acos(clamp(R / (R + h), 0.0, 1.0)) + acos(R / (R + atmosphere_thickness()));
    bool day = acos(clamp(mu_s, -1.0, 1.0)) + reach <= 0.5 * PI - SB_AZIMUTH_DAY_MARGIN;
    SphereAzimuths az;
    az.n = day ? (n_phi + 3u) / 4u : n_phi;
    az.crowded = !day;
    return az;
}

struct AzimuthWeights {
    float cos_phi;  /* the node's */
    float iso;      /* W_p for P = 1 */
    float rayleigh; /* W_p for P_R */
    float mie;      /* W_p for P_M (1 - the cap's window) */
};

AzimuthWeights sphere_azimuth_weights(float a, float b, uint p, SphereAzimuths az)
{
    AzimuthWeights w;
    float v_p = (float(p) + 0.5) / float(az.n);
    float dphi, phi_p = sphere_azimuth(v_p, az.crowded, dphi);
    w.cos_phi = cos(phi_p);
    if (az.crowded) { /* as sphere_direction */
        float nu = clamp(a + b * w.cos_phi, -1.0, 1.0);
        w.iso = dphi / float(az.n);
        w.rayleigh = w.iso * phase_rayleigh(nu);
        w.mie = w.iso * phase_mie(nu) * (1.0 - sphere_cap_window(true, nu));
        return w;
    }
    /* 1 - nu = (1 - a - b) + 2 b sin^2(phi / 2), exact near the peak */
    float o_0 = max(1.0 - a - b, 0.0);
    float sum_i = 0.0, sum_r = 0.0, sum_m = 0.0;
    for (uint j = 0u; j < SB_AZIMUTH_DENSE; j++) {
        float phi = PI * (float(j) + 0.5) / float(SB_AZIMUTH_DENSE);
        float s = sin(0.5 * phi);
        float o = o_0 + 2.0 * b * s * s, nu = 1.0 - o;
        /* n l_p(phi) = 1 + sum_{m=1}^{n-1} (cos m (phi - phi_p) + cos m (phi + phi_p)) */
        float x = cos(phi - phi_p), y = cos(phi + phi_p);
        float x0 = 1.0, x1 = x, y0 = 1.0, y1 = y, l = 1.0;
        for (uint m = 1u; m < az.n; m++) {
            l += x1 + y1;
            float x2 = 2.0 * x * x1 - x0, y2 = 2.0 * y * y1 - y0;
            x0 = x1, x1 = x2, y0 = y1, y1 = y2;
        }
        sum_i += l;
        sum_r += phase_rayleigh(nu) * l;
        sum_m += phase_mie(nu) * (1.0 - sphere_cap_window_o(true, atm.mie_extinction.w < 0.0 ? 2.0 - o : o)) * l;
    }
    float k = PI / float(az.n * SB_AZIMUTH_DENSE);
    w.iso = k * sum_i;
    w.rayleigh = k * sum_r;
    w.mie = k * sum_m;
    return w;
}

SphereCap sphere_cap(float h, bool whole_sphere, float mu_s)
{
    SphereCap c;
    c.whole_sphere = whole_sphere;
    float r = ground_radius() + h;
    c.g = abs(atm.mie_extinction.w);
    c.sign = atm.mie_extinction.w < 0.0 ? -1.0 : 1.0;
    c.mu_h = whole_sphere ? -horizon_distance(h) / r : 0.0;
    c.mu_a = c.sign * mu_s;
    c.sin_a = sqrt(max(1.0 - mu_s * mu_s, 0.0));
    float e_a = asin(clamp(c.mu_a, -1.0, 1.0)), e_h = asin(c.mu_h);
    float reach = whole_sphere ? 2.0 * SB_CAP_THETA : PI; /* the cap's radius */
    float o_end = whole_sphere ? SPHERE_CAP_O_2 : 2.0;
    /* the rings that touch the horizon: angles |e_a - e_h| and pi - |e_a + e_h| */
    float a = 0.5 * abs(e_a - e_h), b = 0.5 * abs(e_a + e_h);
    float cuts[2] = float[2](2.0 * sin(a) * sin(a), 2.0 * cos(b) * cos(b));
    c.count = 0;
    float from = 0.0;
    for (int i = 0; i < 2; i++)
        if (cuts[i] > from && cuts[i] < o_end) {
            c.o_lo[c.count] = from;
            c.o_hi[c.count] = cuts[i];
            c.crowd_lo[c.count] = from > 0.0;
            c.crowd_hi[c.count] = true;
            c.count++;
            from = cuts[i];
        }
    c.o_lo[c.count] = from;
    c.o_hi[c.count] = o_end;
    c.crowd_lo[c.count] = from > 0.0;
    c.crowd_hi[c.count] = false;
    c.count++;
    bool sky = e_a - e_h > -reach, ground = whole_sphere && e_a - e_h < reach;
    c.side_first = sky ? 0u : 1u;
    c.side_end = ground ? 2u : 1u;
    return c;
}

uint sphere_cap_direction_count(SphereCap c, uint n_mu, uint n_phi)
{
    return sphere_cap_active(c.whole_sphere) ? uint(c.count) * n_mu * (c.side_end - c.side_first) * n_phi : 0u;
}

struct CapDirection {
    float mu, nu;
    float phase_weight;  /* P_M(nu) alpha times the solid angle, both halves */
    bool toward_ground;
};

CapDirection sphere_cap_direction(SphereCap c, uint d, uint n_mu, uint n_phi)
{
    uint sides = c.side_end - c.side_first;
    uint p = d % n_phi, side = c.side_first + (d / n_phi) % sides;
    uint k = (d / (n_phi * sides)) % n_mu, piece = d / (n_phi * sides * n_mu);
    float u = 0.5 + 0.5 * sphere_node[k], w_u = 0.5 * sphere_weight[k], dx;
    float x = sphere_crowd(u, c.crowd_lo[piece], c.crowd_hi[piece], dx);
    float lo = c.o_lo[piece], hi = c.o_hi[piece], o, phase_do;
    float q = (1.0 - c.g) * (1.0 - c.g), kk = 3.0 / (8.0 * PI) * (1.0 - c.g * c.g) / (2.0 + c.g * c.g);
    if (c.g < 0.01) {
        o = lo + (hi - lo) * x;
        float nu_a = 1.0 - o;
        phase_do = kk * (1.0 + nu_a * nu_a) / pow(q + 2.0 * c.g * o, 1.5) * (hi - lo) * dx * w_u;
    } else {
        float t_lo = log(q + 2.0 * c.g * lo), t_hi = log(q + 2.0 * c.g * hi);
        float e = exp(t_lo + (t_hi - t_lo) * x);
        o = clamp((e - q) / (2.0 * c.g), lo, hi);
        float nu_a = 1.0 - o;
        phase_do = kk * (1.0 + nu_a * nu_a) * (t_hi - t_lo) * dx * w_u / (2.0 * c.g * sqrt(e));
    }
    float nu_a = 1.0 - o, sin_v = sqrt(max(o * (2.0 - o), 0.0));
    float radius = c.sin_a * sin_v, centre = c.mu_a * nu_a;
    float psi_h = radius > 0.0 ? acos(clamp((c.mu_h - centre) / radius, -1.0, 1.0)) : (centre >= c.mu_h ? PI : 0.0);
    float a = side == 1u ? psi_h : 0.0, b = side == 1u ? PI : psi_h;
    float dt;
    /* crowded toward psi_h: the end of the sky side, the start of the ground side */
    float y = sphere_crowd(sphere_phi_node[p], side == 1u, side == 0u, dt);
    float mu = clamp(centre + radius * cos(a + (b - a) * y), -1.0, 1.0);
    CapDirection cd;
    cd.toward_ground = side == 1u;
    cd.mu = cd.toward_ground ? min(mu, c.mu_h) : max(mu, c.mu_h);
    cd.nu = c.sign * nu_a;
    cd.phase_weight = 2.0 * phase_do * sphere_cap_window_o(c.whole_sphere, o) * (b - a) * dt * sphere_phi_weight[p];
    return cd;
}

/* Sum `count` values for each of SB_SPHERE_REDUCED invocations, stored at
 * sphere_partial[i * SB_SPHERE_MAX_SUMS + c], into sphere_partial[c]; a
 * fixed pairwise tree. */
void sphere_reduce(uint count)
{
    for (uint stride = SB_SPHERE_REDUCED / 2u; stride > 0u; stride >>= 1u) {
        barrier();
        for (uint i = gl_LocalInvocationIndex; i < stride; i += SB_SPHERE_THREADS)
            for (uint c = 0u; c < count; c++)
                sphere_partial[i * SB_SPHERE_MAX_SUMS + c] += sphere_partial[(i + stride) * SB_SPHERE_MAX_SUMS + c];
    }
    barrier();
}

/* This workgroup's number, and its texel. The host dispatches width x
 * height groups; a kernel that defines SB_SPHERE_BY_COLUMN takes them column
 * by column (one sun cosine, every altitude), so that the workgroups that
 * run together read the same column of the ring table (sun_rings.glsl)
 * and find more of it in the caches. On the H100 that took the default
 * multiscattering bake from 0.63 to 0.57 ms; irradiance_sky, which reads no
 * ring table, went from 4.96 to 4.57 ms too (its texels' costs differ most
 * along a row, so a column's groups may simply share the waves better: not
 * pinned down); irradiance_ground, no faster that way, keeps the rows.
 * Each texel's sums are what they were. */
uint sphere_group()
{
    return gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
}

/* The column a CPU device takes n-th: n k mod width, k the integer nearest
 * width (sqrt 5 - 1) / 2 that is coprime to the width, so that any run of
 * columns taken one after another spreads evenly over the sun's cosines.
 * llvmpipe hands each of its threads one run of a dispatch's workgroups,
 * and a texel's cost depends on its sun: in plain order one thread got the
 * night and the other the day, and the bake took as long as the slower.
 * A GPU hands out workgroups as its cores free up and keeps the plain
 * order, which starts the costly night and twilight texels first and
 * leaves the short ones to fill the last wave: with irradiance_sky's
 * quarter of the azimuths by day, the stride took the H100's bake from 3.2
 * to 4.2 ms. */
uint sphere_column(uint n, uint width)
{
    uint k = uint(float(width) * 0.618034 + 0.5);
    for (uint step = 1u; width > 2u; step++) {
        uint a = k, b = width;
        while (b != 0u) {
            uint t = a % b;
            a = b;
            b = t;
        }
        if (a == 1u)
            break;
        k += (step & 1u) != 0u ? step : -step; /* k, k + 1, k - 1, k + 2, ... */
    }
    return width > 2u ? n * k % width : n;
}

uvec2 sphere_texel()
{
#if defined(SB_SPHERE_BY_COLUMN) && !defined(SB_SPHERE_GPU) && !defined(SB_SPHERE_RAYS)
    return uvec2(sphere_column(sphere_group() / pc.height, pc.width), sphere_group() % pc.height);
#elif defined(SB_SPHERE_BY_COLUMN)
    return uvec2(sphere_group() / pc.height, sphere_group() % pc.height);
#else
    return gl_WorkGroupID.xy;
#endif
}

uint sphere_slot()
{
    return (sphere_group() * SB_SPHERE_THREADS + gl_LocalInvocationIndex) * SB_SPHERE_MAX_SUMS;
}

#ifdef SB_SPHERE_RAYS
/* This invocation's direction. */
uint sphere_ray()
{
    return gl_WorkGroupID.z * SB_SPHERE_THREADS + gl_LocalInvocationIndex;
}
#endif

/* Where direction d of this texel keeps its sums, one direction an invocation. */
uint sphere_ray_slot(uint d)
{
    return (sphere_group() * pc.direction_slots + d) * SB_SPHERE_MAX_SUMS;
}

/* Start this pass from the previous passes' sums. */
void sphere_begin()
{
#ifdef SB_SPHERE_RAYS
    for (uint c = 0u; c < SB_SPHERE_MAX_SUMS; c++)
        sphere_acc[c] = 0.0;
#else
    uint slot = sphere_slot();
    for (uint c = 0u; c < SB_SPHERE_MAX_SUMS; c++)
        sphere_acc[c] = pc.step_begin > 0u ? uintBitsToFloat(sphere_partials[slot + c]) : 0.0;
#endif
}

uint sphere_first_direction()
{
#ifdef SB_SPHERE_RAYS
    return sphere_ray();
#else
    return gl_LocalInvocationIndex + pc.step_begin * SB_SPHERE_THREADS;
#endif
}

uint sphere_end_direction(uint count)
{
#if defined(SB_SPHERE_RAYS)
    sphere_count = count;
    return min(count, sphere_ray() + 1u);
#else
    return min(count, pc.step_end * SB_SPHERE_THREADS);
#endif
}

void sphere_add3(uint c, vec3 value)
{
    sphere_acc[c] += value.r;
    sphere_acc[c + 1u] += value.g;
    sphere_acc[c + 2u] += value.b;
}

/*
 * End of this pass: flag the scratch buffer if llvmpipe's loop limiter ran
 * out (then this two-iteration loop over a buffer the compiler cannot see
 * through stops after one), then keep the sums for the next pass and return
 * false, or, after the last pass, reduce the first `count` sums over the
 * workgroup and return true. Every invocation must call it.
 */
bool sphere_finish(uint count)
{
    uint k = 0u;
    while (sphere_sentinel[k] != 0u)
        k++;
    if (k != 2u)
        sphere_truncated = 1u;
#ifdef SB_SPHERE_RAYS
    if (sphere_ray() < sphere_count)
        for (uint c = 0u; c < count; c++)
            sphere_partials[sphere_ray_slot(sphere_ray()) + c] = floatBitsToUint(sphere_acc[c]);
    /* The texel's counter, after every texel's sums: the workgroup that
     * brings it to the texel's workgroup count sums the directions. */
    memoryBarrierBuffer();
    barrier();
    if (gl_LocalInvocationIndex == 0u) {
        uint counter = SB_SPHERE_COUNTERS(gl_NumWorkGroups.x * gl_NumWorkGroups.y, pc.direction_slots) + sphere_group();
        sphere_last = atomicAdd(sphere_partials[counter], 1u) + 1u == gl_NumWorkGroups.z;
    }
    barrier();
    if (!sphere_last)
        return false;
    memoryBarrierBuffer();
    for (uint i = gl_LocalInvocationIndex; i < SB_SPHERE_REDUCED; i += SB_SPHERE_THREADS) {
        float acc[SB_SPHERE_MAX_SUMS];
        for (uint c = 0u; c < count; c++)
            acc[c] = 0.0;
        for (uint d = i; d < sphere_count; d += SB_SPHERE_REDUCED)
            for (uint c = 0u; c < count; c++)
                acc[c] += uintBitsToFloat(sphere_partials[sphere_ray_slot(d) + c]);
        for (uint c = 0u; c < count; c++)
            sphere_partial[i * SB_SPHERE_MAX_SUMS + c] = acc[c];
    }
#else
    if (pc.step_end < pc.step_count) {
        uint slot = sphere_slot();
        for (uint c = 0u; c < count; c++)
            sphere_partials[slot + c] = floatBitsToUint(sphere_acc[c]);
        return false;
    }
    for (uint c = 0u; c < count; c++)
        sphere_partial[gl_LocalInvocationIndex * SB_SPHERE_MAX_SUMS + c] = sphere_acc[c];
#endif
    sphere_reduce(count);
    return true;
}

vec3 sphere_sum3(uint c)
{
    return vec3(sphere_partial[c], sphere_partial[c + 1u], sphere_partial[c + 2u]);
}

#endif
