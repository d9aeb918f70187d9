#include "pathtrace.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "atmosphere_ref.h"
#include "splitmix.h"

#define PT_PI 3.14159265358979323846
#define MAX_CUTS 128
#define TABLE_SPLIT 8 /* intervals of the view ray's optical-depth table per piece */
#define ROULETTE 0.2  /* of the first vertex's throughput */
#define BATCHES 16
#define GUIDE_G 0.5 /* Mie's |g| from which sunlight_ahead() draws directions about the sun too */

/* ---- Random numbers: xoshiro256** seeded through splitmix64 ------------------- */

struct rng {
    uint64_t s[4];
};

static uint64_t mix(uint64_t h, uint64_t v)
{
    uint64_t x = h ^ v;
    return sb_splitmix64(&x);
}

static uint64_t double_bits(double d)
{
    uint64_t u;
    memcpy(&u, &d, sizeof(u));
    return u;
}

static void rng_seed(struct rng *g, uint64_t stream)
{
    for (int i = 0; i < 4; i++)
        g->s[i] = sb_splitmix64(&stream);
}

static uint64_t rotl(uint64_t x, int k)
{
    return (x << k) | (x >> (64 - k));
}

/* Uniform in [0, 1), 53 bits. */
static double rng_next(struct rng *g)
{
    uint64_t *s = g->s;
    uint64_t result = rotl(s[1] * 5, 7) * 9, t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return (double)(result >> 11) * 0x1.0p-53;
}

/* ---- Vectors ------------------------------------------------------------------ */

static double dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double length(const double a[3])
{
    return sqrt(dot(a, a));
}

/* The direction at polar cosine `c` and azimuth phi around the unit vector n
 * (the branchless basis of Duff et al. 2017). */
static void around(const double n[3], double c, double phi, double out[3])
{
    double sign = copysign(1.0, n[2]), a = -1.0 / (sign + n[2]), b = n[0] * n[1] * a;
    double t1[3] = {1.0 + sign * n[0] * n[0] * a, sign * b, -sign * n[0]};
    double t2[3] = {b, sign + n[1] * n[1] * a, -n[1]};
    double s = sqrt(fmax(1.0 - c * c, 0.0)), x = s * cos(phi), y = s * sin(phi);
    for (int i = 0; i < 3; i++)
        out[i] = c * n[i] + x * t1[i] + y * t2[i];
    double len = length(out);
    for (int i = 0; i < 3; i++)
        out[i] /= len;
}

/* ---- The medium, one channel -------------------------------------------------- */

struct tracer {
    const struct sb_atmosphere_params *p;
    int channel, max_order;
    bool guided; /* next-event estimation one vertex ahead, from directions about the sun (continue_path) */
    double R, top;
    double sun[3];
    double rayleigh, mie_scattering, mie_extinction, ozone; /* per km at density 1 */
    double levels[64];                                      /* altitudes (km) where rays are cut into pieces */
    int level_count;
};

struct coefficients {
    double rayleigh, mie, extinction; /* per km */
};

static double ozone_density(const struct sb_atmosphere_params *p, double h)
{
    return fmax(0.0, 1.0 - fabs(h - p->ozone_center_km) / p->ozone_half_width_km);
}

static struct coefficients coefficients_at(const struct tracer *tr, double h)
{
    const struct sb_atmosphere_params *p = tr->p;
    double dr = exp(-h / p->rayleigh_scale_height_km), dm = exp(-h / p->mie_scale_height_km);
    return (struct coefficients){
        .rayleigh = tr->rayleigh * dr,
        .mie = tr->mie_scattering * dm,
        .extinction = tr->rayleigh * dr + tr->mie_extinction * dm + tr->ozone * ozone_density(p, h),
    };
}

/* An upper bound of the extinction between altitudes lo <= hi (the
 * exponentials fall with altitude; the tent peaks at its centre). */
