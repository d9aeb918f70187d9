#include "atmosphere_ref.h"

#include "config.h"
#include "physics.h"

#include <math.h>
#include <pthread.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#define REF_PI 3.14159265358979323846
#define MAX_BREAKS 96

/* ---- Gauss-Legendre tables, computed once in fp64 ------------------------------ */

struct gl_rule {
    int n;
    double x[32], w[32]; /* on [-1, 1], ascending */
    double s[32][32];    /* s[i][j] = integral from -1 to x_i of Lagrange basis j */
};

static struct gl_rule gl8, gl16;
static pthread_once_t gl_once = PTHREAD_ONCE_INIT;

static void gl_compute(struct gl_rule *g, int n)
{
    g->n = n;
    for (int i = 0; i < n; i++)
        sb_gauss_legendre_node(i, n, -1.0, 1.0, &g->x[i], &g->w[i]);
}

static void gl_init(void)
{
    gl_compute(&gl8, 8);
    gl_compute(&gl16, 16);
    /* Collocation matrix of gl8 by exact 16-point integration of each
     * degree-7 Lagrange polynomial over [-1, x_i]. */
    for (int i = 0; i < 8; i++)
        for (int j = 0; j < 8; j++) {
            double a = -1, b = gl8.x[i], sum = 0;
            for (int k = 0; k < 16; k++) {
                double t = 0.5 * (a + b) + 0.5 * (b - a) * gl16.x[k], l = 1;
                for (int m = 0; m < 8; m++)
                    if (m != j)
                        l *= (t - gl8.x[m]) / (gl8.x[j] - gl8.x[m]);
                sum += gl16.w[k] * l * 0.5 * (b - a);
            }
            gl8.s[i][j] = sum;
        }
}

/* ---- Medium ------------------------------------------------------------------ */

void sb_ref_medium(const struct sb_atmosphere_params *p, double h, struct sb_ref_medium *m)
{
    double dr = exp(-h / p->rayleigh_scale_height_km);
    double dm = exp(-h / p->mie_scale_height_km);
    double dozone = 1.0 - fabs(h - p->ozone_center_km) / p->ozone_half_width_km;
    if (dozone < 0)
        dozone = 0;
    for (int c = 0; c < 3; c++) {
        m->rayleigh[c] = p->rayleigh_scattering_per_km[c] * dr;
        m->mie[c] = p->mie_scattering_per_km[c] * dm;
        m->extinction[c] = m->rayleigh[c] + (p->mie_scattering_per_km[c] + p->mie_absorption_per_km[c]) * dm +
                           p->ozone_absorption_per_km[c] * dozone;
    }
}

double sb_ref_phase_rayleigh(double nu)
{
    return 3.0 / (16.0 * REF_PI) * (1.0 + nu * nu);
}

double sb_ref_phase_mie(double g, double nu)
{
    double k = 3.0 / (8.0 * REF_PI) * (1.0 - g * g) / (2.0 + g * g);
    return k * (1.0 + nu * nu) / pow(1.0 + g * g - 2.0 * g * nu, 1.5);
}

/* ---- Geometry (plain fp64) --------------------------------------------------- */

static double radius_at(double r0, double mu, double t)
{
    return sqrt(fmax(r0 * r0 + t * t + 2.0 * r0 * mu * t, 0.0));
}

static double dist_top(const struct sb_atmosphere_params *p, double r, double mu)
{
    double top = p->top_radius_km;
    double disc = r * r * (mu * mu - 1.0) + top * top;
    return fmax(-r * mu + sqrt(fmax(disc, 0.0)), 0.0);
}

static bool hits_ground(const struct sb_atmosphere_params *p, double r, double mu)
{
    double R = p->ground_radius_km;
    return mu < 0.0 && r * r * (mu * mu - 1.0) + R * R >= 0.0;
}

static double dist_ground(const struct sb_atmosphere_params *p, double r, double mu)
{
    double R = p->ground_radius_km;
    double disc = r * r * (mu * mu - 1.0) + R * R;
    return fmax(-r * mu - sqrt(fmax(disc, 0.0)), 0.0);
}

static void sort_doubles(double *v, int n)
{
    for (int i = 1; i < n; i++) {
        double x = v[i];
        int j = i - 1;
        while (j >= 0 && v[j] > x) {
            v[j + 1] = v[j];
            j--;
        }
        v[j + 1] = x;
    }
}

/* Distances in (0, t_end) where the ray's altitude equals `level`. */
static int level_crossings(const struct sb_atmosphere_params *p, double r0, double mu, double t_end, double level,
                           double *out)
{
    double rl = p->ground_radius_km + level;
    double b = r0 * mu, c = r0 * r0 - rl * rl;
    double disc = b * b - c;
    int n = 0;
    if (disc < 0)
        return 0;
    double s = sqrt(disc);
    double roots[2] = {-b - s, -b + s};
    for (int i = 0; i < 2; i++)
        if (roots[i] > 0 && roots[i] < t_end)
            out[n++] = roots[i];
    return n;
}

/* ---- Transmittance ----------------------------------------------------------- */

