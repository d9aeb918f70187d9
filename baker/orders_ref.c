#include "orders_ref.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "atmosphere_ref.h"
#include "config.h"
#include "log.h"
#include "parallel.h"
#include "physics.h"

#define ORD_PI 3.14159265358979323846
#define DEPTH_W 1024 /* the optical-depth table: x_mu */
#define DEPTH_H 1024 /* x_r */
#define GL_RAY 4     /* Gauss-Legendre nodes per piece of a ray */
#define MAX_PIECES (2 * SB_MAX_LEVELS + 4)
#define SPHERE_GROUND 8 /* the density's directions: cos(zenith) toward the ground */
#define SPHERE_SKY 16   /* and toward the sky (Gauss-Legendre on each side of the horizon) */
#define SPHERE_PHI 16   /* azimuths (midpoints over 2 pi) */
#define HEMI_MU 16      /* the ground's irradiance: cos(zenith) */
#define HEMI_PHI 32
#define MIE_U 16   /* the density's Mie part: quantiles of Henyey-Greenstein's scattering angle */
#define MIE_PHI 16 /* and azimuths about the view */

/* n + 1 altitudes from 0 to Z: h_i = Z (q^i - 1) / (q^n - 1), or Z i / n
 * for q = 1 (q: sb_orders_height_ratio). */
struct progression {
    double Z, q;
    int n;
};

struct sb_orders_ref {
    struct sb_atmosphere_params p;
    int nr, nmu, nmus, nnu;
    double R, top, mu_s_min;
    double grid_top, H;         /* the grid's top (sb_orders_top_km) and the horizon's distance from it */
    struct progression heights; /* the r nodes' altitudes */
    double levels[SB_MAX_LEVELS];
    int level_count;
    double *depth; /* DEPTH_W x DEPTH_H x 3: optical depth to the top */
    /* per node, rgb */
    double *single_r, *single_m; /* single scattering without its phase */
    double *density, *order, *previous, *sum;
    /* the ground's irradiance by mu_s node: the sky's orders 1 and up */
    double *ground, *ground_order;
    double nu_power;  /* the azimuth nodes' pi x^p (sb_orders_azimuth_power) */
    bool log_azimuth; /* views read the sun's azimuth log-trigonometrically (sb_orders_log_azimuth) */
    int orders;
    double last_share;
    double tail[3]; /* the last order's factor for the orders after it (sb_orders_tail_factor) */
    double gl_ray_x[GL_RAY], gl_ray_w[GL_RAY];
    double gl_ground_x[SPHERE_GROUND], gl_ground_w[SPHERE_GROUND];
    double gl_sky_x[SPHERE_SKY], gl_sky_w[SPHERE_SKY];
    double gl_hemi_x[HEMI_MU], gl_hemi_w[HEMI_MU];
    double gl_mie_x[MIE_U], gl_mie_w[MIE_U];
};

/* ---- Altitudes in a geometric progression ----------------------------------- */

static double progression_at(const struct progression *g, int i)
{
    if (i >= g->n)
        return g->Z;
    return g->q == 1.0 ? g->Z * i / g->n : g->Z * (pow(g->q, i) - 1) / (pow(g->q, g->n) - 1);
}

/* The continuous index of altitude h, clamped to [0, n]. */
static double progression_index(const struct progression *g, double h)
{
    h = fmin(fmax(h, 0.0), g->Z);
    double i = g->q == 1.0 ? h / g->Z * g->n : log1p(h / g->Z * (pow(g->q, g->n) - 1)) / log(g->q);
    return fmin(fmax(i, 0.0), (double)g->n);
}

/* ---- The optical depth -------------------------------------------------------- */

static double clamp1(double x)
{
    return fmax(-1.0, fmin(1.0, x));
}

/* The optical depth from (r, mu) to the top; the ray must not hit the ground. */
static void depth_to_top(const struct sb_orders_ref *o, double r, double mu, double out[3])
{
    double x_mu, x_r;
    sb_ref_transmittance_coords(&o->p, fmin(fmax(r, o->R), o->top), clamp1(mu), &x_mu, &x_r);
    double fx = fmin(fmax(x_mu * (DEPTH_W - 1), 0.0), DEPTH_W - 1.0);
    double fy = fmin(fmax(x_r * (DEPTH_H - 1), 0.0), DEPTH_H - 1.0);
    int x0 = fx < DEPTH_W - 2 ? (int)fx : DEPTH_W - 2, y0 = fy < DEPTH_H - 2 ? (int)fy : DEPTH_H - 2;
    double ax = fx - x0, ay = fy - y0;
    const double *d = o->depth;
    for (int c = 0; c < 3; c++) {
        double v00 = d[((size_t)y0 * DEPTH_W + x0) * 3 + c], v10 = d[((size_t)y0 * DEPTH_W + x0 + 1) * 3 + c];
        double v01 = d[((size_t)(y0 + 1) * DEPTH_W + x0) * 3 + c];
        double v11 = d[((size_t)(y0 + 1) * DEPTH_W + x0 + 1) * 3 + c];
        out[c] = (v00 * (1 - ax) + v10 * ax) * (1 - ay) + (v01 * (1 - ax) + v11 * ax) * ay;
    }
}

static void depth_row(void *user, int y)
{
    struct sb_orders_ref *o = user;
    for (int x = 0; x < DEPTH_W; x++) {
        double r, mu, t[3];
        sb_ref_transmittance_geometry(&o->p, (double)x / (DEPTH_W - 1), (double)y / (DEPTH_H - 1), &r, &mu);
        sb_ref_transmittance(&o->p, r, mu, 2, t);
        for (int c = 0; c < 3; c++)
            o->depth[((size_t)y * DEPTH_W + x) * 3 + c] = -log(fmax(t[c], 1e-300));
    }
}

static bool hits_ground(const struct sb_orders_ref *o, double r, double mu)
{
    return mu < 0.0 && r * r * (mu * mu - 1.0) + o->R * o->R >= 0.0;
}

