/*
 * Rings: multiscattering's integral over the sphere with the azimuth taken
 * first (docs/accuracy.md, "Rings"). Include after atmosphere.glsl.
 *
 * Of everything multiscattering integrates along a ray, only the sun's
 * transmittance depends on the ray's azimuth about the texel's zenith, and
 * the integrand is isotropic (psi_ms's phase is 1 / (4 pi)). So each zenith
 * direction takes one ray, and each node of it, at altitude h and angle
 * gamma from the texel's zenith as seen from the planet's centre, the mean
 * of the sun's transmittance over the ring the node sweeps as the azimuth
 * turns: G(h, gamma; mu_s), the mean over phi in [0, pi] of
 * T_sun(h, cos(gamma) mu_s + sin(gamma) sin_s cos(phi)). For a column of
 * the LUT (one mu_s) G depends on two numbers; sun_rings.comp tabulates it
 * per column, each entry a ring integrated by Gauss-Legendre on the pieces
 * between where the ring enters the planet's shadow and where the sun's
 * ray grazes an ozone corner.
 *
 * The table's axes follow G's shape:
 * - rows in altitude (up to ring_table_top), split at h*, where the sun sets (its content flips
 *   from lit to shadowed there, so a table across it would be
 *   discontinuous): linear below, sqrt above (or sqrt over the whole
 *   atmosphere where the sun does not set within it);
 * - in gamma, through its half-angle tangent w = tan(gamma / 2), which a
 *   node has from its position without an arctangent (ring_tan_along),
 *   split at the ring's tangency with the shadow, w_c for the angle
 *   c = |theta_s - theta_shadow(h)|, where G starts to fall as a square
 *   root: w = w_c v below (SB_RINGS_INNER entries), w_c + (w_max - w_c)
 *   v^2 above (SB_RINGS_OUTER), w_max for the largest angle a node of a
 *   ray inside the atmosphere can have (gamma < pi there, so w is finite
 *   and increases with gamma; w - w_c is smooth in gamma - c, so the
 *   square root's onset is where v^2 puts it);
 * - Catmull-Rom within each block, the ghost entries beyond a block's ends
 *   extrapolated quadratically (3 v0 - 3 v1 + v2).
 * The ground's ring (the mean of max(mu, 0) T_sun on the ground) is a 1D
 * table in w per column.
 *
 * A ray is cut where its nodes' rings change character: at the levels and
 * the ozone corners (as every ray), at its closest point to the centre,
 * and where the ring touches the shadow or an ozone tangency, that is where
 * cos(theta_s +- gamma) = -sqrt(1 - (rc / r)^2): there
 * r sin(theta_s +- gamma) = +-rc, linear in the distance along the ray.
 */
#ifndef SB_SUN_RINGS_GLSL
#define SB_SUN_RINGS_GLSL

#include "config.h"
#include "atmosphere.glsl"

layout(std430, set = 0, binding = SB_BINDING_SUN_RINGS) readonly buffer SunRingsBuffer {
    vec4 sun_rings[];
};

/* The table's rows reach up to 25 of the largest scale height (or the
 * top): above that the air's density has fallen by e^-25, and nothing a
 * node there gathers counts. In an atmosphere as thick as its planet this
 * keeps the rows where the air is. */
float ring_table_top()
{
    return min(atmosphere_thickness(), 25.0 * max(atm.rayleigh_scattering.w, atm.mie_scattering.w));
}

/* What a column's table depends on. */
struct RingColumn {
    float mu_s, sin_s;
    float h_star; /* where the sun sets, or -1 where it does not within the atmosphere */
    float w_top;  /* tan(gamma_top / 2), gamma_top the angle from the ground to the horizon of the top */
};

RingColumn ring_column(float mu_s)
{
    RingColumn col;
    col.mu_s = mu_s;
    col.sin_s = sqrt(max(1.0 - mu_s * mu_s, 0.0));
    /* The sun sets at h* where the horizon's dip, acos(R / r), reaches
     * a = theta_s - pi / 2: r* = R / cos(a), cos(a) = sin_s, so
     * h* = R (1 - sin_s) / sin_s = R mu_s^2 / ((1 + sin_s) sin_s). */
    col.h_star = -1.0;
    if (mu_s < 0.0 && col.sin_s > 0.0) {
        float h = ground_radius() * mu_s * mu_s / ((1.0 + col.sin_s) * col.sin_s);
        if (h < ring_table_top())
            col.h_star = h;
    }
    /* tan(a / 2) = sin(a) / (1 + cos(a)), here rho_top / r_top over 1 + R / r_top */
    col.w_top = horizon_top() / (top_radius() + ground_radius());
    return col;
}