static double majorant(const struct tracer *tr, double lo, double hi)
{
    const struct sb_atmosphere_params *p = tr->p;
    double oz =
        p->ozone_center_km >= lo && p->ozone_center_km <= hi ? 1.0 : fmax(ozone_density(p, lo), ozone_density(p, hi));
    double bound = tr->rayleigh * exp(-lo / p->rayleigh_scale_height_km) +
                   tr->mie_extinction * exp(-lo / p->mie_scale_height_km) + tr->ozone * oz;
    return bound * (1.0 + 1e-9); /* the point's altitude may round below lo */
}

static double phase_rayleigh(double nu)
{
    return 3.0 / (16.0 * PT_PI) * (1.0 + nu * nu);
}

static double henyey_greenstein(double g, double nu)
{
    double d = 1.0 + g * g - 2.0 * g * nu;
    return (1.0 - g * g) / (4.0 * PT_PI * d * sqrt(d));
}

/* Cornette-Shanks as the ratio to Henyey-Greenstein that its sampling weighs by. */
static double cornette_shanks_over_hg(double g, double nu)
{
    return 1.5 * (1.0 + nu * nu) / (2.0 + g * g);
}

static double phase_mie(double g, double nu)
{
    return henyey_greenstein(g, nu) * cornette_shanks_over_hg(g, nu);
}

/* The cosine to the axis of a direction drawn from Henyey-Greenstein g at quantile u. */
static double sample_henyey_greenstein(double g, double u)
{
    if (fabs(g) < 1e-6)
        return 2.0 * u - 1.0;
    double s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    return fmax(-1.0, fmin(1.0, (1.0 + g * g - s * s) / (2.0 * g)));
}

/* ---- Rays --------------------------------------------------------------------- */

struct ray {
    double r, mu;          /* the origin's radius and the direction's cosine to the vertical there */
    double t_end;          /* to the ground or the top */
    bool ground;           /* the ray ends on the ground */
    double cuts[MAX_CUTS]; /* 0, where the ray crosses a level or grazes its lowest point, t_end */
    int cut_count;
};