static double dist_ground(const struct sb_orders_ref *o, double r, double mu)
{
    return fmax(-r * mu - sqrt(fmax(r * r * (mu * mu - 1.0) + o->R * o->R, 0.0)), 0.0);
}

static double dist_to(double r, double mu, double top)
{
    return fmax(-r * mu + sqrt(fmax(r * r * (mu * mu - 1.0) + top * top, 0.0)), 0.0);
}

static double dist_top(const struct sb_orders_ref *o, double r, double mu)
{
    return dist_to(r, mu, o->top);
}

/* Transmittance along the ray from (r, mu) to distance t on it (Bruneton's
 * ratio of depths to the top; a ray that ends on the ground reversed). */
static void transmittance_along(const struct sb_orders_ref *o, double r, double mu, bool ground, double t,
                                double out[3])
{
    double rt = sqrt(fmax(r * r + t * t + 2.0 * r * mu * t, 0.0)), mut = clamp1((r * mu + t) / fmax(rt, 1e-9));
    double a[3], b[3];
    if (ground) {
        depth_to_top(o, rt, -mut, a);
        depth_to_top(o, r, -mu, b);
    } else {
        depth_to_top(o, r, mu, a);
        depth_to_top(o, rt, mut, b);
    }
    for (int c = 0; c < 3; c++)
        out[c] = exp(-fmax(a[c] - b[c], 0.0));
}

/* The sun's transmittance at radius r with sun cosine mu_s: 0 where the
 * planet hides it. */
static void sunlight(const struct sb_orders_ref *o, double r, double mu_s, double out[3])
{
    if (hits_ground(o, r, mu_s)) {
        out[0] = out[1] = out[2] = 0.0;
        return;
    }
    double d[3];
    depth_to_top(o, r, mu_s, d);
    for (int c = 0; c < 3; c++)
        out[c] = o->p.solar_irradiance[c] * exp(-d[c]);
}

/* ---- Rays --------------------------------------------------------------------- */

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The pieces of the ray from (r, mu) to t_end: cut where it crosses an
 * altitude level and at its lowest point. */
static int ray_cuts(const struct sb_orders_ref *o, double r, double mu, double t_end, double cuts[MAX_PIECES + 1])
{
    int n = 0;
    cuts[n++] = 0.0;
    for (int i = 0; i < o->level_count; i++) {
        double rl = o->R + o->levels[i], b = r * mu, disc = b * b - (r * r - rl * rl);
        if (disc < 0)
            continue;
        double s = sqrt(disc), roots[2] = {-b - s, -b + s};
        for (int k = 0; k < 2; k++)
            if (roots[k] > 0 && roots[k] < t_end && n < MAX_PIECES - 1)
                cuts[n++] = roots[k];
    }
    if (-r * mu > 0 && -r * mu < t_end && n < MAX_PIECES)
        cuts[n++] = -r * mu;
    cuts[n++] = t_end;
    qsort(cuts, (size_t)n, sizeof(double), compare_doubles);
    return n;
}

/* ---- The grid ------------------------------------------------------------------- */

static size_t node_index(const struct sb_orders_ref *o, int ir, int imu, int imus, int inu)
{
    return (((size_t)ir * o->nmu + imu) * o->nmus + imus) * o->nnu + inu;
}

static size_t node_count(const struct sb_orders_ref *o)
{
    return (size_t)o->nr * o->nmu * o->nmus * o->nnu;
}

static double radius_of(const struct sb_orders_ref *o, int ir)
{
    return o->R + progression_at(&o->heights, ir);
}

/* mu at node imu of radius r: the first half ends on the ground. */
static double mu_of(const struct sb_orders_ref *o, double r, int imu)
{
    int half = o->nmu / 2;
    double rho = sqrt(fmax(r * r - o->R * o->R, 0.0));
    if (imu < half) {
        double x = (double)imu / (half - 1), d_min = r - o->R, d_max = rho, d = d_min + x * (d_max - d_min);
        return d <= 0.0 ? -1.0 : clamp1(-(rho * rho + d * d) / (2.0 * r * d));
    }
    double x = (double)(imu - half) / (half - 1), d_min = o->grid_top - r, d_max = rho + o->H;
    double d = d_min + x * (d_max - d_min);
    return d <= 0.0 ? 1.0 : clamp1((o->H * o->H - rho * rho - d * d) / (2.0 * r * d));
}

/* The continuous mu index of (r, mu) in the half `ground` says. */
static double mu_coord(const struct sb_orders_ref *o, double r, double mu, bool ground)
{
    int half = o->nmu / 2;
    double rho = sqrt(fmax(r * r - o->R * o->R, 0.0));
    if (ground) {
        double d_min = r - o->R, d_max = rho, d = dist_ground(o, r, mu);
        double x = d_max > d_min ? (d - d_min) / (d_max - d_min) : 0.0;
        return fmin(fmax(x, 0.0), 1.0) * (half - 1);
    }
    double d_min = fmax(o->grid_top - r, 0.0), d_max = rho + o->H, d = dist_to(r, mu, o->grid_top);
    double x = d_max > d_min ? (d - d_min) / (d_max - d_min) : 0.0;
    return half + fmin(fmax(x, 0.0), 1.0) * (half - 1);
}

/* mu_s at node imus: half the nodes from mu_s_min to 0.1 (twilight and a
 * low sun, where the sky changes fastest), the rest on to 1. */
#define MU_S_SPLIT SB_ORDERS_MU_S_SPLIT
static double mu_s_of(const struct sb_orders_ref *o, int imus)
{
    int low = o->nmus / 2;
    if (imus <= low)
        return o->mu_s_min + (MU_S_SPLIT - o->mu_s_min) * imus / low;
    return MU_S_SPLIT + (1.0 - MU_S_SPLIT) * (imus - low) / (o->nmus - 1 - low);
}