void sb_ref_optical_depth(const struct sb_atmosphere_params *p, double r, double mu, double t_from, double t_to,
                          int subdivisions, double out[3])
{
    pthread_once(&gl_once, gl_init);
    double br[80];
    int n = 0;
    br[n++] = t_from;
    double cuts[80];
    int m = 0;
    double corners[3] = {p->ozone_center_km - p->ozone_half_width_km, p->ozone_center_km,
                         p->ozone_center_km + p->ozone_half_width_km};
    for (int k = 0; k < 3; k++)
        if (corners[k] > 0)
            m += level_crossings(p, r, mu, t_to, corners[k], cuts + m);
    /* Deep in the exponential tails of a thick atmosphere, cut at 16 H x 2^k
     * (the largest scale height H) too, so that the composite rule's
     * pieces follow the density down. */
    double thickness = p->top_radius_km - p->ground_radius_km;
    double tail = 16.0 * fmax(p->rayleigh_scale_height_km, p->mie_scale_height_km);
    for (int k = 0; k < 30 && tail < thickness; k++, tail *= 2.0)
        m += level_crossings(p, r, mu, t_to, tail, cuts + m);
    if (-r * mu > 0 && -r * mu < t_to)
        cuts[m++] = -r * mu;
    for (int k = 0; k < m; k++)
        if (cuts[k] > t_from)
            br[n++] = cuts[k];
    br[n++] = t_to;
    sort_doubles(br, n);
    out[0] = out[1] = out[2] = 0;
    for (int i = 0; i + 1 < n; i++) {
        double step = (br[i + 1] - br[i]) / subdivisions;
        for (int s = 0; s < subdivisions; s++) {
            double a = br[i] + s * step, half = 0.5 * step;
            for (int k = 0; k < 16; k++) {
                double t = a + half * (1.0 + gl16.x[k]);
                struct sb_ref_medium md;
                sb_ref_medium(p, radius_at(r, mu, t) - p->ground_radius_km, &md);
                for (int c = 0; c < 3; c++)
                    out[c] += half * gl16.w[k] * md.extinction[c];
            }
        }
    }
}

void sb_ref_transmittance(const struct sb_atmosphere_params *p, double r, double mu, int subdivisions, double out[3])
{
    double tau[3];
    sb_ref_optical_depth(p, r, mu, 0.0, dist_top(p, r, mu), subdivisions, tau);
    for (int c = 0; c < 3; c++)
        out[c] = exp(-tau[c]);
}

void sb_ref_transmittance_geometry(const struct sb_atmosphere_params *p, double x_mu, double x_r, double *r_out,
                                   double *mu_out)
{
    double R = p->ground_radius_km, top = p->top_radius_km;
    double H = sqrt(top * top - R * R);
    double rho = H * x_r;
    double r = sqrt(rho * rho + R * R);
    double d_min = top - r, d_max = rho + H;
    double d = d_max - (1.0 - x_mu) * (1.0 - x_mu) * (d_max - d_min);
    double mu = d == 0.0 ? 1.0 : (H * H - rho * rho - d * d) / (2.0 * r * d);
    *r_out = r;
    *mu_out = fmax(-1.0, fmin(1.0, mu));
}

void sb_ref_transmittance_coords(const struct sb_atmosphere_params *p, double r, double mu, double *x_mu, double *x_r)
{
    double R = p->ground_radius_km, top = p->top_radius_km;
    double H = sqrt(top * top - R * R);
    double rho = sqrt(fmax(r * r - R * R, 0.0));
    double d = dist_top(p, r, mu), d_min = top - r, d_max = rho + H;
    *x_mu = d_max > d_min ? 1.0 - sqrt(fmin(fmax((d_max - d) / (d_max - d_min), 0.0), 1.0)) : 0.0;
    *x_r = rho / H;
}

/* ---- LUT lookups ------------------------------------------------------------- */
/*
 * The LUTs a product reads (psi_ms along rays, ground irradiance for the
 * ground seen from the air) are read as the shaders read them: Catmull-Rom
 * of the logarithm (floored at 1e-30) in each axis, the edge texels
 * repeated, on LUTs whose texel i of n sits at x = i / (n - 1). C1, since the
 * kinks of a bilinear lookup slow the sphere quadratures down; in log space,
 * since at twilight these LUTs fall by a factor 5 to 7 per texel and a
 * linear lookup overestimates them by up to 2x.
 */

/* First of the four texels around x in [0, 1] on n texels, and their weights. */
static int cubic_taps(double x, int n, double w[4])
{
    return sb_cubic_taps(fmin(fmax(x, 0.0), 1.0) * (n - 1), n, w);
}

static int clamp_index(int i, int n)
{
    return i < 0 ? 0 : (i > n - 1 ? n - 1 : i);
}

/* The sum of channels c and c + stride (stride 0: channel c alone) of a
 * LUT at unit coordinates (x_u, x_v), channels c = 0..2. */
static void lut_log_cubic(const struct sb_image *lut, double x_u, double x_v, uint32_t stride, double out[3])
{
    int w = (int)lut->width, h = (int)lut->height, nc = (int)lut->channel_count;
    double wx[4], wy[4];
    int x0 = cubic_taps(x_u, w, wx), y0 = cubic_taps(x_v, h, wy);
    for (int c = 0; c < 3; c++) {
        double sum = 0;
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 4; i++) {
                const float *texel = lut->data + ((size_t)clamp_index(y0 + j, h) * w + clamp_index(x0 + i, w)) * nc;
                double v = (double)texel[c] + (stride ? (double)texel[c + stride] : 0.0);
                sum += wx[i] * wy[j] * log(fmax(v, 1e-30));
            }
        out[c] = exp(sum);
    }
}