/* w_max at altitude h: gamma_max = gamma_top + the horizon's angle from
 * the node's zenith at h, whose half tangent is rho / (r + R); the sum's
 * from tan((a + b) / 2) = (ta + tb) / (1 - ta tb), both half angles below
 * pi / 4. */
float ring_w_max(RingColumn col, float h)
{
    float tb = horizon_distance(h) / (2.0 * ground_radius() + h);
    return (col.w_top + tb) / (1.0 - col.w_top * tb);
}

/* The ring's tangency with the shadow, the gamma axis' split: the angle c
 * between the sun and the shadow's edge at altitude h, the ray grazing the
 * ground (cosine -rho / r, sine R / r), as tan(c / 2) = |sin c| / (1 + cos c)
 * from its sine and cosine times r, which do not cancel where c is small as
 * the difference of the two angles would (c < pi - pi / 6 within any
 * atmosphere up to its planet's radius thick, so 1 + cos c does not either),
 * at most w_max = ring_w_max(col, h). */
float ring_cut(RingColumn col, float h, float w_max)
{
    float R = ground_radius(), rho = horizon_distance(h);
    float s = col.sin_s * rho + col.mu_s * R;
    float c = col.sin_s * R - col.mu_s * rho;
    return min(abs(s) / (R + h + c), w_max);
}

/* The row block of altitude h: its first row and row count, and the
 * continuous row within it. */
float ring_row(RingColumn col, float h, out int first, out int count)
{
    float top = ring_table_top();
    if (col.h_star < 0.0) {
        first = 0;
        count = SB_RINGS_ROWS;
        return sqrt(clamp(h / top, 0.0, 1.0)) * float(count - 1);
    }
    count = SB_RINGS_ROWS / 2;
    if (h < col.h_star) {
        first = 0;
        return clamp(h / col.h_star, 0.0, 1.0) * float(count - 1);
    }
    first = count;
    return sqrt(clamp((h - col.h_star) / (top - col.h_star), 0.0, 1.0)) * float(count - 1);
}

/* The altitude of row i (the inverse of ring_row). */
float ring_row_altitude(RingColumn col, int i)
{
    float top = ring_table_top();
    if (col.h_star < 0.0) {
        float x = float(i) / float(SB_RINGS_ROWS - 1);
        return x * x * top;
    }
    const int half_rows = SB_RINGS_ROWS / 2;
    float x = float(i % half_rows) / float(half_rows - 1);
    return i < half_rows ? x * col.h_star : col.h_star + x * x * (top - col.h_star);
}

/* The half-angle tangent of entry j of a row at altitude h. */
float ring_entry_tan(RingColumn col, float h, int j)
{
    float w_max = ring_w_max(col, h), c = ring_cut(col, h, w_max);
    if (j < SB_RINGS_INNER)
        return c * float(j) / float(SB_RINGS_INNER - 1);
    float v = float(j - SB_RINGS_INNER) / float(SB_RINGS_OUTER - 1);
    return c + (w_max - c) * v * v;
}

/* Catmull-Rom weights of continuous entry f of a block of n >= 4 entries,
 * on four consecutive entries from the returned one: the ghost entry beyond
 * either end, 3 v0 - 3 v1 + v2, folded into the entries it is made of. */
int ring_taps(float f, int n, out float w[4])
{
    int first = cubic_taps(f, n, w);
    if (first < 0) {
        float g = w[0];
        w[0] = w[1] + 3.0 * g;
        w[1] = w[2] - 3.0 * g;
        w[2] = w[3] + g;
        w[3] = 0.0;
        return 0;
    }
    if (first + 3 >= n) {
        float g = w[3];
        w[3] = w[2] + 3.0 * g;
        w[2] = w[1] - 3.0 * g;
        w[1] = w[0] + g;
        w[0] = 0.0;
        return n - 4;
    }
    return first;
}