/* The continuous node index of mu_s. */
static double mu_s_coord(const struct sb_orders_ref *o, double mu_s)
{
    int low = o->nmus / 2;
    mu_s = fmin(fmax(mu_s, o->mu_s_min), 1.0);
    if (mu_s <= MU_S_SPLIT)
        return (mu_s - o->mu_s_min) / (MU_S_SPLIT - o->mu_s_min) * low;
    return low + (mu_s - MU_S_SPLIT) / (1.0 - MU_S_SPLIT) * (o->nmus - 1 - low);
}

/* nu from the sun's azimuth phi about the vertical, from the view's. */
static double nu_of(double mu, double mu_s, double phi)
{
    return clamp1(mu * mu_s + sqrt(fmax((1 - mu * mu) * (1 - mu_s * mu_s), 0.0)) * cos(phi));
}

static double phi_of(double mu, double mu_s, double nu)
{
    double s = sqrt(fmax((1 - mu * mu) * (1 - mu_s * mu_s), 0.0));
    return s > 1e-12 ? acos(clamp1((nu - mu * mu_s) / s)) : 0.0;
}

/* The sun's azimuth at nu node inu, and the continuous node index of phi. */
static double node_phi(const struct sb_orders_ref *o, int inu)
{
    return o->nu_power == 1.0 ? ORD_PI * inu / (o->nnu - 1) : ORD_PI * pow((double)inu / (o->nnu - 1), o->nu_power);
}

static double phi_coord(const struct sb_orders_ref *o, double phi)
{
    double x = fmin(fmax(phi / ORD_PI, 0.0), 1.0);
    return (o->nnu - 1) * (o->nu_power == 1.0 ? x : pow(x, 1.0 / o->nu_power));
}

/* Between two nodes in mu_s or nu: linear by day; geometric at twilight
 * (both mu_s nodes below the horizon) where both are positive: twilight
 * falls exponentially with the sun's depth and, through the limb, with its
 * azimuth, and a line between nodes would lift it. */
static double blend_twilight(double a, double b, double f, bool twilight)
{
    if (f == 0.0)
        return a;
    return twilight && a > 0.0 && b > 0.0 ? a * pow(b / a, f) : a + f * (b - a);
}

/* The weights of the sun's azimuth phi at the n azimuth nodes (phi_j = pi j
 * / (n - 1)) in the trigonometric interpolation of an even function
 * through them: the cardinal functions of the 2 (n - 1) points about the
 * circle, each node counting for its mirror image too. */
static void azimuth_weights(int n, double phi, double w[])
{
    int M = 2 * (n - 1);
    for (int j = 0; j < n; j++) {
        double pj = ORD_PI * j / (n - 1), d = 1.0 + cos(0.5 * M * phi) * cos(0.5 * M * pj);
        for (int m = 1; m < M / 2; m++)
            d += 2.0 * cos(m * phi) * cos(m * pj);
        w[j] = (j == 0 || j == n - 1 ? 1.0 : 2.0) * d / M;
    }
}

/* A table (rgb per node, fp64 or, with table NULL, fp32) read at (r, mu,
 * mu_s, nu): linear in r and mu, in mu_s and then nu by blend_twilight.
 * A view's read (`view`) where the grid says so (log_azimuth), by day:
 * multilinear in r, mu and mu_s at every azimuth node, then across the
 * azimuth log-trigonometrically through them all (exact for exp(a + b cos
 * phi + c cos 2 phi + ...)), kept between the two nodes about phi; where a
 * node is not positive, linearly. */
static void lookup_any(const struct sb_orders_ref *o, const double *table, const float *ftable, double r, double mu,
                       double mu_s, double nu, bool ground, bool view, double out[3])
{
    if (o->grid_top < o->top) /* above the grid (a density along a ray): its top's */
        r = fmin(r, o->grid_top);
    double fr = progression_index(&o->heights, r - o->R);
    int ir = fr < o->nr - 2 ? (int)fr : o->nr - 2;
    double ar = fr - ir;
    double fmus = mu_s_coord(o, mu_s);
    int ims = fmus < o->nmus - 2 ? (int)fmus : o->nmus - 2;
    double as = fmus - ims;
    bool twilight = mu_s_of(o, ims + 1) <= 0.0;
    double phi = phi_of(mu, mu_s, nu), fnu = phi_coord(o, phi);
    int inu = fnu < o->nnu - 2 ? (int)fnu : o->nnu - 2;
    double an = fnu - inu;
    bool log_read = view && o->log_azimuth && !twilight;
    int first = log_read ? 0 : inu, last = log_read ? o->nnu - 1 : inu + 1;
    int half = o->nmu / 2, lo = ground ? 0 : half;
    /* the ray's length fraction, read at both radii (Bruneton's texture coordinate) */
    double fmu = mu_coord(o, r, mu, ground);
    int im = (int)fmu < lo + half - 2 ? (int)fmu : lo + half - 2;
    double am = fmu - im, u[SB_ORDERS_MAX_NODES][3];
    if (log_read)
        memset(u, 0, 3 * sizeof(double) * (size_t)o->nnu);
    out[0] = out[1] = out[2] = 0.0;
    for (int dr = 0; dr < 2; dr++) {
        double wr = dr ? ar : 1 - ar;
        for (int dm = 0; dm < 2; dm++) {
            double w = wr * (dm ? am : 1 - am), v[2][3];
            if (w == 0.0)
                continue;
            for (int j = first; j <= last; j++) {
                size_t i0 = 3 * node_index(o, ir + dr, im + dm, ims, j);
                size_t i1 = 3 * node_index(o, ir + dr, im + dm, ims + 1, j);
                for (int c = 0; c < 3; c++) {
                    double v0 = table ? table[i0 + c] : ftable[i0 + c], v1 = table ? table[i1 + c] : ftable[i1 + c];
                    double x = blend_twilight(v0, v1, as, twilight);
                    if (log_read)
                        u[j][c] += w * x;
                    if (j == inu || j == inu + 1)
                        v[j - inu][c] = x;
                }
            }
            for (int c = 0; c < 3; c++)
                out[c] += w * blend_twilight(v[0][c], v[1][c], an, twilight);
        }
    }
    if (!log_read)
        return;
    double wt[SB_ORDERS_MAX_NODES];
    azimuth_weights(o->nnu, phi, wt);
    for (int c = 0; c < 3; c++) {
        double lg = 0.0;
        bool positive = true;
        for (int j = 0; j < o->nnu && positive; j++) {
            positive = u[j][c] > 0.0;
            lg += positive ? wt[j] * log(u[j][c]) : 0.0;
        }
        if (positive)
            out[c] = fmin(fmax(exp(lg), fmin(u[inu][c], u[inu + 1][c])), fmax(u[inu][c], u[inu + 1][c]));
    }
}