void sb_ref_multiscattering_lookup(const struct sb_atmosphere_params *p, const struct sb_image *lut, double h,
                                   double mu_s, double out[3])
{
    lut_log_cubic(lut, mu_s * 0.5 + 0.5, h / (p->top_radius_km - p->ground_radius_km), 0, out);
}

/* ---- Scattering along a ray ------------------------------------------------- */

struct ray_sums {
    double sun_rayleigh[3], sun_mie[3], ms_rayleigh[3], ms_mie[3], scattering[3], transmittance[3];
    double t_end;
};

/* A texel's optical depth, as the lookup form holds it (physics.h). */
static double depth_of(float t)
{
    return -log(fmax((double)t, 1e-30));
}

void sb_ref_transmittance_lookup(const struct sb_atmosphere_params *p, const struct sb_image *lut, double r, double mu,
                                 double out[3])
{
    double x_mu, x_r;
    sb_ref_transmittance_coords(p, r, mu, &x_mu, &x_r);
    int w = (int)lut->width, h = (int)lut->height;
    double fx = fmin(fmax(x_mu * (w - 1), 0.0), w - 1.0), fy = fmin(fmax(x_r * (h - 1), 0.0), h - 1.0);
    int x0 = (int)fx < w - 2 ? (int)fx : w - 2, y0 = (int)fy < h - 2 ? (int)fy : h - 2;
    double ax = fx - x0, ay = fy - y0;
    for (int c = 0; c < 3; c++) {
        const float *d = lut->data;
        size_t nc = lut->channel_count;
        double v00 = depth_of(d[((size_t)y0 * w + x0) * nc + c]), v10 = depth_of(d[((size_t)y0 * w + x0 + 1) * nc + c]);
        double v01 = depth_of(d[((size_t)(y0 + 1) * w + x0) * nc + c]);
        double v11 = depth_of(d[((size_t)(y0 + 1) * w + x0 + 1) * nc + c]);
        out[c] = exp(-((v00 * (1 - ax) + v10 * ax) * (1 - ay) + (v01 * (1 - ax) + v11 * ax) * ay));
    }
}

/* t_lut: NULL to integrate the sun's transmittance exactly, else read it from this LUT. */
static void integrate_ray(const struct sb_atmosphere_params *p, double r0, double mu, double mu_s, double nu,
                          bool toward_ground, const struct sb_image *ms_lut, const struct sb_image *t_lut,
                          const struct sb_ref_quality *q, struct ray_sums *o)
{
    memset(o, 0, sizeof(*o));
    double R = p->ground_radius_km, thickness = p->top_radius_km - R;
    double t_end = toward_ground ? dist_ground(p, r0, mu) : dist_top(p, r0, mu);
    o->t_end = t_end;
    double br[MAX_BREAKS];
    int n = 0;
    br[n++] = 0;
    double level = 0.25 * fmin(p->rayleigh_scale_height_km, p->mie_scale_height_km);
    double factor = pow(2.0, 1.0 / q->level_steps);
    while (level < thickness && n < MAX_BREAKS - 8) {
        n += level_crossings(p, r0, mu, t_end, level, br + n);
        level *= factor;
    }
    if (-r0 * mu > 0 && -r0 * mu < t_end)
        br[n++] = -r0 * mu;
    /* Where the planet starts or stops hiding the sun along the ray. */
    double a = r0 * mu_s, b = nu;
    double qa = 1 - b * b, qb = 2 * r0 * mu - 2 * a * b, qc = r0 * r0 - a * a - R * R;
    double roots[2];
    int nroots = 0;
    if (fabs(qa) > 1e-12) {
        double disc = qb * qb - 4 * qa * qc;
        if (disc >= 0) {
            roots[nroots++] = (-qb - sqrt(disc)) / (2 * qa);
            roots[nroots++] = (-qb + sqrt(disc)) / (2 * qa);
        }
    } else if (fabs(qb) > 1e-12) {
        roots[nroots++] = -qc / qb;
    }
    for (int i = 0; i < nroots; i++)
        if (roots[i] > 0 && roots[i] < t_end && a + b * roots[i] < 0)
            br[n++] = roots[i];
    br[n++] = t_end;
    sort_doubles(br, n);

    double tau[3] = {0, 0, 0};
    for (int s = 0; s + 1 < n; s++) {
        double half = 0.5 * (br[s + 1] - br[s]);
        if (half <= 0)
            continue;
        struct sb_ref_medium m[8];
        double sun[8][3], psi[8][3];
        for (int j = 0; j < 8; j++) {
            double t = br[s] + half * (1 + gl8.x[j]);
            double rt = radius_at(r0, mu, t);
            double h = fmax(rt - R, 0.0);
            double mus = fmax(-1.0, fmin(1.0, (r0 * mu_s + t * nu) / rt));
            sb_ref_medium(p, h, &m[j]);
            if (hits_ground(p, rt, mus)) {
                sun[j][0] = sun[j][1] = sun[j][2] = 0;
            } else if (t_lut) {
                sb_ref_transmittance_lookup(p, t_lut, fmax(rt, R), mus, sun[j]);
            } else {
                sb_ref_transmittance(p, fmax(rt, R), mus, q->transmittance_subdivisions, sun[j]);
            }
            if (ms_lut)
                lut_log_cubic(ms_lut, mus * 0.5 + 0.5, h / thickness, 0, psi[j]);
        }
        for (int i = 0; i < 8; i++)
            for (int c = 0; c < 3; c++) {
                double depth = tau[c];
                for (int j = 0; j < 8; j++)
                    depth += half * gl8.s[i][j] * m[j].extinction[c];
                double tw = exp(-depth) * half * gl8.w[i];
                o->sun_rayleigh[c] += tw * m[i].rayleigh[c] * sun[i][c];
                o->sun_mie[c] += tw * m[i].mie[c] * sun[i][c];
                o->scattering[c] += tw * (m[i].rayleigh[c] + m[i].mie[c]);
                if (ms_lut) {
                    o->ms_rayleigh[c] += tw * m[i].rayleigh[c] * psi[i][c];
                    o->ms_mie[c] += tw * m[i].mie[c] * psi[i][c];
                }
            }
        for (int j = 0; j < 8; j++)
            for (int c = 0; c < 3; c++)
                tau[c] += half * gl8.w[j] * m[j].extinction[c];
    }
    for (int c = 0; c < 3; c++)
        o->transmittance[c] = exp(-tau[c]);
}

