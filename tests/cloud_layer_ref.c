/*
 * The cloud layer in fp64 (cloud_layer_ref.h): shaders/cloud_layer.glsl's
 * model, step for step, with fine integrals.
 */
#include "cloud_layer_ref.h"

#include <math.h>
#include <string.h>

#include "atmosphere_ref.h"
#include "clouds_gpu.h"
#include "config.h"

/* A value as the runtime's RGBA16F textures hold it. */
static double half(float v)
{
    return sb_half_to_float(sb_half_from_float(v));
}

static int wrap_index(long i, uint32_t n)
{
    long m = i % (long)n;
    return (int)(m < 0 ? m + (long)n : m);
}

/* Channel c of `image` filtered linearly at texture coordinates u (each
 * axis repeating), as VK_FILTER_LINEAR with VK_SAMPLER_ADDRESS_MODE_REPEAT
 * reads it; 2D images take u[0], u[1]. */
static void sample(const struct sb_image *image, const double u[3], double out[4])
{
    uint32_t size[3] = {image->width, image->height, image->depth ? image->depth : 1};
    int dims = size[2] > 1 ? 3 : 2;
    long i0[3] = {0, 0, 0};
    double f[3] = {0, 0, 0};
    for (int k = 0; k < dims; k++) {
        double x = u[k] * size[k] - 0.5;
        double fl = floor(x);
        i0[k] = (long)fl;
        f[k] = x - fl;
    }
    for (int c = 0; c < 4; c++)
        out[c] = 0.0;
    for (int corner = 0; corner < (dims == 3 ? 8 : 4); corner++) {
        double w = 1.0;
        size_t index = 0, stride = 1;
        for (int k = 0; k < dims; k++) {
            int o = (corner >> k) & 1;
            w *= o ? f[k] : 1.0 - f[k];
            index += (size_t)wrap_index(i0[k] + o, size[k]) * stride;
            stride *= size[k];
        }
        for (uint32_t c = 0; c < image->channel_count && c < 4; c++)
            out[c] += w * half(image->data[index * image->channel_count + c]);
    }
}

static double clamp01(double x)
{
    return x < 0.0 ? 0.0 : x > 1.0 ? 1.0 : x;
}

static double remap(double v, double lo, double hi)
{
    return clamp01((v - lo) / fmax(hi - lo, 1e-3));
}

static double smooth01(double x)
{
    x = clamp01(x);
    return x * x * (3.0 - 2.0 * x);
}

double sb_cloud_ref_density(const struct sb_cloud_ref *ref, const double q[3])
{
    const struct sb_cloud_layer_params *m = &ref->layer;
    double f = (q[1] - m->base_altitude_m) / (m->top_altitude_m - m->base_altitude_m);
    if (f <= 0.0 || f >= 1.0)
        return 0.0;
    double w[4], s[4], curl[4], d[4];
    sample(ref->noise[3], (const double[3]){q[0] / m->weather_scale_m, q[2] / m->weather_scale_m, 0}, w);
    double c = clamp01(w[0] + 2.0 * m->coverage - 1.0);
    if (c <= 0.0)
        return 0.0;
    double top = 0.3 + 0.7 * w[2];
    double profile = smooth01(f * 10.0) * smooth01((top - f) / (0.4 * top));
    if (profile <= 0.0)
        return 0.0;
    sample(ref->noise[0], (const double[3]){q[0] / m->shape_scale_m, q[1] / m->shape_scale_m, q[2] / m->shape_scale_m},
           s);
    double fbm = s[1] * 0.625 + s[2] * 0.25 + s[3] * 0.125;
    double base = remap(s[0], fbm - 1.0, 1.0) * profile;
    base = remap(base, 1.0 - c, 1.0) * c;
    if (base <= 0.0)
        return 0.0;
    sample(ref->noise[2], (const double[3]){q[0] / m->curl_scale_m, q[2] / m->curl_scale_m, 0}, curl);
    double p[3];
    for (int k = 0; k < 3; k++)
        p[k] = (q[k] + (curl[k] * 2.0 - 1.0) * (m->curl_m * (1.0 - f))) / m->detail_scale_m;
    sample(ref->noise[1], p, d);
    double dfbm = d[0] * 0.625 + d[1] * 0.25 + d[2] * 0.125;
    double t = clamp01(f * 10.0);
    double modifier = dfbm + (1.0 - 2.0 * dfbm) * t;
    return remap(base, modifier * m->erosion, 1.0);
}

/* ---- Geometry on the sphere, as atmosphere.glsl and cloud_layer.glsl have it ---- */

static bool hits_ground(const struct sb_cloud_ref *ref, double h, double mu)
{
    double R = ref->atmosphere->ground_radius_km, r = R + h;
    return mu < 0.0 && r * r * mu * mu >= h * (2.0 * R + h);
}

static double altitude_along(const struct sb_cloud_ref *ref, double h0, double mu, double t)
{
    double r0 = ref->atmosphere->ground_radius_km + h0;
    double q = t * (t + 2.0 * r0 * mu);
    double rt = sqrt(fmax(r0 * r0 + q, 0.0));
    return fmax(h0 + q / (rt + r0), 0.0);
}