static void lookup(const struct sb_orders_ref *o, const double *table, double r, double mu, double mu_s, double nu,
                   bool ground, double out[3])
{
    lookup_any(o, table, NULL, r, mu, mu_s, nu, ground, false, out);
}

/* ---- Single scattering -------------------------------------------------------- */

/* Single scattering along the view from (r, mu) without its phase functions,
 * Rayleigh's and Mie's. */
static void single_along(const struct sb_orders_ref *o, double r, double mu, bool ground, double mu_s, double nu,
                         double ray[3], double mie[3])
{
    double t_end = ground ? dist_ground(o, r, mu) : dist_top(o, r, mu), cuts[MAX_PIECES + 1];
    int n = ray_cuts(o, r, mu, t_end, cuts);
    for (int c = 0; c < 3; c++)
        ray[c] = mie[c] = 0.0;
    for (int i = 0; i + 1 < n; i++) {
        double a = cuts[i], b = cuts[i + 1];
        for (int k = 0; k < GL_RAY && b > a; k++) {
            double t = 0.5 * (a + b) + 0.5 * (b - a) * o->gl_ray_x[k], w = 0.5 * (b - a) * o->gl_ray_w[k];
            double rt = sqrt(fmax(r * r + t * t + 2 * r * mu * t, 0.0)), mu_s_t = clamp1((r * mu_s + t * nu) / rt);
            double tv[3], ts[3];
            struct sb_ref_medium m;
            transmittance_along(o, r, mu, ground, t, tv);
            sunlight(o, rt, mu_s_t, ts);
            sb_ref_medium(&o->p, fmax(rt - o->R, 0.0), &m);
            for (int c = 0; c < 3; c++) {
                ray[c] += w * tv[c] * ts[c] * m.rayleigh[c];
                mie[c] += w * tv[c] * ts[c] * m.mie[c];
            }
        }
    }
}

static void node_view(const struct sb_orders_ref *o, size_t index, double *r, double *mu, double *mu_s, double *nu)
{
    int inu = (int)(index % (size_t)o->nnu), ims = (int)(index / o->nnu % (size_t)o->nmus);
    int imu = (int)(index / ((size_t)o->nnu * o->nmus) % (size_t)o->nmu);
    int ir = (int)(index / ((size_t)o->nnu * o->nmus * o->nmu));
    *r = radius_of(o, ir);
    *mu = mu_of(o, *r, imu);
    *mu_s = mu_s_of(o, ims);
    *nu = nu_of(*mu, *mu_s, node_phi(o, inu));
}

static bool node_ground(const struct sb_orders_ref *o, size_t index)
{
    return (int)(index / ((size_t)o->nnu * o->nmus) % (size_t)o->nmu) < o->nmu / 2;
}

/* Nodes are processed in rows of nnu * nmus. */
static void single_row(void *user, int row)
{
    struct sb_orders_ref *o = user;
    size_t per = (size_t)o->nnu * o->nmus;
    for (size_t i = (size_t)row * per; i < (size_t)(row + 1) * per; i++) {
        double r, mu, mu_s, nu;
        node_view(o, i, &r, &mu, &mu_s, &nu);
        if (node_ground(o, i) && r <= o->R)
            continue; /* on the ground, looking into it: no air */
        single_along(o, r, mu, node_ground(o, i), mu_s, nu, &o->single_r[3 * i], &o->single_m[3 * i]);
    }
}

/* ---- Orders ------------------------------------------------------------------- */

/* The ground's irradiance at sun cosine mu_s from order k - 1 (the direct sun
 * for k - 1 = 0): what a ground bounce of order k reflects. */
static void ground_irradiance(const struct sb_orders_ref *o, const double *table, double mu_s, double out[3])
{
    if (!table) {
        double t[3];
        sunlight(o, o->R, mu_s, t);
        for (int c = 0; c < 3; c++)
            out[c] = t[c] * fmax(mu_s, 0.0);
        return;
    }
    double f = mu_s_coord(o, mu_s);
    int i = f < o->nmus - 2 ? (int)f : o->nmus - 2;
    double a = f - i;
    for (int c = 0; c < 3; c++)
        out[c] = blend_twilight(table[3 * i + c], table[3 * (i + 1) + c], a, mu_s_of(o, i + 1) <= 0.0);
}

/* Order k - 1's radiance reaching (r, mu') with (mu_s, nu'): from the air
 * (the single scattering tables with their phase for k - 1 = 1, else the
 * previous order's table) and, for a direction that ends on the ground,
 * the ground lit by order k - 2. */