void sb_ref_gauss_legendre(int n, double a, double b, double *x, double *w)
{
    for (int k = 0; k < n; k++)
        sb_gauss_legendre_node(k, n, a, b, &x[k], &w[k]);
}

static struct sb_ref_quality resolve(const struct sb_ref_quality *q)
{
    struct sb_ref_quality r = q ? *q : (struct sb_ref_quality){0};
    if (!r.directions_mu)
        r.directions_mu = 32;
    if (!r.directions_phi)
        r.directions_phi = 16;
    if (!r.level_steps)
        r.level_steps = 2;
    if (!r.transmittance_subdivisions)
        r.transmittance_subdivisions = 2;
    return r;
}

/*
 * Quadrature in cos(zenith). The sphere is cut into pieces where the
 * integrand is not smooth or changes scale: the horizon (the ray meets the
 * ground below it); below it, where the ray's virtual tangent point is 2.5
 * and 25 scale heights under the ground; above it, the directions whose
 * tangent point sits at a kink of the density (the ozone tent's corners);
 * the sun's mirror image mu = -mu_s; and the sun, for products with a
 * forward-peaked phase function. Next to the horizon a ray integral
 * behaves like sqrt(|mu - mu_h|) (the path through the dense air near the
 * tangent point), so those pieces take Gauss-Legendre nodes in s with
 * mu = mu_h +- (range) s^2, in which the integrand is smooth; pieces next
 * to the peak crowd their nodes toward it the same way.
 */
struct zenith_piece {
    double lo, hi;
    bool ground;             /* below the horizon */
    bool crowd_lo, crowd_hi; /* nodes crowded toward that end (horizon or peak) */
};

/* Cut the piece strictly containing mu there; `crowd`: toward the cut. */
static int split_piece(struct zenith_piece *out, int n, double mu, bool crowd)
{
    for (int i = 0; i < n; i++) {
        if (!(mu > out[i].lo && mu < out[i].hi))
            continue;
        memmove(out + i + 2, out + i + 1, (size_t)(n - i - 1) * sizeof(*out));
        out[i + 1] = out[i];
        out[i + 1].lo = mu;
        out[i + 1].crowd_lo = crowd;
        out[i].hi = mu;
        out[i].crowd_hi = crowd;
        return n + 1;
    }
    return n;
}

static int zenith_pieces(const struct sb_atmosphere_params *p, double h, bool whole_sphere, double mu_s, bool peaked,
                         struct zenith_piece *out)
{
    double R = p->ground_radius_km, r = R + h;
    double mu_h = whole_sphere ? -sqrt(fmax(1.0 - (R / r) * (R / r), 0.0)) : 0.0;
    int n = 0;
    if (whole_sphere) {
        /* Below the horizon, cut where the ray's (virtual) tangent point is
         * 25 and 2.5 smallest scale heights below the ground: the ray
         * integral goes from a grazing path to a slant one over a few. */
        double scale = fmin(p->rayleigh_scale_height_km, p->mie_scale_height_km), lo = -1.0;
        const double depths[2] = {25 * scale, 2.5 * scale};
        for (int i = 0; i < 2; i++) {
            double rt = R - depths[i];
            if (rt <= 0)
                continue;
            double mu = -sqrt(1.0 - (rt / r) * (rt / r));
            if (mu > lo && mu < mu_h) {
                out[n++] = (struct zenith_piece){lo, mu, true, false, false};
                lo = mu;
            }
        }
        out[n++] = (struct zenith_piece){lo, mu_h, true, false, true};
    }
    double corners[3] = {p->ozone_center_km - p->ozone_half_width_km, p->ozone_center_km,
                         p->ozone_center_km + p->ozone_half_width_km};
    double from = mu_h;
    int first_sky = n;
    for (int i = 0; i < 3 && whole_sphere; i++) {
        if (corners[i] <= 0 || corners[i] >= h)
            continue;
        double rc = R + corners[i];
        double mu_c = -sqrt(1.0 - (rc / r) * (rc / r));
        if (mu_c > from) {
            out[n] = (struct zenith_piece){from, mu_c, false, n == first_sky, false};
            n++;
            from = mu_c;
        }
    }
    out[n] = (struct zenith_piece){from, 1.0, false, n == first_sky, false};
    n++;
    /* Above the cuts so far, the light of the air fades as exp(-z / H) with
     * the ray's tangent altitude z: from high up (the atmosphere as thick
     * as its planet) the piece reaching to the zenith is too long for
     * that fade (16 nodes miss it by 20% with the sun set). Cut where it
     * has faded, at 25 largest scale heights. */
    double z_fade = 25 * fmax(p->rayleigh_scale_height_km, p->mie_scale_height_km);
    if (whole_sphere && z_fade < h)
        n = split_piece(out, n, -sqrt(1.0 - ((R + z_fade) / r) * ((R + z_fade) / r)), false);
    /* The sun's mirror image in the horizontal plane: the azimuthal
     * integral kinks there (rays leaving parallel to the shadow's edge,
     * mu = mu_s nu, reach azimuth pi). A forward-peaked phase function
     * peaks at the sun: cut there too, crowding toward it. */
    n = split_piece(out, n, -mu_s, false);
    if (peaked)
        n = split_piece(out, n, mu_s, true);
    return n;
}