/* (near, far) km to the sphere at altitude a from altitude h along mu; false on a miss. */
static bool sphere_hits(const struct sb_cloud_ref *ref, double h, double mu, double a, double t[2])
{
    double R = ref->atmosphere->ground_radius_km, r = R + h;
    double c = (h - a) * (r + R + a), b = r * mu, disc = b * b - c;
    if (disc < 0.0)
        return false;
    double s = sqrt(disc), q = b >= 0.0 ? -(b + s) : s - b;
    double t1 = q, t2 = q != 0.0 ? c / q : 0.0;
    t[0] = fmin(t1, t2);
    t[1] = fmax(t1, t2);
    return true;
}

static double exit_m(const struct sb_cloud_ref *ref, double h, double mu)
{
    double top[2], base[2];
    double t = sphere_hits(ref, h, mu, ref->layer.top_altitude_m * 1e-3, top) ? top[1] : 0.0;
    if (sphere_hits(ref, h, mu, ref->layer.base_altitude_m * 1e-3, base) && base[0] > 0.0)
        t = fmin(t, base[0]);
    return fmax(t, 0.0) * 1e3;
}

static void planet_position(const struct sb_cloud_ref *ref, const double world_m[3], double out[3])
{
    out[0] = world_m[0] * 1e-3;
    out[1] = ref->atmosphere->ground_radius_km + world_m[1] * 1e-3;
    out[2] = world_m[2] * 1e-3;
}