static void previous_radiance(const struct sb_orders_ref *o, int k, double r, double mu, double mu_s, double nu,
                              const double *ground_previous, double out[3])
{
    bool ground = hits_ground(o, r, mu);
    if (k == 2) {
        double a[3], b[3];
        lookup(o, o->single_r, r, mu, mu_s, nu, ground, a);
        lookup(o, o->single_m, r, mu, mu_s, nu, ground, b);
        double pr = sb_ref_phase_rayleigh(nu), pm = sb_ref_phase_mie(o->p.mie_g, nu);
        for (int c = 0; c < 3; c++)
            out[c] = pr * a[c] + pm * b[c];
    } else {
        lookup(o, o->previous, r, mu, mu_s, nu, ground, out);
    }
    if (ground) {
        double d = dist_ground(o, r, mu), mu_s_g = clamp1((r * mu_s + d * nu) / o->R), e[3], t[3];
        ground_irradiance(o, ground_previous, mu_s_g, e);
        transmittance_along(o, r, mu, true, d, t);
        for (int c = 0; c < 3; c++)
            out[c] += t[c] * o->p.ground_albedo[c] / ORD_PI * e[c];
    }
}

struct order_job {
    struct sb_orders_ref *o;
    int k;
    const double *ground_previous; /* order k - 2's ground irradiance; NULL: the direct sun */
};

/* The scattering density J = s_r J_r + s_m J_m (J_r, J_m: the in-radiance
 * weighed by each phase function) is kept divided by the scattering
 * s_r + s_m, and multiplied by it again where it is read: J falls with the
 * air's density, some 8 km a factor e, which the altitude nodes could not
 * follow linearly (views through the limb from above read 5 to 10% high),
 * while J / s changes only with the light. Where the air does not scatter,
 * the two parts count alike. */
static double density_per_scattering(double s_r, double s_m, double j_r, double j_m)
{
    double s = s_r + s_m;
    return s > 0 ? (s_r * j_r + s_m * j_m) / s : 0.5 * (j_r + j_m);
}

static void density_row(void *user, int row)
{
    struct order_job *job = user;
    struct sb_orders_ref *o = job->o;
    size_t per = (size_t)o->nnu * o->nmus;
    for (size_t i = (size_t)row * per; i < (size_t)(row + 1) * per; i++) {
        double r, mu, mu_s, nu;
        node_view(o, i, &r, &mu, &mu_s, &nu);
        double sv = sqrt(fmax(1 - mu * mu, 0.0)), ss = sqrt(fmax(1 - mu_s * mu_s, 0.0));
        double phi_s = node_phi(o, (int)(i % (size_t)o->nnu));
        double view[3] = {sv, 0.0, mu}, sun[3] = {ss * cos(phi_s), ss * sin(phi_s), mu_s};
        struct sb_ref_medium m;
        sb_ref_medium(&o->p, fmax(r - o->R, 0.0), &m);
        double horizon = -sqrt(fmax(r * r - o->R * o->R, 0.0)) / r, jr[3] = {0, 0, 0}, jm[3] = {0, 0, 0};
        for (int side = 0; side < 2; side++) {
            int n = side ? SPHERE_SKY : SPHERE_GROUND;
            const double *gx = side ? o->gl_sky_x : o->gl_ground_x, *gw = side ? o->gl_sky_w : o->gl_ground_w;
            double a = side ? horizon : -1.0, b = side ? 1.0 : horizon;
            for (int q = 0; q < n && b > a; q++) {
                double mu_in = 0.5 * (a + b) + 0.5 * (b - a) * gx[q], w_mu = 0.5 * (b - a) * gw[q];
                double s_in = sqrt(fmax(1 - mu_in * mu_in, 0.0));
                for (int f = 0; f < SPHERE_PHI; f++) {
                    double psi = 2 * ORD_PI * (f + 0.5) / SPHERE_PHI;
                    double in[3] = {s_in * cos(psi), s_in * sin(psi), mu_in};
                    double nu_in = clamp1(in[0] * sun[0] + in[1] * sun[1] + in[2] * sun[2]);
                    double cos_scatter = clamp1(in[0] * view[0] + in[1] * view[1] + in[2] * view[2]), l[3];
                    previous_radiance(o, job->k, r, mu_in, mu_s, nu_in, job->ground_previous, l);
                    double w = w_mu * 2 * ORD_PI / SPHERE_PHI * sb_ref_phase_rayleigh(cos_scatter);
                    for (int c = 0; c < 3; c++)
                        jr[c] += w * l[c];
                }
            }
        }
        /* Mie's part about the view, at quantiles of Henyey-Greenstein's
         * scattering angle (however narrow its peak), weighted by
         * Cornette-Shanks over it */
        double g = o->p.mie_g, t1[3] = {mu, 0.0, -sv}, t2[3] = {0.0, 1.0, 0.0};
        for (int q = 0; q < MIE_U; q++) {
            double u = 0.5 + 0.5 * o->gl_mie_x[q], w_u = 0.5 * o->gl_mie_w[q], c_s, ratio;
            if (fabs(g) < 1e-3) {
                c_s = 2 * u - 1;
                ratio = 4 * ORD_PI * sb_ref_phase_mie(g, c_s);
            } else {
                double k = (1 - g * g) / (1 - g + 2 * g * u);
                c_s = clamp1((1 + g * g - k * k) / (2 * g));
                double d = 1 + g * g - 2 * g * c_s;
                ratio = sb_ref_phase_mie(g, c_s) / ((1 - g * g) / (4 * ORD_PI * d * sqrt(d)));
            }
            double s_s = sqrt(fmax(1 - c_s * c_s, 0.0));
            for (int f = 0; f < MIE_PHI; f++) {
                double psi = 2 * ORD_PI * (f + 0.5) / MIE_PHI, in[3], l[3];
                for (int a = 0; a < 3; a++)
                    in[a] = c_s * view[a] + s_s * (cos(psi) * t1[a] + sin(psi) * t2[a]);
                double mu_in = clamp1(in[2]), nu_in = clamp1(in[0] * sun[0] + in[1] * sun[1] + in[2] * sun[2]);
                previous_radiance(o, job->k, r, mu_in, mu_s, nu_in, job->ground_previous, l);
                double w = w_u / MIE_PHI * ratio;
                for (int c = 0; c < 3; c++)
                    jm[c] += w * l[c];
            }
        }
        /* kept per unit of scattering (density_per_scattering) */
        for (int c = 0; c < 3; c++)
            o->density[3 * i + c] = density_per_scattering(m.rayleigh[c], m.mie[c], jr[c], jm[c]);
    }
}