static double crowd(double u, bool lo, bool hi, double *dx);

static void zenith_node(const struct zenith_piece *piece, int k, int n, double *mu, double *w)
{
    double s, ws, dx;
    sb_gauss_legendre_node(k, n, 0.0, 1.0, &s, &ws);
    double x = crowd(s, piece->crowd_lo, piece->crowd_hi, &dx);
    *mu = piece->lo + (piece->hi - piece->lo) * x;
    *w = (piece->hi - piece->lo) * dx * ws;
}

/* Azimuth node ip of n over [0, pi]: the midpoint rule in v, with
 * phi = pi (v - sin(2 pi v) / (2 pi)) if `crowd`, crowding toward the sun's
 * side where the Mie peak is. *w includes the factor 2 for the other half. */
static void azimuth_node(int ip, int n, bool crowd, double *cos_phi, double *w)
{
    double v = (ip + 0.5) / n;
    double phi = crowd ? REF_PI * (v - sin(2 * REF_PI * v) / (2 * REF_PI)) : REF_PI * v;
    *cos_phi = cos(phi);
    *w = 2 * REF_PI * (crowd ? 1 - cos(2 * REF_PI * v) : 1.0) / n;
}

/* A direction of a sphere (or hemisphere) quadrature around a point. */
struct direction {
    double mu, nu, weight; /* cos(zenith), cos(angle to the sun), solid angle */
    bool ground;           /* the ray ends on the ground */
};

/* Every direction of the quadrature at altitude h with the sun at mu_s; the
 * caller frees *out. Returns the count, or 0 when out of memory. */
static int directions(const struct sb_atmosphere_params *p, const struct sb_ref_quality *q, double h, double mu_s,
                      bool whole_sphere, bool peaked, struct direction **out)
{
    struct zenith_piece pieces[SB_SPHERE_MAX_PIECES];
    int piece_count = zenith_pieces(p, h, whole_sphere, mu_s, peaked, pieces);
    int n = 0;
    *out = malloc((size_t)piece_count * q->directions_mu * q->directions_phi * sizeof(**out));
    if (!*out)
        return 0;
    double sin_s = sqrt(fmax(1 - mu_s * mu_s, 0.0));
    for (int pc = 0; pc < piece_count; pc++)
        for (int k = 0; k < q->directions_mu; k++) {
            double mu, w_mu;
            zenith_node(&pieces[pc], k, q->directions_mu, &mu, &w_mu);
            double sin_v = sqrt(fmax(1 - mu * mu, 0.0));
            for (int ip = 0; ip < q->directions_phi; ip++) {
                double cos_phi, w_phi;
                azimuth_node(ip, q->directions_phi, peaked, &cos_phi, &w_phi);
                (*out)[n++] = (struct direction){
                    .mu = mu,
                    .nu = fmax(-1.0, fmin(1.0, sin_v * sin_s * cos_phi + mu * mu_s)),
                    .weight = w_mu * w_phi,
                    .ground = pieces[pc].ground,
                };
            }
        }
    return n;
}

/*
 * Mie single scattering, E_sun P_M(nu) S(w) with S = integral of T sigma_M
 * T_sun dt, has a peak of its own: at the sun (at the anti-sun for g < 0),
 * about 1 - |g| wide, which a grid fixed to the zenith does not resolve for
 * g near +-1 (at g = 0.999, 24^2 directions left 10% errors). So it gets a
 * cap around the peak's axis, where the phase function takes the share
 * alpha and the zenith grid the rest, 1 - alpha:
 * - over a hemisphere (irradiance_ground) the cap is all of it, alpha = 1;
 * - over the sphere (irradiance_sky), where the light can come mostly from
 *   far from the peak (below the horizon, from high up), the cap has radius
 *   SB_CAP_THETA and alpha falls smoothly to 0 at twice that, and only for
 *   |g| >= SB_CAP_MIN_G: below it the zenith grid, crowded toward the sun,
 *   resolves the peak.
 *
 * The cap's directions: o = 1 - nu' (nu' = sign(g) nu, the cosine to the
 * axis; o is exact near the peak, where nu is not in fp32) and psi =
 * azimuth about the axis from its vertical plane (toward the zenith),
 * d(solid angle) = do dpsi. The rings of constant o take Gauss-Legendre
 * nodes in t = ln((1 - |g|)^2 + 2 |g| o), in which Henyey-Greenstein's
 * peak is a plain exponential, so the nodes spread evenly in the log of the
 * angle from the axis and resolve both the peak and S far from it;
 * P_M do = k (1 + nu^2) dt / (2 |g| sqrt(e^t)), without cancellation.
 *
 * The horizon cuts the rings: mu = mu_a nu' + sin_a sin' cos(psi) (mu_a:
 * the axis's cosine) meets mu_h at psi_h, where S jumps (rays toward the
 * ground) or, for a hemisphere, the integration ends. Each ring is split
 * there, nodes crowded toward the cut (S goes like sqrt(mu - mu_h) there, as
 * in the zenith grid). The rings that touch the horizon, at angles
 * |e_a - e_h| and pi - |e_a + e_h| from the axis (e: elevations), cut o
 * into pieces, their nodes crowded toward those cuts, where the rings'
 * split appears.
 */