/* G(h, gamma) of column `column` from its table, w = tan(gamma / 2). */
vec3 ring_table_sample(uint column, RingColumn col, float h, float w)
{
    int first, rows;
    float fr = ring_row(col, h, first, rows);
    float w_max = ring_w_max(col, h), c = ring_cut(col, h, w_max);
    bool outer = w >= c && w_max > c;
    int n = outer ? SB_RINGS_OUTER : SB_RINGS_INNER;
    float u = outer ? sqrt(max(w - c, 0.0) / (w_max - c)) : (c > 0.0 ? w / c : 0.0);
    float wr[4], wg[4];
    int i0 = ring_taps(fr, rows, wr), j0 = ring_taps(min(u, 1.0) * float(n - 1), n, wg);
    uint k = column * uint(SB_RINGS_COLUMN) + uint((first + i0) * SB_RINGS_ANGLES + (outer ? SB_RINGS_INNER : 0) + j0);
    vec3 sum = vec3(0.0);
    for (int a = 0; a < 4; a++, k += uint(SB_RINGS_ANGLES))
        sum += wr[a] * (wg[0] * sun_rings[k].rgb + wg[1] * sun_rings[k + 1u].rgb + wg[2] * sun_rings[k + 2u].rgb
                        + wg[3] * sun_rings[k + 3u].rgb);
    return max(sum, vec3(0.0));
}

/* The half-angle tangent of the ground ring's entry j, uniform over
 * [0, w_top]. */
float ring_ground_tan(RingColumn col, int j)
{
    return col.w_top * float(j) / float(SB_RINGS_GROUND - 1);
}

/* The ground ring's mean of max(mu, 0) T_sun at w = tan(gamma / 2), from
 * the table. */
vec3 ring_ground_sample(uint column, RingColumn col, float wg)
{
    float w[4];
    int j0 = cubic_taps(wg / col.w_top * float(SB_RINGS_GROUND - 1), SB_RINGS_GROUND, w);
    uint base = column * uint(SB_RINGS_COLUMN) + uint(SB_RINGS_ROWS * SB_RINGS_ANGLES);
    vec3 sum = vec3(0.0);
    for (int i = 0; i < 4; i++)
        sum += w[i] * sun_rings[base + uint(clamp(j0 + i, 0, SB_RINGS_GROUND - 1))].rgb;
    return max(sum, vec3(0.0));
}

/* tan(gamma / 2) at distance t along the ray from altitude h0 with cosine
 * mu (sine sin_v), where the altitude is h: r cos(gamma) = r0 + t mu,
 * r sin(gamma) = t sin_v, and tan(gamma / 2) = r sin / (r + r cos), whose
 * denominator stays above r / 2 (gamma < 2 pi / 3 within an atmosphere up
 * to its planet's radius thick). */
float ring_tan_along(float h0, float mu, float sin_v, float t, float h)
{
    return t * sin_v / (2.0 * ground_radius() + h + h0 + t * mu);
}

/* The cuts (atmosphere.glsl) of the ray from altitude h0 with cosine mu
 * for rings (above). */
RayCuts ring_cuts(float h0, float mu, RingColumn col)
{
    RayCuts cuts = ray_level_cuts(h0, mu);
    float R = ground_radius(), r0 = R + h0;
    cuts.extra[0] = -r0 * mu; /* the closest point, where the ray passes it */
    float sin_v = sqrt(max(1.0 - mu * mu, 0.0));
    /* r sin(theta_s + sg gamma) = sin_s (r0 + t mu) + sg mu_s t sin_v =
     * side rc, where also r cos(theta_s + sg gamma) = mu_s (r0 + t mu) -
     * sg sin_s t sin_v < 0 (the ring's extreme cosine is the tangency's,
     * below the horizon). rc - sin_s r0 = (hc - h0) + r0 mu_s^2 / (1 + sin_s)
     * without cancelling. */
    float lift = r0 * col.mu_s * col.mu_s / (1.0 + col.sin_s);
    [[unroll]] for (int k = -1; k < 3; k++) {
        float hc = k < 0 ? 0.0 : ozone_corner(k);
        bool used = k < 0 || (hc > 0.0 && hc < atmosphere_thickness());
        [[unroll]] for (int e = 0; e < 4; e++) {
            float sg = (e & 1) != 0 ? -1.0 : 1.0;
            bool far_side = e >= 2;
            float den = col.sin_s * mu + sg * col.mu_s * sin_v;
            float num = far_side ? -(R + hc) - col.sin_s * r0 : (hc - h0) + lift;
            float t = num / den;
            bool cut = used && abs(den) >= 1e-7 && t > 0.0
                    && col.mu_s * (r0 + t * mu) - sg * col.sin_s * t * sin_v < 0.0;
            cuts.extra[1 + 4 * (k + 1) + e] = cut ? t : -1.0;
        }
    }
    return cuts;
}

#endif