static void order_row(void *user, int row)
{
    struct order_job *job = user;
    struct sb_orders_ref *o = job->o;
    size_t per = (size_t)o->nnu * o->nmus;
    for (size_t i = (size_t)row * per; i < (size_t)(row + 1) * per; i++) {
        double r, mu, mu_s, nu;
        node_view(o, i, &r, &mu, &mu_s, &nu);
        bool ground = node_ground(o, i);
        if (ground && r <= o->R) {
            memset(&o->order[3 * i], 0, 3 * sizeof(double));
            continue;
        }
        double t_end = ground ? dist_ground(o, r, mu) : dist_top(o, r, mu), cuts[MAX_PIECES + 1], s[3] = {0, 0, 0};
        int n = ray_cuts(o, r, mu, t_end, cuts);
        for (int p = 0; p + 1 < n; p++) {
            double a = cuts[p], b = cuts[p + 1];
            for (int k = 0; k < GL_RAY && b > a; k++) {
                double t = 0.5 * (a + b) + 0.5 * (b - a) * o->gl_ray_x[k], w = 0.5 * (b - a) * o->gl_ray_w[k];
                double rt = sqrt(fmax(r * r + t * t + 2 * r * mu * t, 0.0));
                double mu_t = clamp1((r * mu + t) / rt), mu_s_t = clamp1((r * mu_s + t * nu) / rt), tv[3], jt[3];
                transmittance_along(o, r, mu, ground, t, tv);
                lookup(o, o->density, rt, mu_t, mu_s_t, nu, ground, jt);
                struct sb_ref_medium m;
                sb_ref_medium(&o->p, fmax(rt - o->R, 0.0), &m);
                for (int c = 0; c < 3; c++)
                    s[c] += w * tv[c] * (m.rayleigh[c] + m.mie[c]) * jt[c];
            }
        }
        memcpy(&o->order[3 * i], s, sizeof(s));
    }
}

/* The ground's irradiance from order k's sky (k = 1: single scattering). */
static void ground_row(void *user, int ims)
{
    struct order_job *job = user;
    struct sb_orders_ref *o = job->o;
    double mu_s = mu_s_of(o, ims), e[3] = {0, 0, 0}, r = o->R;
    for (int q = 0; q < HEMI_MU; q++) {
        double mu = 0.5 + 0.5 * o->gl_hemi_x[q], w_mu = 0.5 * o->gl_hemi_w[q], s = sqrt(fmax(1 - mu * mu, 0.0));
        for (int f = 0; f < HEMI_PHI; f++) {
            double psi = 2 * ORD_PI * (f + 0.5) / HEMI_PHI, l[3];
            double nu = clamp1(s * cos(psi) * sqrt(fmax(1 - mu_s * mu_s, 0.0)) + mu * mu_s);
            if (job->k == 1) {
                double a[3], b[3];
                lookup(o, o->single_r, r, mu, mu_s, nu, false, a);
                lookup(o, o->single_m, r, mu, mu_s, nu, false, b);
                for (int c = 0; c < 3; c++)
                    l[c] = sb_ref_phase_rayleigh(nu) * a[c] + sb_ref_phase_mie(o->p.mie_g, nu) * b[c];
            } else {
                lookup(o, o->order, r, mu, mu_s, nu, false, l);
            }
            for (int c = 0; c < 3; c++)
                e[c] += w_mu * 2 * ORD_PI / HEMI_PHI * mu * l[c];
        }
    }
    memcpy(&o->ground_order[3 * ims], e, sizeof(e));
}

struct sb_orders_settings sb_orders_settings_resolve(const struct sb_orders_settings *s)
{
    struct sb_orders_settings out = {
        .r = s && s->r > 1 ? s->r : 16,
        .mu = s && s->mu > 3 ? (s->mu + 1) / 2 * 2 : 64,
        .mu_s = s && s->mu_s > 1 ? s->mu_s : 24,
        .nu = s && s->nu > 1 ? s->nu : 8,
        .max_order = s && s->max_order > 1 ? s->max_order : 16,
        .tolerance = s && s->tolerance > 0 ? s->tolerance : 1e-3,
    };
    return out;
}

static struct progression heights_of(const struct sb_atmosphere_params *p, int nr)
{
    return (struct progression){sb_orders_top_km(p) - p->ground_radius_km, sb_orders_height_ratio(p, nr), nr - 1};
}

/* The grid and the quadratures, no table. */
static void grid_init(struct sb_orders_ref *o, const struct sb_atmosphere_params *p,
                      const struct sb_orders_settings *set)
{
    o->p = *p;
    o->nr = set->r;
    o->nmu = set->mu;
    o->nmus = set->mu_s;
    o->nnu = set->nu;
    o->R = p->ground_radius_km;
    o->top = p->top_radius_km;
    o->grid_top = sb_orders_top_km(p);
    o->H = sqrt(o->grid_top * o->grid_top - o->R * o->R);
    o->heights = heights_of(p, o->nr);
    o->mu_s_min = -o->H / o->grid_top;
    o->log_azimuth = sb_orders_log_azimuth(p);
    o->nu_power = (float)sb_orders_azimuth_power(p); /* as the GPU's grid holds it */
    o->level_count = sb_atmosphere_levels(p, o->levels);
    sb_ref_gauss_legendre(GL_RAY, -1, 1, o->gl_ray_x, o->gl_ray_w);
    sb_ref_gauss_legendre(SPHERE_GROUND, -1, 1, o->gl_ground_x, o->gl_ground_w);
    sb_ref_gauss_legendre(SPHERE_SKY, -1, 1, o->gl_sky_x, o->gl_sky_w);
    sb_ref_gauss_legendre(HEMI_MU, -1, 1, o->gl_hemi_x, o->gl_hemi_w);
    sb_ref_gauss_legendre(MIE_U, -1, 1, o->gl_mie_x, o->gl_mie_w);
}