static bool cap_active(const struct sb_atmosphere_params *p, bool whole_sphere)
{
    return !whole_sphere || fabs(p->mie_g) >= SB_CAP_MIN_G;
}

/* alpha at o = 1 - nu'. */
static double cap_window_o(const struct sb_atmosphere_params *p, bool whole_sphere, double o)
{
    if (!cap_active(p, whole_sphere))
        return 0.0;
    if (!whole_sphere)
        return 1.0;
    double o_1 = 2 * sin(0.5 * SB_CAP_THETA) * sin(0.5 * SB_CAP_THETA), o_2 = 2 * sin(SB_CAP_THETA) * sin(SB_CAP_THETA);
    double x = fmax(0.0, fmin(1.0, (o_2 - o) / (o_2 - o_1)));
    return x * x * (3 - 2 * x);
}

/* alpha at a zenith-grid direction with sun cosine nu. */
static double cap_window(const struct sb_atmosphere_params *p, bool whole_sphere, double nu)
{
    return cap_window_o(p, whole_sphere, 1 - (p->mie_g < 0 ? -nu : nu));
}

/* Nodes crowded toward an end, or both: x(u) in [0, 1] with dx = x'(u),
 * flat (as u^2) at a crowded end. */
static double crowd(double u, bool lo, bool hi, double *dx)
{
    *dx = 1.0;
    if (lo && hi) {
        *dx = 6 * u * (1 - u);
        return u * u * (3 - 2 * u);
    }
    if (lo) {
        *dx = 2 * u;
        return u * u;
    }
    if (hi) {
        *dx = 2 * (1 - u);
        return 1 - (1 - u) * (1 - u);
    }
    return u;
}

/* A direction of the cap: phase_weight = P_M(nu) alpha times its solid angle. */
struct cap_direction {
    double mu, nu, phase_weight;
    bool ground;
};

/* Every direction of the cap; the caller frees *out. Returns the count, or
 * -1 when out of memory. */
static int cap_directions(const struct sb_atmosphere_params *p, const struct sb_ref_quality *q, double h, double mu_s,
                          bool whole_sphere, struct cap_direction **out)
{
    double R = p->ground_radius_km, r = R + h, g = fabs(p->mie_g), sign = p->mie_g < 0 ? -1.0 : 1.0;
    double mu_h = whole_sphere ? -sqrt(fmax(1.0 - (R / r) * (R / r), 0.0)) : 0.0;
    double mu_a = sign * mu_s, e_a = asin(mu_a), e_h = asin(mu_h);
    double reach = whole_sphere ? 2 * SB_CAP_THETA : REF_PI;
    double o_end = whole_sphere ? 2 * sin(SB_CAP_THETA) * sin(SB_CAP_THETA) : 2.0;
    double a = 0.5 * fabs(e_a - e_h), b = 0.5 * fabs(e_a + e_h);
    double cuts[2] = {2 * sin(a) * sin(a), 2 * cos(b) * cos(b)};
    struct {
        double lo, hi;
        bool crowd_lo, crowd_hi;
    } pieces[3];
    int piece_count = 0;
    double from = 0.0;
    for (int i = 0; i < 2; i++)
        if (cuts[i] > from && cuts[i] < o_end) {
            pieces[piece_count].lo = from;
            pieces[piece_count].hi = cuts[i];
            pieces[piece_count].crowd_lo = from > 0;
            pieces[piece_count++].crowd_hi = true;
            from = cuts[i];
        }
    pieces[piece_count].lo = from;
    pieces[piece_count].hi = o_end;
    pieces[piece_count].crowd_lo = from > 0;
    pieces[piece_count++].crowd_hi = false;
    int side_first = e_a - e_h > -reach ? 0 : 1, side_end = whole_sphere && e_a - e_h < reach ? 2 : 1;
    *out = malloc((size_t)piece_count * q->directions_mu * (side_end - side_first) * q->directions_phi * sizeof(**out));
    if (!*out)
        return -1;
    double qg = (1 - g) * (1 - g), k_phase = 3.0 / (8.0 * REF_PI) * (1 - g * g) / (2 + g * g);
    double sin_a = sqrt(fmax(1 - mu_s * mu_s, 0.0));
    int n = 0;
    for (int pc = 0; pc < piece_count; pc++)
        for (int k = 0; k < q->directions_mu; k++) {
            double u, w_u, dx, lo = pieces[pc].lo, hi = pieces[pc].hi, o, phase_do;
            sb_gauss_legendre_node(k, q->directions_mu, 0.0, 1.0, &u, &w_u);
            double x = crowd(u, pieces[pc].crowd_lo, pieces[pc].crowd_hi, &dx);
            if (g < 0.01) {
                o = lo + (hi - lo) * x;
                phase_do = k_phase * (1 + (1 - o) * (1 - o)) / pow(qg + 2 * g * o, 1.5) * (hi - lo) * dx * w_u;
            } else {
                double t_lo = log(qg + 2 * g * lo), t_hi = log(qg + 2 * g * hi);
                double e = exp(t_lo + (t_hi - t_lo) * x);
                o = fmax(lo, fmin(hi, (e - qg) / (2 * g)));
                phase_do = k_phase * (1 + (1 - o) * (1 - o)) * (t_hi - t_lo) * dx * w_u / (2 * g * sqrt(e));
            }
            double nu_a = 1 - o, sin_v = sqrt(fmax(o * (2 - o), 0.0));
            double radius = sin_a * sin_v, centre = mu_a * nu_a;
            /* psi_h: the ring is above the horizon for psi < psi_h */
            double psi_h =
                radius > 0 ? acos(fmax(-1.0, fmin(1.0, (mu_h - centre) / radius))) : (centre >= mu_h ? REF_PI : 0.0);
            double alpha = cap_window_o(p, whole_sphere, o);
            for (int side = side_first; side < side_end; side++) {
                double psi_lo = side ? psi_h : 0.0, psi_hi = side ? REF_PI : psi_h;
                for (int ip = 0; ip < q->directions_phi; ip++) {
                    double v, w_v, dy;
                    sb_gauss_legendre_node(ip, q->directions_phi, 0.0, 1.0, &v, &w_v);
                    /* crowded toward psi_h: the end of the sky side, the start of the ground side */
                    double y = crowd(v, side == 1, side == 0, &dy);
                    double mu = fmax(-1.0, fmin(1.0, centre + radius * cos(psi_lo + (psi_hi - psi_lo) * y)));
                    (*out)[n++] = (struct cap_direction){
                        .mu = side ? fmin(mu, mu_h) : fmax(mu, mu_h),
                        .nu = sign * nu_a,
                        .phase_weight = 2 * phase_do * alpha * (psi_hi - psi_lo) * dy * w_v,
                        .ground = side == 1,
                    };
                }
            }
        }
    return n;
}