static double length3(const double v[3])
{
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

/* ---- Light ---- */

void sb_cloud_ref_init(struct sb_cloud_ref *ref, const struct sb_image *multiscattering)
{
    double P[3];
    planet_position(ref, ref->camera_m, P);
    double r = length3(P);
    ref->mu_s0 = (P[0] * ref->sun[0] + P[1] * ref->sun[1] + P[2] * ref->sun[2]) / r - 0.01;
    ref->mu_s_step = 0.02 / (SB_CLOUD_REF_TABLE - 1);
    struct sb_ref_quality q = {0};
    for (int i = 0; i < SB_CLOUD_REF_TABLE; i++) {
        double direct[3], sky[3];
        sb_ref_irradiance_ground(ref->atmosphere, 0.0, ref->mu_s0 + i * ref->mu_s_step, multiscattering, &q, direct,
                                 sky);
        for (int c = 0; c < 3; c++) {
            ref->e_up[i][c] = sky[c];
            ref->e_down[i][c] = ref->atmosphere->ground_albedo[c] * (direct[c] + sky[c]);
        }
    }
    ref->view_steps = 4000;
    ref->light_steps = 512;
    ref->shadow_steps = 4000;
}

static void ambient(const struct sb_cloud_ref *ref, double mu_s, double f, double out[3])
{
    double x = (mu_s - ref->mu_s0) / ref->mu_s_step;
    x = x < 0 ? 0 : x > SB_CLOUD_REF_TABLE - 1 ? SB_CLOUD_REF_TABLE - 1 : x;
    int i = (int)x < SB_CLOUD_REF_TABLE - 1 ? (int)x : SB_CLOUD_REF_TABLE - 2;
    double a = x - i;
    for (int c = 0; c < 3; c++) {
        double up = ref->e_up[i][c] + a * (ref->e_up[i + 1][c] - ref->e_up[i][c]);
        double down = ref->e_down[i][c] + a * (ref->e_down[i + 1][c] - ref->e_down[i][c]);
        out[c] = (up * (0.5 + 0.5 * f) + down * (1.0 - 0.5 * f)) / (2.0 * M_PI);
    }
}

static double hg(double g, double nu)
{
    double d = 1.0 + g * g - 2.0 * g * nu;
    return (1.0 - g * g) / (4.0 * M_PI * d * sqrt(d));
}

/* The optical depth toward the sun from q, to the layer's edge or the light march's reach. */
static double light_depth(const struct sb_cloud_ref *ref, const double q[3], double h, double mu_s)
{
    double reach = fmin(exit_m(ref, h, mu_s), SB_CLOUD_LIGHT_DISTANCE_M), piece = reach / ref->light_steps;
    double tau = 0.0;
    for (int k = 0; k < ref->light_steps; k++) {
        double s = (k + 0.5) * piece;
        double p[3] = {q[0] + ref->sun[0] * s, altitude_along(ref, h, mu_s, s * 1e-3) * 1e3, q[2] + ref->sun[2] * s};
        tau += sb_cloud_ref_density(ref, p) * piece;
    }
    return tau * ref->layer.extinction_per_m;
}

/* The light per unit scattering at q (cloud_light). */
static void light(const struct sb_cloud_ref *ref, const double q[3], const double up[3], double h, double f, double nu,
                  double out[3])
{
    const struct sb_cloud_layer_params *m = &ref->layer;
    double mu_s = up[0] * ref->sun[0] + up[1] * ref->sun[1] + up[2] * ref->sun[2];
    double t[3] = {0, 0, 0};
    if (!hits_ground(ref, h, mu_s))
        sb_ref_transmittance_lookup(ref->atmosphere, ref->transmittance, ref->atmosphere->ground_radius_km + h, mu_s,
                                    t);
    double octaves = 0.0;
    if (t[0] > 0.0 || t[1] > 0.0 || t[2] > 0.0) {
        double tau = light_depth(ref, q, h, mu_s), a = 1.0;
        for (uint32_t i = 0; i < m->scattering_octaves; i++) {
            double p = m->phase_forward_weight * hg(m->phase_forward_g * a, nu) +
                       (1.0 - m->phase_forward_weight) * hg(m->phase_backward_g * a, nu);
            octaves += a * exp(-a * tau) * p;
            a *= 0.5;
        }
    }
    double amb[3];
    ambient(ref, mu_s, f, amb);
    for (int c = 0; c < 3; c++)
        out[c] = m->albedo[c] * (ref->atmosphere->solar_irradiance[c] * t[c] * octaves + amb[c]);
}

/* ---- The view ray ---- */

void sb_cloud_ref_march(const struct sb_cloud_ref *ref, const double d[3], double scene_m, double inscatter[3],
                        double *transmittance)
{
    const struct sb_cloud_layer_params *m = &ref->layer;
    double C[3];
    planet_position(ref, ref->camera_m, C);
    double rc = length3(C), h_c = rc - ref->atmosphere->ground_radius_km;
    double mu = (C[0] * d[0] + C[1] * d[1] + C[2] * d[2]) / rc;
    double base = m->base_altitude_m * 1e-3, top = m->top_altitude_m * 1e-3;
    double hb[2] = {-1, -1}, ht[2] = {-1, -1};
    sphere_hits(ref, h_c, mu, base, hb);
    sphere_hits(ref, h_c, mu, top, ht);
    double t0 = 0.0, t1 = 0.0;
    bool any = true;
    if (h_c < base) {
        any = !hits_ground(ref, h_c, mu);
        t0 = hb[1];
        t1 = ht[1];
    } else if (h_c < top) {
        t1 = hb[0] > 0.0 ? fmin(ht[1], hb[0]) : ht[1];
    } else {
        any = ht[0] > 0.0;
        t0 = ht[0];
        t1 = hb[0] > 0.0 ? hb[0] : ht[1];
    }
    t0 *= 1e3;
    t1 = fmin(fmin(t1 * 1e3, t0 + SB_CLOUD_REACH_M), scene_m);
    inscatter[0] = inscatter[1] = inscatter[2] = 0.0;
    double T = 1.0;
    if (any && t1 > t0) {
        double nu = d[0] * ref->sun[0] + d[1] * ref->sun[1] + d[2] * ref->sun[2];
        double dt = (t1 - t0) / ref->view_steps;
        for (int i = 0; i < ref->view_steps; i++) {
            double t = t0 + (i + 0.5) * dt;
            double h = altitude_along(ref, h_c, mu, t * 1e-3);
            double q[3] = {ref->camera_m[0] + d[0] * t, h * 1e3, ref->camera_m[2] + d[2] * t};
            double density = sb_cloud_ref_density(ref, q);
            if (density <= 0.0)
                continue;
            double P[3] = {C[0] + d[0] * t * 1e-3, C[1] + d[1] * t * 1e-3, C[2] + d[2] * t * 1e-3};
            double rp = length3(P), up[3] = {P[0] / rp, P[1] / rp, P[2] / rp};
            double L[3];
            light(ref, q, up, h, (q[1] - m->base_altitude_m) / (m->top_altitude_m - m->base_altitude_m), nu, L);
            double absorbed = T * -expm1(-density * m->extinction_per_m * dt);
            for (int c = 0; c < 3; c++)
                inscatter[c] += L[c] * absorbed;
            T -= absorbed;
        }
    }
    *transmittance = T;
}

double sb_cloud_ref_sun_transmittance(const struct sb_cloud_ref *ref, const double p[3])
{
    double P[3];
    planet_position(ref, p, P);
    double r = length3(P), h = r - ref->atmosphere->ground_radius_km;
    double mu_s = (P[0] * ref->sun[0] + P[1] * ref->sun[1] + P[2] * ref->sun[2]) / r;
    double hb[2], ht[2];
    if (hits_ground(ref, h, mu_s) || !sphere_hits(ref, h, mu_s, ref->layer.base_altitude_m * 1e-3, hb) ||
        !sphere_hits(ref, h, mu_s, ref->layer.top_altitude_m * 1e-3, ht))
        return 1.0;
    double enter = fmax(hb[1], 0.0) * 1e3, leave = fmin(ht[1] * 1e3, enter + SB_CLOUD_SHADOW_REACH_M);
    double piece = fmax(leave - enter, 0.0) / ref->shadow_steps, tau = 0.0;
    for (int i = 0; i < ref->shadow_steps; i++) {
        double s = enter + (i + 0.5) * piece;
        double q[3] = {p[0] + ref->sun[0] * s, altitude_along(ref, h, mu_s, s * 1e-3) * 1e3, p[2] + ref->sun[2] * s};
        tau += sb_cloud_ref_density(ref, q) * piece;
    }
    return exp(-tau * ref->layer.extinction_per_m);
}