struct sb_orders_ref *sb_orders_grid_create(const struct sb_atmosphere_params *p, const struct sb_orders_settings *s)
{
    struct sb_orders_ref *o = calloc(1, sizeof(*o));
    if (!o)
        return NULL;
    struct sb_orders_settings set = sb_orders_settings_resolve(s);
    grid_init(o, p, &set);
    return o;
}

/* The grid of `p` with its tables allocated and single scattering at its
 * nodes, computed in `medium` (p itself, or its delta-M scaling). */
static struct sb_orders_ref *ref_single(const struct sb_atmosphere_params *p, const struct sb_atmosphere_params *medium,
                                        const struct sb_orders_settings *s)
{
    struct sb_orders_ref *o = sb_orders_grid_create(p, s);
    if (!o)
        return NULL;
    o->p = *medium;
    size_t n = node_count(o);
    o->depth = malloc((size_t)DEPTH_W * DEPTH_H * 3 * sizeof(double));
    double *block = calloc(6 * 3 * n + 2 * 3 * (size_t)o->nmus, sizeof(double));
    if (!o->depth || !block) {
        free(block);
        sb_orders_ref_destroy(&o);
        return NULL;
    }
    o->single_r = block;
    o->single_m = block + 3 * n;
    o->density = block + 6 * n;
    o->order = block + 9 * n;
    o->previous = block + 12 * n;
    o->sum = block + 15 * n;
    o->ground = block + 18 * n;
    o->ground_order = o->ground + 3 * o->nmus;

    sb_status("multiple scattering by orders: single scattering");
    sb_parallel_for(DEPTH_H, depth_row, o);
    sb_parallel_for(o->nr * o->nmu, single_row, o);
    return o;
}

/* Orders 2 and up from the single scattering at the nodes; false on failure (memory). */
static bool ref_orders(struct sb_orders_ref *o, int max_order, double tolerance)
{
    size_t n = node_count(o);
    int rows = o->nr * o->nmu;
    /* the ground's irradiance from single scattering: order 1 */
    struct order_job job = {o, 1, NULL};
    sb_parallel_for(o->nmus, ground_row, &job);
    /* the ground's irradiance of orders k - 1 and k - 2 (E_0, the direct sun, is NULL) */
    double *e1 = calloc(6 * (size_t)o->nmus, sizeof(double)), *e2 = e1 ? e1 + 3 * o->nmus : NULL;
    if (!e1)
        return false;
    size_t ground_bytes = 3 * (size_t)o->nmus * sizeof(double);
    memcpy(e1, o->ground_order, ground_bytes);
    for (int k = 2; k <= max_order; k++) {
        sb_status("multiple scattering by orders: order %d", k);
        /* the ground seen at a view's end is lit by orders up to k - 1 (its
         * reflection is order k) */
        for (int i = 0; i < 3 * o->nmus; i++)
            o->ground[i] += e1[i];
        /* order k's density reads order k - 1 in the air and the ground lit by order k - 2 */
        job = (struct order_job){o, k, k == 2 ? NULL : e2};
        sb_parallel_for(rows, density_row, &job);
        sb_parallel_for(rows, order_row, &job);
        sb_parallel_for(o->nmus, ground_row, &job);
        memcpy(e2, e1, ground_bytes);
        memcpy(e1, o->ground_order, ground_bytes);
        double largest = 0.0, total = 0.0, last[3] = {0, 0, 0}, before[3] = {0, 0, 0};
        for (size_t i = 0; i < 3 * n; i++) {
            o->sum[i] += o->order[i];
            largest = fmax(largest, o->order[i]);
            total = fmax(total, o->sum[i]);
            last[i % 3] += o->order[i];
            before[i % 3] += o->previous[i];
        }
        memcpy(o->previous, o->order, 3 * n * sizeof(double));
        o->orders = k;
        o->last_share = total > 0 ? largest / total : 0.0;
        if (o->last_share < tolerance || k == max_order) {
            /* the orders after k, as the product adds them (orders.h) */
            for (int c = 0; c < 3; c++)
                o->tail[c] = sb_orders_tail_factor(last[c], before[c]);
            for (size_t i = 0; i < 3 * n; i++)
                o->sum[i] += o->tail[i % 3] * o->order[i];
            for (int i = 0; i < 3 * o->nmus; i++)
                o->ground[i] += o->tail[i % 3] * e2[i];
            break;
        }
    }
    free(e1);
    return true;
}

/*
 * A peaked Mie's orders computed in its delta-M medium `m` (f of Mie's
 * scattering carried forward as unscattered light) become the
 * atmosphere's `o`: its table is m's orders, plus the light the peak
 * carries forward that the air then scatters once (m's single scattering,
 * its transmittance and smooth phase, less the same smooth scattering in
 * o's transmittance: o's sky draws single scattering with Mie's whole
 * phase), its ground row m's plus the sun the peak carries to the ground.
 */
static void ref_take_delta_m(struct sb_orders_ref *o, const struct sb_orders_ref *m, double f)
{
    size_t n = node_count(o);
    for (size_t i = 0; i < n; i++) {
        double r, mu, mu_s, nu;
        node_view(o, i, &r, &mu, &mu_s, &nu);
        double pr = sb_ref_phase_rayleigh(nu), pm = sb_ref_phase_mie(m->p.mie_g, nu);
        for (int c = 0; c < 3; c++) {
            size_t k = 3 * i + c;
            double forward = pr * (m->single_r[k] - o->single_r[k]) + pm * (m->single_m[k] - (1 - f) * o->single_m[k]);
            o->sum[k] = m->sum[k] + fmax(forward, 0.0);
        }
    }
    for (int i = 0; i < o->nmus; i++) {
        double mu_s = mu_s_of(o, i), t_m[3], t_o[3];
        sunlight(m, o->R, mu_s, t_m);
        sunlight(o, o->R, mu_s, t_o);
        for (int c = 0; c < 3; c++)
            o->ground[3 * i + c] = m->ground[3 * i + c] + fmax(t_m[c] - t_o[c], 0.0) * fmax(mu_s, 0.0);
    }
    o->orders = m->orders;
    o->last_share = m->last_share;
    memcpy(o->tail, m->tail, sizeof(o->tail));
}