static double radius_at(double r, double mu, double t)
{
    return sqrt(fmax(r * r + t * t + 2.0 * r * mu * t, 0.0));
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void ray_init(const struct tracer *tr, double r, double mu, struct ray *ray)
{
    ray->r = r;
    ray->mu = mu;
    double disc_ground = r * r * (mu * mu - 1.0) + tr->R * tr->R;
    ray->ground = mu < 0.0 && disc_ground >= 0.0;
    if (ray->ground) {
        ray->t_end = fmax(-r * mu - sqrt(disc_ground), 0.0);
    } else {
        double disc = r * r * (mu * mu - 1.0) + tr->top * tr->top;
        ray->t_end = fmax(-r * mu + sqrt(fmax(disc, 0.0)), 0.0);
    }
    int n = 0;
    ray->cuts[n++] = 0.0;
    for (int i = 0; i < tr->level_count; i++) {
        double rl = tr->R + tr->levels[i], b = r * mu, disc = b * b - (r * r - rl * rl);
        if (disc < 0)
            continue;
        double s = sqrt(disc), roots[2] = {-b - s, -b + s};
        for (int k = 0; k < 2; k++)
            if (roots[k] > 0 && roots[k] < ray->t_end && n < MAX_CUTS - 2)
                ray->cuts[n++] = roots[k];
    }
    if (-r * mu > 0 && -r * mu < ray->t_end)
        ray->cuts[n++] = -r * mu; /* the lowest point: altitude is monotone between cuts */
    ray->cuts[n++] = ray->t_end;
    qsort(ray->cuts, (size_t)n, sizeof(double), compare_doubles);
    ray->cut_count = n;
}

static double altitude_at(const struct tracer *tr, const struct ray *ray, double t)
{
    return fmax(radius_at(ray->r, ray->mu, t) - tr->R, 0.0);
}

/*
 * Delta tracking from the ray's origin: the distance of the first real
 * collision, or -1 when the ray reaches its end first. Each piece between
 * cuts has the extinction at its lowest end as majorant.
 */
static double track(const struct tracer *tr, const struct ray *ray, struct rng *g)
{
    for (int i = 0; i + 1 < ray->cut_count; i++) {
        double a = ray->cuts[i], b = ray->cuts[i + 1];
        if (b <= a)
            continue;
        double ha = altitude_at(tr, ray, a), hb = altitude_at(tr, ray, b);
        double bound = majorant(tr, fmin(ha, hb), fmax(ha, hb));
        if (!(bound > 0))
            continue;
        double t = a;
        for (;;) {
            t -= log1p(-rng_next(g)) / bound;
            if (t >= b)
                break;
            if (rng_next(g) * bound < coefficients_at(tr, altitude_at(tr, ray, t)).extinction)
                return t;
        }
    }
    return -1.0;
}

/* ---- Light -------------------------------------------------------------------- */

/* The sun's irradiance reaching radius r with sun cosine mu_s: 0 behind the planet. */
static double sunlight(const struct tracer *tr, double r, double mu_s)
{
    if (mu_s < 0.0 && r * r * (mu_s * mu_s - 1.0) + tr->R * tr->R >= 0.0)
        return 0.0;
    double t[3];
    sb_ref_transmittance(tr->p, fmax(r, tr->R), mu_s, 2, t);
    return tr->p->solar_irradiance[tr->channel] * t[tr->channel];
}

/* The scattering function of a vertex, in the air with coefficients m or
 * on the ground (its cosine: the albedo is in the throughput), and the
 * density scatter() draws directions from there, for the path that came
 * along dir and leaves along next. */
static double scattering_function(const struct tracer *tr, const struct coefficients *m, bool on_ground,
                                  const double up[3], const double dir[3], const double next[3], double *pdf)
{
    if (on_ground)
        return *pdf = fmax(dot(up, next), 0.0) / PT_PI;
    double c = dot(dir, next), scattering = m->rayleigh + m->mie, gm = tr->p->mie_g;
    *pdf = (m->rayleigh * phase_rayleigh(c) + m->mie * henyey_greenstein(gm, c)) / scattering;
    return (m->rayleigh * phase_rayleigh(c) + m->mie * phase_mie(gm, c)) / scattering;
}

/* Henyey-Greenstein about the sun: where Mie's peak lights the air. */
static double about_sun_pdf(const struct tracer *tr, const double d[3])
{
    return henyey_greenstein(tr->p->mie_g, dot(d, tr->sun));
}

/* The direction a path leaves a vertex by: the ground's cosine, or the
 * air's phase functions (Rayleigh's exactly, Cornette-Shanks' from
 * Henyey-Greenstein's), in proportion to their scattering. Returns the
 * scattering function over that density, and the density in *pdf. */
static double scatter(const struct tracer *tr, struct rng *g, const struct coefficients *m, bool on_ground,
                      const double up[3], const double dir[3], double next[3], double *pdf)
{
    double phi = 2.0 * PT_PI * rng_next(g);
    if (on_ground) {
        around(up, sqrt(rng_next(g)), phi, next);
    } else if (rng_next(g) * (m->rayleigh + m->mie) < m->rayleigh) {
        /* Invert the CDF (c^3 + 3c + 4) / 8 of 1 + c^2 (Cardano). */
        double z = 4.0 * rng_next(g) - 2.0, a = cbrt(fabs(z) + sqrt(z * z + 1.0));
        around(dir, copysign(a - 1.0 / a, z), phi, next);
    } else {
        around(dir, sample_henyey_greenstein(tr->p->mie_g, rng_next(g)), phi, next);
    }
    double value = scattering_function(tr, m, on_ground, up, dir, next, pdf);
    return value > 0 ? value / *pdf : 0.0;
}

/*
 * Next-event estimation one vertex ahead. A strong Mie peak (|g| near 1)
 * makes the sunlight at a vertex rare and large: it comes from the few
 * paths whose last direction lies in the peak about the sun. So the
 * direction to the next vertex is drawn two ways: by scatter() (which also
 * carries the path on) and from Henyey-Greenstein about the sun; the
 * sunlight at the next vertex in the air counts from each with the balance
 * heuristic's weight (Veach 1997), the ground's from the first alone.
 * Returns this second draw's share per unit of the path's throughput at the
 * vertex x (m, on_ground, up: as scatter's), reached along dir.
 */
static double sunlight_ahead(const struct tracer *tr, struct rng *g, const double x[3], const struct coefficients *m,
                             bool on_ground, const double up[3], const double dir[3])
{
    const struct sb_atmosphere_params *p = tr->p;
    double d[3], pdf;
    around(tr->sun, sample_henyey_greenstein(p->mie_g, rng_next(g)), 2.0 * PT_PI * rng_next(g), d);
    double value = scattering_function(tr, m, on_ground, up, dir, d, &pdf);
    if (!(value > 0))
        return 0.0;
    double weight = value / (pdf + about_sun_pdf(tr, d));
    struct ray ray;
    ray_init(tr, length(x), dot(up, d), &ray);
    double t = track(tr, &ray, g);
    if (t < 0)
        return 0.0; /* space, or the ground: counted from the first draw */
    double y[3];
    for (int i = 0; i < 3; i++)
        y[i] = x[i] + t * d[i];
    double ry = length(y), nu = dot(d, tr->sun);
    double in = sunlight(tr, ry, dot(y, tr->sun) / ry);
    if (!(in > 0))
        return 0.0;
    struct coefficients at = coefficients_at(tr, fmax(ry - tr->R, 0.0));
    return weight * in * (at.rayleigh * phase_rayleigh(nu) + at.mie * phase_mie(p->mie_g, nu)) / at.extinction;
}

/*
 * Carry on a path whose next vertex is at x (in the medium, or on the ground
 * when `on_ground`), reached along `dir` with `throughput`; returns the
 * radiance it gathers from there on.
 */
static double continue_path(const struct tracer *tr, struct rng *g, double x[3], double dir[3], bool on_ground,
                            double throughput)
{
    const struct sb_atmosphere_params *p = tr->p;
    double radiance = 0.0, roulette = ROULETTE * throughput;
    double nee_weight = 1.0; /* of the sunlight at a vertex in the air, reached by scatter()'s direction */
    for (int order = 1;; order++) {
        double r = length(x), up[3] = {x[0] / r, x[1] / r, x[2] / r}, next[3];
        struct coefficients m = {0};
        if (on_ground) {
            double albedo = p->ground_albedo[tr->channel], mu_s = dot(up, tr->sun);
            if (mu_s > 0)
                radiance += throughput * albedo / PT_PI * mu_s * sunlight(tr, tr->R, mu_s);
            throughput *= albedo;
        } else {
            m = coefficients_at(tr, fmax(r - tr->R, 0.0));
            double scattering = m.rayleigh + m.mie;
            if (!(scattering > 0))
                break;
            throughput *= scattering / m.extinction;
            double nu = dot(dir, tr->sun);
            double in = sunlight(tr, r, dot(up, tr->sun));
            if (in > 0)
                radiance += nee_weight * throughput * in *
                            (m.rayleigh * phase_rayleigh(nu) + m.mie * phase_mie(p->mie_g, nu)) / scattering;
        }
        if ((tr->max_order && order >= tr->max_order) || !(throughput > 0))
            break;
        if (tr->guided)
            radiance += throughput * sunlight_ahead(tr, g, x, &m, on_ground, up, dir);
        double pdf;
        throughput *= scatter(tr, g, &m, on_ground, up, dir, next, &pdf);
        nee_weight = tr->guided ? pdf / (pdf + about_sun_pdf(tr, next)) : 1.0;
        if (!(throughput > 0))
            break;
        if (throughput < roulette) {
            double survive = throughput / roulette;
            if (rng_next(g) >= survive)
                break;
            throughput = roulette;
        }
        struct ray ray;
        ray_init(tr, r, dot(up, next), &ray);
        double t = track(tr, &ray, g);
        if (t < 0 && !ray.ground)
            break; /* into space */
        on_ground = t < 0;
        if (on_ground)
            t = ray.t_end;
        for (int i = 0; i < 3; i++)
            x[i] += t * next[i];
        if (on_ground) {
            double len = length(x);
            for (int i = 0; i < 3; i++)
                x[i] *= tr->R / len;
        }
        memcpy(dir, next, sizeof(next));
    }
    return radiance;
}

/* ---- The view ray ------------------------------------------------------------- */

/*
 * Where first collisions on the view ray are drawn: the ray's optical depth
 * at nodes (exact), linear between them, and a weight per interval that
 * mixes, half and half, collision density alone with collision density
 * times single scattering's integrand at the interval's middle (sunlight,
 * phase, albedo). The first half serves the orders that light the planet's
 * shadow too, the second single scattering at twilight, where most of the
 * optical depth lies in the shadow.
 */
struct depth_table {
    int count; /* nodes */
    double *t, *tau;
    double *mass; /* cumulative weight at the nodes; mass[count - 1] is the total */
};

/* Single scattering's integrand per unit collision density at t on the ray
 * from x0 along dir. */
static double single_scattering_at(const struct tracer *tr, const struct ray *ray, const double x0[3],
                                   const double dir[3], double t)
{
    double x[3];
    for (int i = 0; i < 3; i++)
        x[i] = x0[i] + t * dir[i];
    double r = length(x), nu = dot(dir, tr->sun);
    struct coefficients m = coefficients_at(tr, altitude_at(tr, ray, t));
    if (!(m.extinction > 0))
        return 0.0;
    double in = sunlight(tr, r, dot(x, tr->sun) / r);
    return in * (m.rayleigh * phase_rayleigh(nu) + m.mie * phase_mie(tr->p->mie_g, nu)) / m.extinction;
}

static bool depth_table_init(const struct tracer *tr, const struct ray *ray, const double x0[3], const double dir[3],
                             struct depth_table *table)
{
    int n = (ray->cut_count - 1) * TABLE_SPLIT + 1;
    double *collide = malloc(5 * (size_t)n * sizeof(double));
    if (!collide)
        return false;
    double *integrand = collide + n;
    table->t = integrand + n;
    table->tau = table->t + n;
    table->mass = table->tau + n;
    table->count = 0;
    for (int i = 0; i + 1 < ray->cut_count; i++) {
        double a = ray->cuts[i], b = ray->cuts[i + 1];
        for (int k = 0; k < TABLE_SPLIT; k++)
            table->t[table->count++] = a + (b - a) * k / TABLE_SPLIT;
    }
    table->t[table->count++] = ray->t_end;
    table->tau[0] = 0.0;
    double plain = 0.0, lit = 0.0;
    for (int i = 0; i + 1 < table->count; i++) {
        double d[3] = {0, 0, 0};
        if (table->t[i + 1] > table->t[i])
            sb_ref_optical_depth(tr->p, ray->r, ray->mu, table->t[i], table->t[i + 1], 1, d);
        table->tau[i + 1] = table->tau[i] + d[tr->channel];
        collide[i] = exp(-table->tau[i]) * -expm1(-d[tr->channel]);
        integrand[i] =
            collide[i] > 0 ? single_scattering_at(tr, ray, x0, dir, 0.5 * (table->t[i] + table->t[i + 1])) : 0.0;
        plain += collide[i];
        lit += collide[i] * integrand[i];
    }
    table->mass[0] = 0.0;
    for (int i = 0; i + 1 < table->count; i++) {
        double weight = lit > 0 ? 0.5 + 0.5 * integrand[i] * plain / lit : 1.0;
        table->mass[i + 1] = table->mass[i] + collide[i] * weight;
    }
    /* to the block's start, where free(table->t) finds it */
    table->t = memmove(collide, table->t, 3 * (size_t)n * sizeof(double));
    table->tau = table->t + n;
    table->mass = table->tau + n;
    return true;
}

/*
 * A first collision on the view ray at quantile u of the table's weights:
 * the interval by its weight, the distance in it from the truncated
 * exponential of its (linear) optical depth. Returns the throughput
 * T(0, t) sigma_t(t) / pdf(t), with the exact optical depth to t.
 */
static double sample_view_ray(const struct tracer *tr, const struct ray *ray, const struct depth_table *table, double u,
                              double *t_out)
{
    double total = table->mass[table->count - 1], target = u * total;
    int lo = 0, hi = table->count - 1;
    while (hi - lo > 1) {
        int mid = (lo + hi) / 2;
        if (table->mass[mid] <= target)
            lo = mid;
        else
            hi = mid;
    }
    double dt = table->t[hi] - table->t[lo], dtau = table->tau[hi] - table->tau[lo];
    double mass = table->mass[hi] - table->mass[lo];
    if (!(dtau > 0) || !(dt > 0) || !(mass > 0))
        return 0.0;
    /* the interval's weight over its collision probability */
    double collide = exp(-table->tau[lo]) * -expm1(-dtau), weight = mass / collide;
    double f = fmin(fmax((target - table->mass[lo]) / mass, 0.0), 1.0);
    double into = -log1p(f * expm1(-dtau)); /* optical depth into the interval */
    double slope = dtau / dt, t = table->t[lo] + fmin(into / slope, dt);
    double pdf = weight * slope * exp(-(table->tau[lo] + into)) / total, d[3] = {0, 0, 0};
    if (t > table->t[lo])
        sb_ref_optical_depth(tr->p, ray->r, ray->mu, table->t[lo], t, 1, d);
    double tau = table->tau[lo] + d[tr->channel];
    *t_out = t;
    return exp(-tau) * coefficients_at(tr, altitude_at(tr, ray, t)).extinction / pdf;
}

static void tracer_init(struct tracer *tr, const struct sb_atmosphere_params *p, int channel,
                        const struct sb_pathtrace_params *params, double mu_s)
{
    *tr = (struct tracer){
        .p = p,
        .channel = channel,
        .max_order = params ? params->max_order : 0,
        .guided = !(params && params->unguided) && p->mie_scattering_per_km[channel] > 0 && fabs(p->mie_g) >= GUIDE_G,
        .R = p->ground_radius_km,
        .top = p->top_radius_km,
        .sun = {sqrt(fmax(1.0 - mu_s * mu_s, 0.0)), 0.0, mu_s},
        .rayleigh = p->rayleigh_scattering_per_km[channel],
        .mie_scattering = p->mie_scattering_per_km[channel],
        .mie_extinction = p->mie_scattering_per_km[channel] + p->mie_absorption_per_km[channel],
        .ozone = p->ozone_absorption_per_km[channel],
    };
    /* Levels every half octave of altitude from a quarter of the smaller
     * scale height (majorants within a factor e^(h / 2.4 H) of the
     * extinction), and the ozone tent's corners. */
    double thickness = tr->top - tr->R;
    double level = 0.25 * fmin(p->rayleigh_scale_height_km, p->mie_scale_height_km);
    for (; level < thickness && tr->level_count < 56; level *= 1.4142135623730951)
        tr->levels[tr->level_count++] = level;
    double corners[3] = {p->ozone_center_km - p->ozone_half_width_km, p->ozone_center_km,
                         p->ozone_center_km + p->ozone_half_width_km};
    for (int i = 0; i < 3; i++)
        if (corners[i] > 0 && corners[i] < thickness)
            tr->levels[tr->level_count++] = corners[i];
}

struct sb_pathtrace_result sb_pathtrace_radiance(const struct sb_atmosphere_params *p,
                                                 const struct sb_pathtrace_view *view, int channel,
                                                 const struct sb_pathtrace_params *params)
{
    struct sb_pathtrace_result result = {0};
    int paths = params && params->paths > 0 ? params->paths : 4096;
    uint64_t seed = params ? params->seed : 0;
    double mu = fmax(-1.0, fmin(1.0, view->mu)), mu_s = fmax(-1.0, fmin(1.0, view->mu_s));
    struct tracer tr;
    tracer_init(&tr, p, channel, params, mu_s);

    /* The camera at (0, 0, r), the sun in the xz plane, the view at the
     * azimuth that gives nu. */
    double sin_v = sqrt(fmax(1.0 - mu * mu, 0.0)), sin_s = tr.sun[0];
    double cos_phi = sin_v * sin_s > 0 ? fmax(-1.0, fmin(1.0, (view->nu - mu * mu_s) / (sin_v * sin_s))) : 1.0;
    double dir0[3] = {sin_v * cos_phi, sin_v * sqrt(fmax(1.0 - cos_phi * cos_phi, 0.0)), mu};
    double x0[3] = {0.0, 0.0, tr.R + fmax(view->altitude_km, 0.0)};
    double r0 = x0[2];
    if (r0 > tr.top) {
        double b = r0 * mu, disc = b * b - (r0 - tr.top) * (r0 + tr.top);
        if (mu >= 0.0 || disc < 0.0)
            return result; /* black space */
        double t = (r0 - tr.top) * (r0 + tr.top) / (-b + sqrt(disc));
        for (int i = 0; i < 3; i++)
            x0[i] += t * dir0[i];
        r0 = length(x0);
    }

    struct ray view_ray;
    ray_init(&tr, r0, dot(x0, dir0) / r0, &view_ray);
    struct depth_table table;
    if (!depth_table_init(&tr, &view_ray, x0, dir0, &table)) {
        result.radiance = result.std_error = NAN;
        return result;
    }
    double total = table.tau[table.count - 1];
    bool collides = table.mass[table.count - 1] > 0;

    uint64_t stream =
        mix(mix(mix(mix(mix(seed, double_bits(view->altitude_km)), double_bits(view->mu)), double_bits(view->mu_s)),
                double_bits(view->nu)),
            (uint64_t)channel);
    /* Independent batches, each stratified over the view ray on its own:
     * the spread of their means estimates the error of the whole mean
     * (the paths of one stratified batch are not independent). */
    int batches = paths >= 2 * BATCHES ? BATCHES : 1;
    double batch_sum[BATCHES] = {0};
    for (int k = 0; k < paths; k++) {
        int batch = k % batches, stratum = k / batches;
        int batch_paths = paths / batches + (batch < paths % batches);
        struct rng g;
        rng_seed(&g, mix(stream, (uint64_t)k));
        double value = 0.0;
        if (collides) {
            double u = (stratum + rng_next(&g)) / batch_paths;
            double t = 0.0, w = sample_view_ray(&tr, &view_ray, &table, u, &t);
            double x[3], dir[3];
            for (int i = 0; i < 3; i++) {
                x[i] = x0[i] + t * dir0[i];
                dir[i] = dir0[i];
            }
            if (w > 0)
                value += continue_path(&tr, &g, x, dir, false, w);
        }
        if (view_ray.ground) {
            double x[3], dir[3];
            for (int i = 0; i < 3; i++) {
                x[i] = x0[i] + view_ray.t_end * dir0[i];
                dir[i] = dir0[i];
            }
            double len = length(x);
            for (int i = 0; i < 3; i++)
                x[i] *= tr.R / len;
            value += continue_path(&tr, &g, x, dir, true, exp(-total));
        }
        batch_sum[batch] += value;
    }
    double sum = 0.0, sum_squares = 0.0;
    for (int b = 0; b < batches; b++) {
        double mean = batch_sum[b] / (paths / batches + (b < paths % batches));
        sum += batch_sum[b];
        sum_squares += mean * mean;
    }
    result.radiance = sum / paths;
    if (batches > 1) {
        double mean_of_means = 0.0;
        for (int b = 0; b < batches; b++)
            mean_of_means += batch_sum[b] / (paths / batches + (b < paths % batches)) / batches;
        double variance = fmax(sum_squares / batches - mean_of_means * mean_of_means, 0.0) * batches / (batches - 1);
        result.std_error = sqrt(variance / batches);
    } else {
        result.std_error = INFINITY;
    }
    free(table.t);
    return result;
}