void sb_ref_multiscattering(const struct sb_atmosphere_params *p, double h, double mu_s,
                            const struct sb_ref_quality *quality, double out[3])
{
    pthread_once(&gl_once, gl_init);
    struct sb_ref_quality q = resolve(quality);
    double R = p->ground_radius_km, r = R + h;
    double l2[3] = {0, 0, 0}, f[3] = {0, 0, 0};
    struct direction *dirs;
    int n = directions(p, &q, h, mu_s, true, false, &dirs);
    for (int i = 0; i < n; i++) {
        const struct direction *d = &dirs[i];
        struct ray_sums rs;
        integrate_ray(p, r, d->mu, mu_s, d->nu, d->ground, NULL, NULL, &q, &rs);
        double ground_term[3] = {0, 0, 0};
        double mu_sp = fmax(-1.0, fmin(1.0, (r * mu_s + rs.t_end * d->nu) / R));
        if (d->ground && mu_sp > 0) {
            double ts[3];
            sb_ref_transmittance(p, R, mu_sp, q.transmittance_subdivisions, ts);
            for (int c = 0; c < 3; c++)
                ground_term[c] = rs.transmittance[c] * p->ground_albedo[c] / REF_PI * mu_sp * ts[c];
        }
        for (int c = 0; c < 3; c++) {
            l2[c] += d->weight * ((rs.sun_rayleigh[c] + rs.sun_mie[c]) / (4 * REF_PI) + ground_term[c]);
            f[c] += d->weight * rs.scattering[c];
        }
    }
    free(dirs);
    for (int c = 0; c < 3; c++) {
        double L2 = l2[c] / (4 * REF_PI), fms = f[c] / (4 * REF_PI);
        out[c] = n ? p->solar_irradiance[c] * L2 / (1 - fms) : NAN;
    }
}

/* Add the cap's share of Mie single scattering, E_sun P_M alpha S [mu], to
 * out[0..2], scaled by `scale`; with !whole_sphere over the upper
 * hemisphere, weighted by mu. Returns false when out of memory. */
static bool add_mie_cap(const struct sb_atmosphere_params *p, const struct sb_ref_quality *q, double h, double mu_s,
                        bool whole_sphere, double scale, double out[3])
{
    if (!cap_active(p, whole_sphere))
        return true;
    double r = p->ground_radius_km + h;
    struct cap_direction *dirs;
    int n = cap_directions(p, q, h, mu_s, whole_sphere, &dirs);
    for (int i = 0; i < n; i++) {
        const struct cap_direction *d = &dirs[i];
        if (d->phase_weight <= 0)
            continue;
        struct ray_sums rs;
        integrate_ray(p, r, d->mu, mu_s, d->nu, d->ground, NULL, NULL, q, &rs);
        double w = scale * d->phase_weight * (whole_sphere ? 1.0 : d->mu);
        for (int c = 0; c < 3; c++)
            out[c] += w * p->solar_irradiance[c] * rs.sun_mie[c];
    }
    if (n >= 0)
        free(dirs);
    return n >= 0;
}