struct sb_orders_ref *sb_orders_ref_create(const struct sb_atmosphere_params *p, const struct sb_orders_settings *s)
{
    struct sb_orders_settings set = sb_orders_settings_resolve(s);
    struct sb_atmosphere_params medium;
    double f = sb_orders_medium(p, &medium);
    struct sb_orders_ref *o = ref_single(p, p, s), *m = NULL;
    if (o && f > 0 && !(m = ref_single(p, &medium, s)))
        sb_orders_ref_destroy(&o);
    if (o && !ref_orders(m ? m : o, set.max_order, set.tolerance))
        sb_orders_ref_destroy(&o);
    if (o && m)
        ref_take_delta_m(o, m, f);
    sb_orders_ref_destroy(&m);
    sb_status(NULL);
    return o;
}

void sb_orders_ref_destroy(struct sb_orders_ref **ref)
{
    if (!*ref)
        return;
    free((*ref)->depth);
    free((*ref)->single_r);
    free(*ref);
    *ref = NULL;
}

double sb_orders_tail_factor(double last, double before)
{
    double rho = before > 0.0 && last > 0.0 ? last / before : 0.0;
    rho = fmin(rho, SB_ORDERS_TAIL_MAX_RATIO);
    return rho / (1.0 - rho);
}

int sb_orders_ref_orders(const struct sb_orders_ref *ref)
{
    return ref->orders;
}

double sb_orders_ref_last_share(const struct sb_orders_ref *ref)
{
    return ref->last_share;
}

void sb_orders_grid_node(const struct sb_orders_ref *o, size_t index, double *h, double *mu, double *mu_s, double *nu)
{
    double r;
    node_view(o, index, &r, mu, mu_s, nu);
    *h = r - o->R;
}

double sb_orders_grid_mu_s(const struct sb_orders_ref *o, int imus)
{
    return mu_s_of(o, imus);
}

void sb_orders_ref_node(const struct sb_orders_ref *o, int ir, int imu, int imus, int inu, double out[3])
{
    memcpy(out, &o->sum[3 * node_index(o, ir, imu, imus, inu)], 3 * sizeof(double));
}

/* A view from above the grid's top as the one from where it enters it;
 * false where it misses. */
static bool enter_atmosphere(const struct sb_orders_ref *o, double *r, double *mu, double *mu_s, double nu)
{
    double top = o->grid_top;
    if (*r <= top)
        return true;
    double b = *r * *mu, disc = b * b - (*r - top) * (*r + top);
    if (*mu >= 0.0 || disc < 0.0)
        return false;
    double t = (*r - top) * (*r + top) / (-b + sqrt(disc));
    *mu = clamp1((*r * *mu + t) / top);
    *mu_s = clamp1((*r * *mu_s + t * nu) / top);
    *r = top;
    return true;
}

void sb_orders_table_read(const struct sb_orders_ref *o, const float *table, double h, double mu, double mu_s,
                          double nu, double out[3])
{
    double r = o->R + fmax(h, 0.0);
    out[0] = out[1] = out[2] = 0.0;
    if (enter_atmosphere(o, &r, &mu, &mu_s, nu))
        lookup_any(o, NULL, table, r, mu, mu_s, nu, hits_ground(o, r, mu), true, out);
}

void sb_orders_ref_ground(const struct sb_orders_ref *o, int imus, double out[3])
{
    memcpy(out, &o->ground[3 * imus], 3 * sizeof(double));
}

void sb_orders_table_ground(const struct sb_orders_ref *o, const float *table, double mu_s, double out[3])
{
    const float *row = table + 3 * node_count(o); /* the row after the nodes, nu values a mu_s node */
    double f = mu_s_coord(o, mu_s);
    int i = f < o->nmus - 2 ? (int)f : o->nmus - 2;
    for (int c = 0; c < 3; c++)
        out[c] =
            blend_twilight(row[3 * i * o->nnu + c], row[3 * (i + 1) * o->nnu + c], f - i, mu_s_of(o, i + 1) <= 0.0);
}

void sb_orders_ref_sky(const struct sb_orders_ref *o, double h, double mu, double mu_s, double nu, double out[3],
                       double multiple[3])
{
    double r = o->R + fmax(h, 0.0);
    out[0] = out[1] = out[2] = 0.0;
    if (multiple)
        multiple[0] = multiple[1] = multiple[2] = 0.0;
    if (!enter_atmosphere(o, &r, &mu, &mu_s, nu))
        return;
    double ray[3], mie[3], ms[3];
    bool ground = hits_ground(o, r, mu);
    single_along(o, r, mu, ground, mu_s, nu, ray, mie);
    lookup_any(o, o->sum, NULL, r, mu, mu_s, nu, ground, true, ms);
    for (int c = 0; c < 3; c++)
        out[c] = sb_ref_phase_rayleigh(nu) * ray[c] + sb_ref_phase_mie(o->p.mie_g, nu) * mie[c] + ms[c];
    if (multiple)
        memcpy(multiple, ms, sizeof(ms));
    if (ground) {
        double d = dist_ground(o, r, mu), mu_s_g = clamp1((r * mu_s + d * nu) / o->R), direct[3], sky[3], t[3];
        ground_irradiance(o, NULL, mu_s_g, direct);
        ground_irradiance(o, o->ground, mu_s_g, sky);
        transmittance_along(o, r, mu, true, d, t);
        for (int c = 0; c < 3; c++)
            out[c] += t[c] * o->p.ground_albedo[c] / ORD_PI * (direct[c] + sky[c]);
    }
}