void sb_ref_irradiance_ground(const struct sb_atmosphere_params *p, double h, double mu_s,
                              const struct sb_image *ms_lut, const struct sb_ref_quality *quality, double direct[3],
                              double sky[3])
{
    pthread_once(&gl_once, gl_init);
    struct sb_ref_quality q = resolve(quality);
    double r = p->ground_radius_km + h;
    double t[3] = {0, 0, 0};
    if (mu_s > 0)
        sb_ref_transmittance(p, r, mu_s, 8, t);
    struct direction *dirs;
    int n = directions(p, &q, h, mu_s, false, false, &dirs); /* Mie's peak: on the cap */
    for (int c = 0; c < 3; c++) {
        direct[c] = mu_s > 0 ? p->solar_irradiance[c] * t[c] * mu_s : 0.0;
        sky[c] = 0.0;
    }
    for (int i = 0; i < n; i++) {
        const struct direction *d = &dirs[i];
        struct ray_sums rs;
        integrate_ray(p, r, d->mu, mu_s, d->nu, false, ms_lut, NULL, &q, &rs);
        double w = d->weight * d->mu, mie = sb_ref_phase_mie(p->mie_g, d->nu) * (1 - cap_window(p, false, d->nu));
        for (int c = 0; c < 3; c++)
            sky[c] += w * (p->solar_irradiance[c] *
                               (rs.sun_rayleigh[c] * sb_ref_phase_rayleigh(d->nu) + rs.sun_mie[c] * mie) +
                           rs.ms_rayleigh[c] + rs.ms_mie[c]);
    }
    free(dirs);
    if (!n || !add_mie_cap(p, &q, h, mu_s, false, 1.0, sky))
        sky[0] = sky[1] = sky[2] = NAN;
}

void sb_ref_irradiance_sky(const struct sb_atmosphere_params *p, double h, double mu_s, const struct sb_image *ms_lut,
                           const struct sb_image *ig_lut, const struct sb_ref_quality *quality, double out[9])
{
    pthread_once(&gl_once, gl_init);
    struct sb_ref_quality q = resolve(quality);
    double R = p->ground_radius_km, r = R + h;
    struct direction *dirs;
    int n = directions(p, &q, h, mu_s, true, true, &dirs);
    for (int c = 0; c < 9; c++)
        out[c] = 0.0;
    for (int i = 0; i < n; i++) {
        const struct direction *d = &dirs[i];
        double w = d->weight / (4 * REF_PI), nu = d->nu;
        double mie = sb_ref_phase_mie(p->mie_g, nu) * (1 - cap_window(p, true, nu));
        struct ray_sums rs;
        integrate_ray(p, r, d->mu, mu_s, nu, d->ground, ms_lut, NULL, &q, &rs);
        double eg[3] = {0};
        if (d->ground && ig_lut) {
            double mu_sp = fmax(-1.0, fmin(1.0, (r * mu_s + rs.t_end * nu) / R));
            lut_log_cubic(ig_lut, mu_sp * 0.5 + 0.5, 0.0, 3, eg); /* direct + sky */
        }
        for (int c = 0; c < 3; c++) {
            out[c] += w * (p->solar_irradiance[c] * rs.sun_rayleigh[c] * sb_ref_phase_rayleigh(nu) + rs.ms_rayleigh[c]);
            out[3 + c] += w * (p->solar_irradiance[c] * rs.sun_mie[c] * mie + rs.ms_mie[c]);
            if (d->ground)
                out[6 + c] += w * rs.transmittance[c] * p->ground_albedo[c] / REF_PI * eg[c];
        }
    }
    free(dirs);
    if (!n || !add_mie_cap(p, &q, h, mu_s, true, 1 / (4 * REF_PI), out + 3))
        for (int c = 0; c < 9; c++)
            out[c] = NAN;
}

void sb_ref_sky_radiance(const struct sb_atmosphere_params *p, double h, double mu, double mu_s, double nu,
                         const struct sb_image *t_lut, const struct sb_image *ms_lut, const struct sb_image *ig_lut,
                         const struct sb_ref_quality *quality, double out[3])
{
    pthread_once(&gl_once, gl_init);
    struct sb_ref_quality q = resolve(quality);
    double R = p->ground_radius_km, r = R + h, top = p->top_radius_km;
    out[0] = out[1] = out[2] = 0.0;
    if (r > top) {
        /* From outside: start where the ray enters the atmosphere, or see
         * black space where it misses it. */
        double b = r * mu, disc = b * b - (r - top) * (r + top);
        if (mu >= 0.0 || disc < 0.0)
            return;
        double t = (r - top) * (r + top) / (-b + sqrt(disc)); /* the nearer root, without cancellation */
        double r_entry = top;
        mu = fmin(1.0, (r * mu + t) / r_entry);
        mu_s = fmax(-1.0, fmin(1.0, (r * mu_s + t * nu) / r_entry));
        r = r_entry;
    }
    bool ground = hits_ground(p, r, mu);
    struct ray_sums rs;
    integrate_ray(p, r, mu, mu_s, nu, ground, ms_lut, t_lut, &q, &rs);
    double eg[3] = {0};
    if (ground && ig_lut) {
        double mu_sp = fmax(-1.0, fmin(1.0, (r * mu_s + rs.t_end * nu) / R));
        lut_log_cubic(ig_lut, mu_sp * 0.5 + 0.5, 0.0, 3, eg);
    }
    for (int c = 0; c < 3; c++) {
        out[c] = p->solar_irradiance[c] *
                     (rs.sun_rayleigh[c] * sb_ref_phase_rayleigh(nu) + rs.sun_mie[c] * sb_ref_phase_mie(p->mie_g, nu)) +
                 rs.ms_rayleigh[c] + rs.ms_mie[c];
        if (ground && ig_lut)
            out[c] += rs.transmittance[c] * p->ground_albedo[c] / REF_PI * eg[c];
    }
}
