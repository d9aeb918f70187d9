/*
 * Geometry: meshes through assimp (real assets from Debian's
 * assimp-testmodels, hostile files), the BVH (determinism, structure, its
 * CPU traversal against brute force) and the GPU's ray casts against
 * Embree, the independent reference, on every test ray but a stated band of
 * rays that graze an edge or a vertex (measured and reported).
 */
#include <cJSON.h>
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "bvh.h"
#include "parallel.h"
#include "pngfile.h"
#include "embree_ref.h"
#include "harness_vk.h"
#include "io.h"
#include "json.h"
#include "level.h"
#include "log.h"
#include "load.h"
#include "mesh.h"
#include "splitmix.h"
#include "raycast.h"
#include "scene.h"
#include "shapes.h"

#define MODELS "/usr/share/assimp/models"
#define IFC_HOUSE MODELS "/IFC/AC14-FZK-Haus.ifc"

/*
 * The band (the "stated, measured epsilon band"): a ray on which
 * the GPU and Embree disagree is excused only when, in fp64, the triangle
 * one side hit and the other missed
 * - is met within BAND_RELATIVE x (|o - v0| + |e1| + |e2|) / cos(theta) of
 *   its boundary (the ray passes by an edge or a vertex; theta is the angle
 *   between the ray and the triangle's normal: a ray grazing the plane
 *   magnifies both tests' rounding by 1 / cos(theta)), or
 * - has the ray's origin within that distance of its plane (a ray leaving a
 *   surface, against a coplanar or adjacent face).
 * Two hits of one triangle agree (the largest difference of their
 * distances, in bands, is reported and must be within one); hits of two
 * triangles within one band of each other agree (shared edges, coincident
 * faces: the IFC house has many). fp32 Moller-Trumbore and Embree's robust test round differently
 * there. Measured: the widest disagreement over the scenes and ray kinds
 * below was 1.04e-5 (the IFC house, a ray aimed at a vertex); the band is
 * 2e-5, about 170 fp32 ulps.
 */
#define BAND_RELATIVE 2e-5
/*
 * In a world of instances the width gains BAND_INSTANCED x (|o| + |v0|) /
 * cos(theta), world coordinates: each side moves the ray into the mesh's
 * space in fp32, rounding its own way, and the flattened copy the hits are
 * judged on rounds the placed vertices: errors of a few ulps of the
 * world's coordinates, not of the triangle's. 1e-6 is about 8 ulps.
 */
#define BAND_INSTANCED 1e-6

static uint64_t rng = 0x9e3779b97f4a7c15ull;

static double uniform(void)
{
    return sb_splitmix_uniform(&rng);
}

static void random_direction(float d[3])
{
    double z = 2 * uniform() - 1, phi = 2 * M_PI * uniform(), r = sqrt(fmax(0.0, 1 - z * z));
    d[0] = (float)(r * cos(phi));
    d[1] = (float)z;
    d[2] = (float)(r * sin(phi));
}

/* ---- the fp64 look at a disagreement ------------------------------------------------------ */

static double dot3d(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3d(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* Distance from p to the segment ab. */
static double segment_distance(const double p[3], const double a[3], const double b[3])
{
    double ab[3], ap[3];
    for (int i = 0; i < 3; i++) {
        ab[i] = b[i] - a[i];
        ap[i] = p[i] - a[i];
    }
    double s = fmin(fmax(dot3d(ap, ab) / fmax(dot3d(ab, ab), 1e-300), 0.0), 1.0);
    double d2 = 0;
    for (int i = 0; i < 3; i++)
        d2 += (ap[i] - s * ab[i]) * (ap[i] - s * ab[i]);
    return sqrt(d2);
}

/* Triangle t and the ray in fp64: where the ray meets its plane (t), how
 * far that point lies from its boundary and the origin from its plane
 * (metres), and the band's width there (BAND_RELATIVE). */
struct exact {
    double t, edge, plane, band, length; /* edge: negative outside the triangle */
};

static void exact_look(const struct sb_mesh *m, uint32_t t, const float *ray, double world_band, struct exact *x)
{
    double v[3][3], o[3], d[3], e1[3], e2[3], s[3], p[3], q[3], n[3];
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < 3; i++)
            v[k][i] = m->positions[3 * (size_t)m->indices[3 * (size_t)t + k] + i];
    for (int i = 0; i < 3; i++) {
        o[i] = ray[i];
        d[i] = ray[4 + i];
        e1[i] = v[1][i] - v[0][i];
        e2[i] = v[2][i] - v[0][i];
        s[i] = o[i] - v[0][i];
    }
    cross3d(e1, e2, n);
    x->length = sqrt(dot3d(d, d));
    double cos_theta = fabs(dot3d(d, n)) / (x->length * sqrt(dot3d(n, n)));
    x->band = (BAND_RELATIVE * (sqrt(dot3d(s, s)) + sqrt(dot3d(e1, e1)) + sqrt(dot3d(e2, e2))) +
               world_band * (sqrt(dot3d(o, o)) + sqrt(dot3d(v[0], v[0])))) /
              fmax(cos_theta, 1e-9);
    x->plane = fabs(dot3d(s, n)) / sqrt(dot3d(n, n));
    cross3d(d, e2, p);
    cross3d(s, e1, q);
    double det = dot3d(e1, p);
    x->t = det != 0 ? dot3d(e2, q) / det : INFINITY;
    x->edge = 0;
    if (det != 0) {
        double hit[3];
        for (int i = 0; i < 3; i++)
            hit[i] = o[i] + x->t * d[i];
        x->edge = fmin(segment_distance(hit, v[0], v[1]),
                       fmin(segment_distance(hit, v[1], v[2]), segment_distance(hit, v[2], v[0])));
        double u = dot3d(s, p) / det, w = dot3d(d, q) / det;
        if (u < 0 || w < 0 || u + w > 1)
            x->edge = -x->edge;
    }
}

static uint32_t hit_triangle(const float *h)
{
    uint32_t t;
    memcpy(&t, &h[1], sizeof(t));
    return t == SB_BVH_MISS ? t : t & ~SB_BVH_BACK_FACE;
}

struct agreement {
    uint32_t rays, hits, same, band, outside;
    double worst_margin; /* the largest distance from an edge excused, in units of the band */
    double worst_t;      /* the largest difference of t between hits of one triangle, in bands */
};

/* Compare the GPU's closest hits with Embree's, ray by ray. */
static void compare(const char *name, const struct sb_mesh *m, double world_band, const float *rays, uint32_t count, const float *gpu,
                    const float *ref, struct agreement *a)
{
    memset(a, 0, sizeof(*a));
    a->rays = count;
    for (uint32_t i = 0; i < count; i++) {
        const float *g = &gpu[4 * (size_t)i], *r = &ref[4 * (size_t)i], *ray = &rays[8 * (size_t)i];
        uint32_t tg = hit_triangle(g), tr = hit_triangle(r);
        a->hits += tr != SB_BVH_MISS;
        if (tg == tr) {
            a->same++;
            if (tg != SB_BVH_MISS) {
                struct exact x;
                exact_look(m, tg, ray, world_band, &x);
                a->worst_t = fmax(a->worst_t, fabs((double)g[0] - r[0]) * x.length / x.band);
            }
            continue;
        }
        /* Two triangles met at one point, within the band: both answers
         * are the same surface point (shared edges, coincident faces). */
        struct exact x, y;
        if (tg != SB_BVH_MISS && tr != SB_BVH_MISS) {
            exact_look(m, tg, ray, world_band, &x);
            exact_look(m, tr, ray, world_band, &y);
            if (fabs((double)g[0] - r[0]) * x.length <= fmax(x.band, y.band)) {
                a->same++;
                continue;
            }
        }
        /* One side missed the nearer triangle: does the ray pass by its
         * edge or start on its plane? */
        uint32_t nearer = tg == SB_BVH_MISS ? tr : tr == SB_BVH_MISS ? tg : (g[0] < r[0] ? tg : tr);
        exact_look(m, nearer, ray, world_band, &x);
        bool band = fabs(x.edge) <= x.band || x.plane <= x.band;
        double units = fabs(x.edge) <= x.band ? fabs(x.edge) / x.band : x.plane / x.band;
        if (band) {
            a->band++;
            a->worst_margin = fmax(a->worst_margin, units);
        } else if (a->outside++ < 5) {
            fprintf(stderr,
                    "%s: ray %u (%g %g %g -> %g %g %g, tmin %g): gpu triangle %d t %.9g, embree %d t %.9g; the "
                    "ray meets triangle %u %.3g bands %s its edges\n",
                    name, i, ray[0], ray[1], ray[2], ray[4], ray[5], ray[6], ray[3], (int)tg, g[0], (int)tr, r[0],
                    nearer, fabs(x.edge) / x.band, x.edge >= 0 ? "inside" : "outside");
        }
    }
}

/* ---- rays ---------------------------------------------------------------------------------- */

enum ray_kind { RAYS_RANDOM, RAYS_AT_VERTICES, RAYS_FROM_SURFACES, RAY_KIND_COUNT };
static const char *const ray_kind_names[] = {"random", "at vertices", "from surfaces"};

/* Deterministic test rays over the mesh's bounds: uniformly random
 * origins and directions; aimed exactly at vertices (every ray grazes an
 * edge: the band's worst case); or leaving points on triangles with
 * tmin 1e-4 (as probe and bounce rays do). */
static void make_rays(const struct sb_mesh *m, enum ray_kind kind, uint32_t count, float *rays)
{
    float lo[3], hi[3];
    sb_mesh_bounds(m, lo, hi);
    for (uint32_t i = 0; i < count; i++) {
        float *r = &rays[8 * (size_t)i];
        for (int k = 0; k < 3; k++) {
            float pad = 0.1f * (hi[k] - lo[k]);
            r[k] = (float)(lo[k] - pad + uniform() * (hi[k] - lo[k] + 2 * pad));
        }
        r[3] = 0.0f;
        r[7] = 1e30f;
        random_direction(&r[4]);
        if (kind == RAYS_AT_VERTICES) {
            uint32_t v = (uint32_t)(uniform() * m->vertex_count) % m->vertex_count;
            for (int k = 0; k < 3; k++)
                r[4 + k] = m->positions[3 * (size_t)v + k] - r[k];
        } else if (kind == RAYS_FROM_SURFACES) {
            uint32_t t = (uint32_t)(uniform() * m->triangle_count) % m->triangle_count;
            double a = uniform(), b = uniform();
            if (a + b > 1) {
                a = 1 - a;
                b = 1 - b;
            }
            for (int k = 0; k < 3; k++) {
                const float *p0 = &m->positions[3 * (size_t)m->indices[3 * (size_t)t] + 0];
                const float *p1 = &m->positions[3 * (size_t)m->indices[3 * (size_t)t + 1] + 0];
                const float *p2 = &m->positions[3 * (size_t)m->indices[3 * (size_t)t + 2] + 0];
                r[k] = (float)(p0[k] + a * (p1[k] - p0[k]) + b * (p2[k] - p0[k]));
            }
            r[3] = 1e-4f;
        }
    }
}

/* ---- tests ---------------------------------------------------------------------------------- */

static void test_gpu_against_embree(struct sb_vk *vk, const char *name, const struct sb_mesh *m, uint32_t count)
{
    struct sb_bvh bvh;
    double t0 = sb_now_s();
    enum sb_result res = sb_bvh_build(m, &bvh);
    double build_s = sb_now_s() - t0;
    CHECK(res == SB_OK, "%s: BVH", name);
    if (res)
        return;
    struct sb_raycaster *rc = NULL;
    struct sb_embree e = {0};
    float *rays = malloc((size_t)count * 8 * sizeof(float));
    float *gpu = malloc((size_t)count * 4 * sizeof(float)), *any = malloc((size_t)count * 4 * sizeof(float));
    float *ref = malloc((size_t)count * 4 * sizeof(float));
    CHECK(rays && gpu && any && ref, "allocation");
    CHECK(sb_embree_create(m, &e), "%s: Embree", name);
    res = sb_raycaster_create(vk, &bvh, &rc);
    CHECK(res == SB_OK, "%s: raycaster: %s", name, sb_result_name(res));
    for (int kind = 0; kind < RAY_KIND_COUNT && rc && rays && gpu && any && ref && e.scene; kind++) {
        make_rays(m, (enum ray_kind)kind, count, rays);
        double gpu_ms = 0, any_ms = 0;
        double g0 = sb_now_s();
        res = sb_raycaster_cast(rc, rays, count, false, gpu, &gpu_ms);
        double gpu_wall = sb_now_s() - g0;
        CHECK(res == SB_OK, "%s: cast: %s", name, sb_result_name(res));
        res = sb_raycaster_cast(rc, rays, count, true, any, &any_ms);
        CHECK(res == SB_OK, "%s: any-hit cast: %s", name, sb_result_name(res));
        double embree_s = sb_embree_cast(&e, rays, count, ref);
        struct agreement a;
        compare(name, m, 0.0, rays, count, gpu, ref, &a);
        uint32_t any_differ = 0;
        for (uint32_t i = 0; i < count; i++)
            any_differ += (hit_triangle(&gpu[4 * (size_t)i]) == SB_BVH_MISS) !=
                          (hit_triangle(&any[4 * (size_t)i]) == SB_BVH_MISS);
        printf("%-14s %-13s %7u rays, %6.2f%% hit: %u agree, %u in the band (%.3f%%, at most %.2g of its width), %u "
               "outside, t within %.2g bands; gpu %.3g Mrays/s (%.1f ms gpu), Embree %.3g Mrays/s (%ld threads)\n",
               name, ray_kind_names[kind], count, 100.0 * a.hits / count, a.same, a.band, 100.0 * a.band / count,
               a.worst_margin, a.outside, a.worst_t, count / fmax(gpu_ms * 1e-3, 1e-9) * 1e-6, gpu_ms,
               count / embree_s * 1e-6, sysconf(_SC_NPROCESSORS_ONLN));
        (void)gpu_wall;
        CHECK(a.outside == 0, "%s, %s rays: %u disagree with Embree outside the edge band", name, ray_kind_names[kind],
              a.outside);
        /* Random rays hit an edge's band rarely; rays aimed at vertices always graze one. */
        if (kind != RAYS_AT_VERTICES)
            CHECK(a.band * 1000u <= count, "%s, %s rays: %u in the band (more than 0.1%%)", name, ray_kind_names[kind],
                  a.band);
        CHECK(a.worst_t <= 1, "%s, %s rays: one triangle's hits differ in t by %.3g bands", name, ray_kind_names[kind],
              a.worst_t);
        CHECK(any_differ == 0, "%s, %s rays: any-hit and closest-hit disagree on %u rays' hit or miss", name,
              ray_kind_names[kind], any_differ);
        CHECK(a.hits > count / 20, "%s, %s rays: only %u hit: the test does not test", name, ray_kind_names[kind],
              a.hits);
    }
    printf("%-14s %u triangles: BVH %u nodes, depth %u, largest leaf %u, built in %.3f s\n", name, m->triangle_count,
           bvh.node_count, bvh.depth, bvh.max_leaf, build_s);
    sb_raycaster_destroy(&rc);
    if (e.device)
        sb_embree_destroy(&e);
    free(rays);
    free(gpu);
    free(any);
    free(ref);
    sb_bvh_finish(&bvh);
}

/* ---- two levels -------------------------------------------------------------------------- */

/* A rotation about a random axis, a scale (non-uniform for every third)
 * and a translation over a 300 m square, as rows of an affine 3 x 4. */
static void random_placement(uint32_t i, double to_world[3][4])
{
    double axis[3], angle = 2 * M_PI * uniform(), s[3];
    float d[3];
    random_direction(d);
    for (int k = 0; k < 3; k++)
        axis[k] = d[k];
    double base = 0.5 + uniform();
    for (int k = 0; k < 3; k++)
        s[k] = i % 3 == 2 ? base * (0.6 + 0.8 * uniform()) : base;
    double c = cos(angle), sn = sin(angle), t = 1 - c;
    double r[3][3] = {
        {t * axis[0] * axis[0] + c, t * axis[0] * axis[1] - sn * axis[2], t * axis[0] * axis[2] + sn * axis[1]},
        {t * axis[0] * axis[1] + sn * axis[2], t * axis[1] * axis[1] + c, t * axis[1] * axis[2] - sn * axis[0]},
        {t * axis[0] * axis[2] - sn * axis[1], t * axis[1] * axis[2] + sn * axis[0], t * axis[2] * axis[2] + c},
    };
    for (int row = 0; row < 3; row++) {
        for (int col = 0; col < 3; col++)
            to_world[row][col] = r[row][col] * s[col];
        to_world[row][3] = row == 1 ? 10 * uniform() : 300 * uniform() - 150;
    }
}

/* Hits of the instanced world (triangle numbered over the meshes, the
 * instance) in place as hits of its flattened copy, as compare() reads them. */
static void to_flat(float *hits, uint32_t count, const uint32_t *mesh_base, const uint32_t *instance_base,
                    const struct sb_bvh_instance *instances, uint32_t instance_count, uint32_t *wrong)
{
    for (uint32_t i = 0; i < count; i++) {
        uint32_t tri, instance;
        memcpy(&tri, &hits[4 * (size_t)i + 1], sizeof(tri));
        memcpy(&instance, &hits[4 * (size_t)i + 2], sizeof(instance));
        if (tri == SB_BVH_MISS)
            continue;
        uint32_t bits = tri & SB_BVH_BACK_FACE, t = tri & ~SB_BVH_BACK_FACE;
        if (instance >= instance_count || t < mesh_base[instances[instance].mesh] ||
            t >= mesh_base[instances[instance].mesh + 1]) {
            ++*wrong;
            tri = SB_BVH_MISS;
        } else {
            tri = (instance_base[instance] + t - mesh_base[instances[instance].mesh]) | bits;
        }
        memcpy(&hits[4 * (size_t)i + 1], &tri, sizeof(tri));
    }
}

/*
 * A world of 4 meshes placed 24 times (rotated, scaled, some unevenly):
 * the two-level BVH's bytes on 1 and 3 threads, and its CPU and GPU
 * traversals against Embree's own instanced scene, each hit compared as a
 * hit of the world flattened into one mesh (the same band as one level).
 */
static void test_instanced(struct sb_vk *vk, const struct sb_mesh *const *meshes, uint32_t mesh_count)
{
    enum { INSTANCES = 24, RAYS = 1u << 14 };
    struct sb_bvh_instance instances[INSTANCES];
    uint32_t mesh_base[8] = {0}, instance_base[INSTANCES];
    for (uint32_t m = 0; m < mesh_count; m++)
        mesh_base[m + 1] = mesh_base[m] + meshes[m]->triangle_count;
    struct sb_mesh flat = {0};
    uint32_t mat;
    sb_mesh_add_material(&flat, "flat", (double[3]){0.5, 0.5, 0.5}, &mat);
    enum sb_result res = SB_OK;
    for (uint32_t i = 0; i < INSTANCES && !res; i++) {
        instances[i].mesh = i % mesh_count;
        random_placement(i, instances[i].to_world);
        instance_base[i] = flat.triangle_count;
        const struct sb_mesh *m = meshes[instances[i].mesh];
        for (uint32_t t = 0; t < m->triangle_count && !res; t++) {
            double p[3][3];
            for (int k = 0; k < 3; k++) {
                const float *v = &m->positions[3 * (size_t)m->indices[3 * (size_t)t + k]];
                for (int r = 0; r < 3; r++)
                    p[k][r] = instances[i].to_world[r][0] * v[0] + instances[i].to_world[r][1] * v[1] +
                              instances[i].to_world[r][2] * v[2] + instances[i].to_world[r][3];
            }
            res = sb_mesh_add_triangle(&flat, p[0], p[1], p[2], mat, "flat");
        }
        /* a triangle too thin once placed would be dropped: keep the numbering */
        CHECK(flat.triangle_count - instance_base[i] == m->triangle_count, "instance %u: every triangle placed", i);
    }
    CHECK(res == SB_OK, "the flattened world: %s", sb_result_name(res));

    struct sb_bvh bvh, again;
    char hash[33], hash_again[33];
    sb_parallel_set_threads(1);
    res = sb_bvh_build_instanced(meshes, mesh_count, instances, INSTANCES, &bvh);
    CHECK(res == SB_OK, "two levels: %s", sb_result_name(res));
    sb_parallel_set_threads(3);
    CHECK(sb_bvh_build_instanced(meshes, mesh_count, instances, INSTANCES, &again) == SB_OK, "two levels, 3 threads");
    sb_parallel_set_threads(0);
    sb_bvh_hash(&bvh, hash);
    sb_bvh_hash(&again, hash_again);
    CHECK(!strcmp(hash, hash_again), "two levels: the same bytes on 1 and 3 threads (%s, %s)", hash, hash_again);
    sb_bvh_finish(&again);
    CHECK(bvh.instance_count == INSTANCES && bvh.triangle_count == mesh_base[mesh_count] &&
              bvh.depth <= 2 * SB_BVH_MAX_DEPTH + 1,
          "two levels: %u instances, %u triangles (one copy a mesh), depth %u", bvh.instance_count, bvh.triangle_count,
          bvh.depth);
    /* refused: an instance of no mesh, a singular transform */
    struct sb_bvh_instance bad = instances[0];
    bad.mesh = mesh_count;
    CHECK(sb_bvh_build_instanced(meshes, mesh_count, &bad, 1, &again) == SB_ERR_MESH, "an instance of no mesh");
    bad = instances[0];
    for (int c = 0; c < 4; c++)
        bad.to_world[2][c] = 0;
    CHECK(sb_bvh_build_instanced(meshes, mesh_count, &bad, 1, &again) == SB_ERR_MESH, "a flat transform");
    if (res)
        goto done;

    struct sb_embree e = {0};
    CHECK(sb_embree_create_instanced(meshes, mesh_count, instances, INSTANCES, &e), "Embree's instanced scene");
    struct sb_raycaster *rc = NULL;
    if (vk)
        CHECK(sb_raycaster_create(vk, &bvh, &rc) == SB_OK, "two levels on the device");
    float *rays = malloc((size_t)RAYS * 8 * sizeof(float));
    float *cpu = malloc((size_t)RAYS * 4 * sizeof(float)), *gpu = malloc((size_t)RAYS * 4 * sizeof(float));
    float *any = malloc((size_t)RAYS * 4 * sizeof(float)), *ref = malloc((size_t)RAYS * 4 * sizeof(float));
    for (int kind = 0; kind < RAY_KIND_COUNT && e.scene && rays && cpu && gpu && any && ref; kind++) {
        make_rays(&flat, (enum ray_kind)kind, RAYS, rays);
        /* leaving a surface 150 m out, by the kernels' offset (probe_bounce.comp) */
        for (uint32_t i = 0; kind == RAYS_FROM_SURFACES && i < RAYS; i++) {
            float *r = &rays[8 * (size_t)i];
            r[3] = 1e-4f + 2e-6f * fmaxf(fabsf(r[0]), fmaxf(fabsf(r[1]), fabsf(r[2])));
        }
        uint32_t wrong = 0, any_differ = 0;
        for (uint32_t i = 0; i < RAYS; i++) {
            const float *r = &rays[8 * (size_t)i];
            struct sb_hit h;
            sb_bvh_intersect(&bvh, r, r + 4, r[3], r[7], false, &h);
            float *c = &cpu[4 * (size_t)i];
            c[0] = h.t;
            uint32_t bits = h.triangle == SB_BVH_MISS ? SB_BVH_MISS : h.triangle | (h.back_face ? SB_BVH_BACK_FACE : 0);
            memcpy(&c[1], &bits, sizeof(bits));
            memcpy(&c[2], &h.instance, sizeof(uint32_t));
            struct sb_hit h_any;
            any_differ += sb_bvh_intersect(&bvh, r, r + 4, r[3], r[7], true, &h_any) != (h.triangle != SB_BVH_MISS);
        }
        sb_embree_cast(&e, rays, RAYS, ref);
        to_flat(ref, RAYS, mesh_base, instance_base, instances, INSTANCES, &wrong);
        to_flat(cpu, RAYS, mesh_base, instance_base, instances, INSTANCES, &wrong);
        struct agreement a;
        compare("instanced cpu", &flat, BAND_INSTANCED, rays, RAYS, cpu, ref, &a);
        printf("%-14s %-13s %7u rays, %6.2f%% hit: %u agree, %u in the band (at most %.2g of its width), %u outside "
               "(CPU)\n",
               "instanced", ray_kind_names[kind], RAYS, 100.0 * a.hits / RAYS, a.same, a.band, a.worst_margin,
               a.outside);
        CHECK(a.outside == 0 && wrong == 0 && any_differ == 0,
              "instanced, %s rays, CPU: %u disagree with Embree outside the band, %u name a wrong instance, %u "
              "any-hit casts differ",
              ray_kind_names[kind], a.outside, wrong, any_differ);
        CHECK(a.hits > RAYS / 20, "instanced, %s rays: only %u hit: the test does not test", ray_kind_names[kind],
              a.hits);
        if (!rc)
            continue;
        CHECK(sb_raycaster_cast(rc, rays, RAYS, false, gpu, NULL) == SB_OK, "GPU cast");
        CHECK(sb_raycaster_cast(rc, rays, RAYS, true, any, NULL) == SB_OK, "GPU any-hit cast");
        to_flat(gpu, RAYS, mesh_base, instance_base, instances, INSTANCES, &wrong);
        compare("instanced gpu", &flat, BAND_INSTANCED, rays, RAYS, gpu, ref, &a);
        any_differ = 0;
        for (uint32_t i = 0; i < RAYS; i++)
            any_differ += (hit_triangle(&gpu[4 * (size_t)i]) == SB_BVH_MISS) !=
                          (hit_triangle(&any[4 * (size_t)i]) == SB_BVH_MISS);
        printf("%-14s %-13s %7u rays, %6.2f%% hit: %u agree, %u in the band (at most %.2g of its width), %u outside, "
               "t within %.2g bands (GPU)\n",
               "instanced", ray_kind_names[kind], RAYS, 100.0 * a.hits / RAYS, a.same, a.band, a.worst_margin,
               a.outside, a.worst_t);
        CHECK(a.outside == 0 && wrong == 0 && any_differ == 0 && a.worst_t <= 1,
              "instanced, %s rays, GPU: %u disagree with Embree outside the band, %u name a wrong instance, %u "
              "any-hit casts differ, t within %.2g bands",
              ray_kind_names[kind], a.outside, wrong, any_differ, a.worst_t);
        /* Random rays meet a band rarely, as in one level. Rays leaving a
         * surface up to 150 m out meet their own surface's rounding more
         * often than near the origin: measured 0.47% (one level, near the
         * origin: 0.002%); at most 1%. */
        if (kind == RAYS_RANDOM)
            CHECK(a.band * 1000u <= RAYS, "instanced, random rays: %u in the band (more than 0.1%%)", a.band);
        if (kind == RAYS_FROM_SURFACES)
            CHECK(a.band * 100u <= RAYS, "instanced, rays from surfaces: %u in the band (more than 1%%)", a.band);
    }
    sb_raycaster_destroy(&rc);
    if (e.device)
        sb_embree_destroy(&e);
    free(rays);
    free(cpu);
    free(gpu);
    free(any);
    free(ref);
done:
    sb_bvh_finish(&bvh);
    sb_mesh_finish(&flat);
}

/* Every triangle once; children inside parents; leaves and depth within
 * their caps; the CPU traversal equal to brute force over every triangle. */
static void test_bvh_structure(const char *name, const struct sb_mesh *m)
{
    /* The same bytes on 1, 3 and 8 threads (more threads than cores too). */
    struct sb_bvh bvh, again;
    sb_parallel_set_threads(8);
    CHECK(sb_bvh_build(m, &bvh) == SB_OK, "%s: BVH", name);
    char h1[33], h2[33];
    sb_bvh_hash(&bvh, h1);
    for (int threads = 1; threads <= 3; threads += 2) {
        sb_parallel_set_threads(threads);
        CHECK(sb_bvh_build(m, &again) == SB_OK, "%s: BVH again", name);
        sb_bvh_hash(&again, h2);
        CHECK(!strcmp(h1, h2) && bvh.node_count == again.node_count,
              "%s: the builds on 8 and %d threads differ (%s, %s)", name, threads, h1, h2);
        if (threads == 1)
            sb_bvh_finish(&again);
    }
    sb_parallel_set_threads(0);
    uint8_t *seen = calloc(m->triangle_count, 1);
    uint32_t leaves = 0, bad = 0;
    for (uint32_t n = 0; n < bvh.node_count; n++) {
        const struct sb_bvh_node *node = &bvh.nodes[n];
        if (node->count) {
            leaves++;
            for (uint32_t i = node->first; i < node->first + node->count; i++) {
                const struct sb_bvh_triangle *t = &bvh.triangles[i];
                bad += seen[t->triangle]++ != 0;
                float p[3][3];
                for (int c = 0; c < 3; c++) {
                    p[0][c] = t->v0[c];
                    p[1][c] = t->v0[c] + t->e1[c];
                    p[2][c] = t->v0[c] + t->e2[c];
                }
                for (int k = 0; k < 3; k++)
                    for (int c = 0; c < 3; c++)
                        bad += p[k][c] < node->min[c] || p[k][c] > node->max[c];
            }
            if (node->count > SB_BVH_MAX_LEAF && bvh.depth < SB_BVH_MAX_DEPTH)
                bad++;
        } else {
            for (int ch = 0; ch < 2; ch++) {
                const struct sb_bvh_node *c = &bvh.nodes[node->first + ch];
                bad += node->first + ch >= bvh.node_count;
                for (int k = 0; k < 3; k++)
                    bad += c->min[k] < node->min[k] || c->max[k] > node->max[k];
            }
        }
    }
    uint32_t missing = 0;
    for (uint32_t t = 0; t < m->triangle_count; t++)
        missing += !seen[t];
    CHECK(!bad && !missing && bvh.depth <= SB_BVH_MAX_DEPTH, "%s: %u broken invariants, %u triangles missing", name,
          bad, missing);
    free(seen);

    /* CPU traversal against every triangle by the same fp32 test: equal. */
    struct sb_bvh flat = {0};
    struct sb_bvh_node root = {{0}, 0, {0}, bvh.triangle_count};
    memcpy(root.min, bvh.nodes[0].min, sizeof(root.min));
    memcpy(root.max, bvh.nodes[0].max, sizeof(root.max));
    flat.nodes = &root;
    flat.node_count = 1;
    flat.triangles = bvh.triangles;
    flat.triangle_count = bvh.triangle_count;
    uint32_t count = m->triangle_count > 20000 ? 200 : 2000, differ = 0;
    float *rays = malloc((size_t)count * 8 * sizeof(float));
    make_rays(m, RAYS_RANDOM, count, rays);
    for (uint32_t i = 0; i < count; i++) {
        struct sb_hit a, b;
        const float *r = &rays[8 * (size_t)i];
        bool ha = sb_bvh_intersect(&bvh, r, r + 4, r[3], r[7], false, &a);
        bool hb = sb_bvh_intersect(&flat, r, r + 4, r[3], r[7], false, &b);
        differ += ha != hb || (ha && a.t != b.t);
    }
    CHECK(differ == 0, "%s: the BVH's CPU traversal differs from brute force on %u of %u rays", name, differ, count);
    free(rays);
    sb_bvh_finish(&bvh);
    sb_bvh_finish(&again);
}

static void test_loading(void)
{
    struct sb_mesh house = {0}, moved = {0};
    CHECK(sb_mesh_load(IFC_HOUSE, NULL, &house) == SB_OK, "the IFC house loads");
    CHECK(house.triangle_count > 10000 && house.material_count >= 2, "the IFC house: %u triangles, %u materials",
          house.triangle_count, house.material_count);
    struct sb_mesh_load_params p = {.transform = {.units_m = 0.5, .scale = 4, .translate_m = {10, -2, 3}}};
    CHECK(sb_mesh_load(IFC_HOUSE, &p, &moved) == SB_OK, "the IFC house, moved");
    float lo0[3], hi0[3], lo1[3], hi1[3];
    sb_mesh_bounds(&house, lo0, hi0);
    sb_mesh_bounds(&moved, lo1, hi1);
    double worst = 0;
    for (int k = 0; k < 3; k++) {
        worst = fmax(worst, fabs(lo1[k] - (2.0 * lo0[k] + p.transform.translate_m[k])));
        worst = fmax(worst, fabs(hi1[k] - (2.0 * hi0[k] + p.transform.translate_m[k])));
    }
    CHECK(worst < 1e-4, "units, scale and translation: bounds off by %g m", worst);
    /* z up: the file's +z becomes +y (height), its +y becomes -z */
    struct sb_mesh turned = {0};
    p = (struct sb_mesh_load_params){.transform = {.up_z = true}};
    CHECK(sb_mesh_load(IFC_HOUSE, &p, &turned) == SB_OK, "the IFC house, z up");
    sb_mesh_bounds(&turned, lo1, hi1);
    CHECK(fabsf(hi1[1] - hi0[2]) < 1e-4f && fabsf(lo1[2] + hi0[1]) < 1e-4f, "up_z turns z into y");
    /* a rotation of 90 degrees about y: x -> -z */
    struct sb_mesh rotated = {0};
    p = (struct sb_mesh_load_params){.transform = {.rotate_deg = {0, 90, 0}}};
    CHECK(sb_mesh_load(IFC_HOUSE, &p, &rotated) == SB_OK, "the IFC house, rotated");
    sb_mesh_bounds(&rotated, lo1, hi1);
    CHECK(fabsf(lo1[2] + hi0[0]) < 1e-3f && fabsf(hi1[0] - hi0[2]) < 1e-3f, "rotate_deg y 90: x -> -z, z -> x");
    sb_mesh_finish(&turned);
    sb_mesh_finish(&rotated);

    /* materials: the file's colours, and overrides */
    struct sb_mesh_albedo_override all = {"*", {0.25, 0.5, 0.75}};
    p = (struct sb_mesh_load_params){.overrides = &all, .override_count = 1};
    uint32_t moved_count = moved.triangle_count;
    CHECK(sb_mesh_load(IFC_HOUSE, &p, &moved) == SB_OK, "appended to a mesh");
    bool overridden = true;
    for (uint32_t i = house.material_count; i < moved.material_count; i++)
        overridden &= moved.material_list[i].albedo[0] == 0.25f && moved.material_list[i].albedo[2] == 0.75f;
    CHECK(overridden && moved.triangle_count == moved_count + house.triangle_count, "override \"*\" and appending");
    bool distinct = false;
    for (uint32_t i = 1; i < house.material_count; i++)
        distinct |= memcmp(house.material_list[i].albedo, house.material_list[0].albedo, 12) != 0;
    CHECK(distinct, "the IFC house's materials carry their own colours");
    sb_mesh_finish(&moved);
    sb_mesh_finish(&house);

    const char *good[] = {MODELS "/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb", MODELS "/OBJ/box.obj",
                          MODELS "/glTF2/BoxTextured-glTF/BoxTextured.gltf", MODELS "/PLY/cube.ply"};
    for (size_t i = 0; i < sizeof(good) / sizeof(good[0]); i++) {
        struct sb_mesh m = {0};
        if (access(good[i], R_OK) != 0) {
            CHECK(false, "%s: missing (assimp-testmodels)", good[i]);
            continue;
        }
        enum sb_result res = sb_mesh_load(good[i], NULL, &m);
        CHECK(res == SB_OK && m.triangle_count >= 12, "%s: %s, %u triangles", good[i], sb_result_name(res),
              m.triangle_count);
        sb_mesh_finish(&m);
    }
}

/*
 * skybake's procedural world (data/worlds/test.json) through sb_mesh_load:
 * its triangle count from its boxes and pillars, a material each, the
 * ground receiving only, every box face wound outward, and the transform.
 */
static void test_world_file(void)
{
    struct sb_mesh m = {0}, moved = {0};
    CHECK(sb_mesh_load(TEST_WORLD, NULL, &m) == SB_OK, "%s loads as a mesh", TEST_WORLD);
    cJSON *root = NULL;
    CHECK(sb_json_load(AT_FDCWD, TEST_WORLD, TEST_WORLD, 1 << 20, true, &root) == SB_OK, "and as JSON");
    const cJSON *boxes = cJSON_GetObjectItemCaseSensitive(root, "boxes"), *pillars, *item;
    pillars = cJSON_GetObjectItemCaseSensitive(root, "pillars");
    uint32_t want = 2 + 12 * (uint32_t)cJSON_GetArraySize(boxes);
    cJSON_ArrayForEach(item, pillars)
    {
        want += 4 * (uint32_t)cJSON_GetObjectItemCaseSensitive(item, "sides")->valuedouble;
    }
    CHECK(m.triangle_count == want, "the test world: %u triangles, %u expected", m.triangle_count, want);
    CHECK(m.material_count == 1u + (uint32_t)cJSON_GetArraySize(boxes) + (uint32_t)cJSON_GetArraySize(pillars),
          "a material for the ground and each object (%u)", m.material_count);
    CHECK(m.material_count > 2 && !strcmp(m.material_list[0].name, "ground") && !m.material_list[0].casts_shadows &&
              !strcmp(m.material_list[1].name, "boxes[0]") && m.material_list[1].casts_shadows,
          "the ground receives only; objects cast");
    /* every box triangle's winding normal points away from its box's centre */
    int inward = 0, box = 0;
    cJSON_ArrayForEach(item, boxes)
    {
        const cJSON *c = cJSON_GetObjectItemCaseSensitive(item, "center_m");
        double centre[3];
        for (int k = 0; k < 3; k++)
            centre[k] = cJSON_GetArrayItem(c, k)->valuedouble;
        for (uint32_t t = 0; t < m.triangle_count; t++) {
            if (m.materials[t] != 1u + (uint32_t)box)
                continue;
            double p[3][3], e1[3], e2[3], n[3], out[3];
            for (int v = 0; v < 3; v++)
                for (int k = 0; k < 3; k++)
                    p[v][k] = m.positions[3 * m.indices[3 * t + v] + k];
            for (int k = 0; k < 3; k++) {
                e1[k] = p[1][k] - p[0][k];
                e2[k] = p[2][k] - p[0][k];
                out[k] = (p[0][k] + p[1][k] + p[2][k]) / 3 - centre[k];
            }
            cross3d(e1, e2, n);
            inward += dot3d(n, out) <= 0;
        }
        box++;
    }
    CHECK(inward == 0, "box faces wound outward (%d inward)", inward);
    cJSON_Delete(root);
    /* its ground reaches the extent cap: moved up it loads, moved sideways it is refused */
    struct sb_mesh_load_params p = {.transform = {.translate_m = {0, 1.5, 0}}};
    CHECK(sb_mesh_load(TEST_WORLD, &p, &moved) == SB_OK, "the test world, moved up");
    float lo0[3], hi0[3], lo1[3], hi1[3];
    sb_mesh_bounds(&m, lo0, hi0);
    sb_mesh_bounds(&moved, lo1, hi1);
    CHECK(lo1[0] == lo0[0] && lo1[1] == lo0[1] + 1.5f && hi1[1] == hi0[1] + 1.5f, "a world file takes the transform");
    p.transform.translate_m[0] = 5;
    uint32_t before = moved.triangle_count;
    CHECK(sb_mesh_load(TEST_WORLD, &p, &moved) == SB_ERR_NUMERIC && moved.triangle_count == before,
          "a ground moved past the extent cap is refused, and the mesh is kept");
    sb_mesh_finish(&m);
    sb_mesh_finish(&moved);
}

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

/* Glass is an opening: the triangles of a material whose opacity is under
 * one half (an OBJ's d, IFC's transparency) are left out, those of one
 * over it kept; the IFC house keeps none of its panes ("Glas", 0.12). */
static void test_glass(void)
{
    char dir[256], path[300];
    CHECK(test_temp_dir("skybake-glass", dir, sizeof(dir)), "temporary directory");
    snprintf(path, sizeof(path), "%s/panes.mtl", dir);
    write_file(path, "newmtl wall\nKd 0.5 0.5 0.5\nnewmtl glass\nKd 0.1 0.1 0.1\nd 0.12\n"
                     "newmtl frosted\nKd 0.8 0.8 0.8\nd 0.6\n");
    snprintf(path, sizeof(path), "%s/panes.obj", dir);
    write_file(path, "mtllib panes.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 0 0 2\nv 1 0 2\n"
                     "v 0 1 2\nusemtl wall\nf 1 2 3\nusemtl glass\nf 4 5 6\nusemtl frosted\nf 7 8 9\n");
    struct sb_mesh m = {0};
    CHECK(sb_mesh_load(path, NULL, &m) == SB_OK, "panes.obj loads");
    bool wall = false, frosted = false, glass = false;
    for (uint32_t t = 0; t < m.triangle_count; t++) {
        const char *name = m.material_list[m.materials[t]].name;
        wall |= !strcmp(name, "wall");
        frosted |= !strcmp(name, "frosted");
        glass |= !strcmp(name, "glass");
    }
    CHECK(m.triangle_count == 2 && wall && frosted && !glass, "the glass pane left out, the rest kept: %u triangles",
          m.triangle_count);
    sb_mesh_finish(&m);
    unlink(path);
    snprintf(path, sizeof(path), "%s/panes.mtl", dir);
    unlink(path);
    rmdir(dir);
    struct sb_mesh house = {0};
    CHECK(sb_mesh_load(IFC_HOUSE, NULL, &house) == SB_OK, "the IFC house loads");
    uint32_t panes = 0;
    for (uint32_t t = 0; t < house.triangle_count; t++)
        panes += !strcmp(house.material_list[house.materials[t]].name, "Glas");
    CHECK(panes == 0, "the IFC house's panes are left out: %u triangles of Glas", panes);
    sb_mesh_finish(&house);
}

/* A scene's world from a mesh file: `ground_json` ("" for the default) in
 * its world section, loaded as the baker and skyview load it. */
static enum sb_result load_scene_world(const char *dir, const char *file, const char *ground_json, struct sb_mesh *m)
{
    char json[512];
    snprintf(json, sizeof(json), "{\"atmosphere\":{\"preset\":\"earth\"},\"world\":{\"file\":\"%s\"%s}}", file,
             ground_json);
    struct sb_scene *scene = malloc(sizeof(*scene));
    enum sb_result res = scene ? sb_scene_parse(json, strlen(json), "ground test", scene) : SB_ERR_NOMEM;
    if (!res)
        res = sb_mesh_load_world(&scene->world, dir, m, NULL, 0);
    free(scene);
    return res;
}

/* The ground's two triangles: material "ground" that casts no shadow, facing
 * up, all at height y, spanning side x side centred on (cx, cz). */
static bool is_ground(const struct sb_mesh *m, double y, double side, double cx, double cz)
{
    if (m->triangle_count < 2)
        return false;
    uint32_t g = m->materials[m->triangle_count - 1];
    bool ok = !strcmp(m->material_list[g].name, "ground") && !m->material_list[g].casts_shadows &&
              m->materials[m->triangle_count - 2] == g;
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (uint32_t t = m->triangle_count - 2; t < m->triangle_count; t++) {
        const float *p[3];
        for (int k = 0; k < 3; k++) {
            p[k] = &m->positions[3 * (size_t)m->indices[3 * (size_t)t + k]];
            ok = ok && fabs(p[k][1] - y) < 1e-4;
            lo[0] = fmin(lo[0], p[k][0]), hi[0] = fmax(hi[0], p[k][0]);
            lo[1] = fmin(lo[1], p[k][2]), hi[1] = fmax(hi[1], p[k][2]);
        }
        double up = ((double)p[2][0] - p[0][0]) * (p[1][2] - p[0][2]) - ((double)p[1][0] - p[0][0]) * (p[2][2] - p[0][2]);
        ok = ok && up > 0;
    }
    return ok && fabs(hi[0] - lo[0] - side) < 1e-3 && fabs(hi[1] - lo[1] - side) < 1e-3 &&
           fabs(0.5 * (lo[0] + hi[0]) - cx) < 1e-3 && fabs(0.5 * (lo[1] + hi[1]) - cz) < 1e-3;
}

/* A model from a mesh file stands on a ground: at its lowest point or 0,
 * under it, 4 times its width or 100 m; none under a model with a ground of
 * its own, none with "ground": false, where and how large the scene says
 * otherwise; a world file's own is its own. */
static void test_ground(void)
{
    char dir[256], path[300];
    CHECK(test_temp_dir("skybake-ground", dir, sizeof(dir)), "temporary directory");
    /* a cube floating from y 1 to 2 over x 30..32, z -5..-3 */
    snprintf(path, sizeof(path), "%s/cube.obj", dir);
    write_file(path, "v 30 1 -5\nv 32 1 -5\nv 32 2 -5\nv 30 2 -5\nv 30 1 -3\nv 32 1 -3\nv 32 2 -3\nv 30 2 -3\n"
                     "f 1 2 3 4\nf 5 8 7 6\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n");
    /* a slab from y -3 with its own floor under all of it, and a post */
    snprintf(path, sizeof(path), "%s/floored.obj", dir);
    write_file(path, "v -50 -3 -50\nv -50 -3 50\nv 50 -3 50\nv 50 -3 -50\nf 1 2 3\nf 1 3 4\n"
                     "v 0 -3 0\nv 1 -3 0\nv 0 5 0\nf 5 6 7\n");
    struct sb_mesh m = {0};
    CHECK(load_scene_world(dir, "cube.obj", "", &m) == SB_OK && m.triangle_count == 14 &&
              is_ground(&m, 0.0, 100.0, 31.0, -4.0),
          "a floating cube stands on a ground at 0, 100 m wide, under it (%u triangles)", m.triangle_count);
    float lo[3], hi[3];
    CHECK(sb_mesh_bounds_casting(&m, lo, hi) && lo[0] == 30.0f && hi[2] == -3.0f && lo[1] == 1.0f,
          "the casters' bounds leave the ground out");
    sb_mesh_finish(&m);
    CHECK(load_scene_world(dir, "cube.obj", ",\"ground\":false", &m) == SB_OK && m.triangle_count == 12,
          "\"ground\": false: none");
    sb_mesh_finish(&m);
    CHECK(load_scene_world(dir, "cube.obj", ",\"ground\":{\"height_m\":-2,\"size_m\":50,\"albedo\":[0.5,0.4,0.3]}",
                           &m) == SB_OK &&
              is_ground(&m, -2.0, 50.0, 31.0, -4.0) &&
              fabsf(m.material_list[m.materials[12]].albedo[1] - 0.4f) < 1e-6f,
          "the ground the scene gives: its height, size and albedo");
    sb_mesh_finish(&m);
    CHECK(load_scene_world(dir, "floored.obj", "", &m) == SB_OK && m.triangle_count == 3,
          "a model with a floor of its own at its lowest point stands on that (%u triangles)", m.triangle_count);
    sb_mesh_finish(&m);
    CHECK(load_scene_world(dir, "floored.obj", ",\"ground\":{}", &m) == SB_OK && m.triangle_count == 5 &&
              is_ground(&m, -3.0, 400.0, 0.0, 0.0),
          "a ground asked for goes under it anyway, at its lowest point");
    sb_mesh_finish(&m);
    struct sb_scene *scene = malloc(sizeof(*scene));
    static const char world_file[] =
        "{\"atmosphere\":{\"preset\":\"earth\"},\"world\":{\"file\":\"w.json\",\"ground\":false}}";
    CHECK(scene && sb_scene_parse(world_file, sizeof(world_file) - 1, "ground test", scene) == SB_ERR_OUT_OF_RANGE,
          "a world file with world.ground is a scene error");
    free(scene);
}

static void test_hostile(void)
{
    char dir[256], path[300];
    CHECK(test_temp_dir("skybake-geometry", dir, sizeof(dir)), "temporary directory");
    struct {
        const char *name, *text;
        enum sb_result want;
    } cases[] = {
        {"nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n", SB_ERR_NUMERIC},
        {"huge.obj", "v 0 0 0\nv 1 0 0\nv 1e30 1 0\nf 1 2 3\n", SB_ERR_NUMERIC},
        {"degenerate.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 1 2\n", SB_ERR_MESH},
        {"lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nl 2 3\n", SB_ERR_MESH},
        {"points.obj", "v 0 0 0\nv 1 0 0\np 1\n", SB_ERR_MESH},
        {"empty.obj", "", SB_ERR_MESH},
        {"garbage.glb", "glTF\x02\x00\x00\x00\xff\xff\xff\xff garbage", SB_ERR_MESH},
        {"garbage.ply", "ply\nformat ascii 1.0\nelement vertex 99999999999\n", SB_ERR_MESH},
        {"index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", SB_ERR_MESH},
        /* skybake world files, through the same call */
        {"syntax.json", "{\"version\": 1,", SB_ERR_JSON_SYNTAX},
        {"key.json", "{\"version\": 1, \"sky\": 1}", SB_ERR_UNKNOWN_KEY},
        {"twice.json", "{\"version\": 1, \"version\": 1}", SB_ERR_DUPLICATE_KEY},
        {"version.json", "{\"version\": 2}", SB_ERR_OUT_OF_RANGE},
        {"ground.json", "{\"version\": 1, \"ground\": {\"size_m\": 30000}}", SB_ERR_OUT_OF_RANGE},
        {"far.json", "{\"version\": 1, \"boxes\": [{\"center_m\": [9999, 0, 0], \"size_m\": [10, 1, 1]}]}",
         SB_ERR_NUMERIC},
        {"sides.json",
         "{\"version\": 1, \"pillars\": [{\"base_m\": [0, 0, 0], \"radius_m\": 1, \"height_m\": 1, "
         "\"sides\": 2.5}]}",
         SB_ERR_OUT_OF_RANGE},
        {"albedo.json",
         "{\"version\": 1, \"boxes\": [{\"center_m\": [0, 0, 0], \"size_m\": [1, 1, 1], "
         "\"albedo\": [2, 0, 0]}]}",
         SB_ERR_OUT_OF_RANGE},
    };
    struct sb_mesh m = {0};
    uint32_t material;
    double grey[3] = {0.5, 0.5, 0.5};
    sb_mesh_add_material(&m, "before", grey, &material);
    double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 0, -1};
    sb_mesh_add_triangle(&m, a, b, c, material, "test");
    for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
        snprintf(path, sizeof(path), "%s/%s", dir, cases[i].name);
        write_file(path, cases[i].text);
        enum sb_result res = sb_mesh_load(path, &(struct sb_mesh_load_params){.time_limit_s = 5}, &m);
        /* assimp may refuse a file itself (mesh) where we would have (numeric, mesh) */
        CHECK(res == cases[i].want || (res == SB_ERR_MESH && cases[i].want != SB_OK), "%s: %s, expected %s",
              cases[i].name, sb_result_name(res), sb_result_name(cases[i].want));
        CHECK(m.triangle_count == 1 && m.material_count == 1, "%s: the mesh changed on failure (%u triangles)",
              cases[i].name, m.triangle_count);
        unlink(path);
    }
    /* files that are not there, not files, or too large to read */
    snprintf(path, sizeof(path), "%s/missing.obj", dir);
    CHECK(sb_mesh_load(path, NULL, &m) == SB_ERR_IO, "a missing file");
    CHECK(sb_mesh_load(dir, NULL, &m) == SB_ERR_IO, "a directory");
    /* FIFOs, as the mesh or named by it (an OBJ's mtllib, a glTF's buffer),
     * are refused at once: an open of one would block until a writer came */
    char fifo[600];
    snprintf(fifo, sizeof(fifo), "%s/fifo.bin", dir);
    CHECK(mkfifo(fifo, 0600) == 0, "a FIFO");
    CHECK(sb_mesh_load(fifo, NULL, &m) == SB_ERR_IO, "a FIFO as the mesh");
    static const struct {
        const char *name, *text;
    } named[] = {
        {"fifo.obj", "mtllib fifo.bin\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"},
        {"fifo.gltf",
         "{\"asset\": {\"version\": \"2.0\"}, \"buffers\": [{\"uri\": \"fifo.bin\", \"byteLength\": 36}], "
         "\"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}], \"accessors\": [{\"bufferView\": 0, "
         "\"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [1, 1, 0]}], "
         "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}}]}], \"nodes\": [{\"mesh\": 0}], "
         "\"scenes\": [{\"nodes\": [0]}], \"scene\": 0}"},
    };
    for (size_t i = 0; i < sizeof(named) / sizeof(named[0]); i++) {
        snprintf(path, sizeof(path), "%s/%s", dir, named[i].name);
        write_file(path, named[i].text);
        struct timespec t0, t1;
        clock_gettime(CLOCK_MONOTONIC, &t0);
        struct sb_mesh f = {0};
        enum sb_result res = sb_mesh_load(path, &(struct sb_mesh_load_params){.time_limit_s = 60}, &f);
        clock_gettime(CLOCK_MONOTONIC, &t1);
        double took = (t1.tv_sec - t0.tv_sec) + 1e-9 * (t1.tv_nsec - t0.tv_nsec);
        /* the OBJ loads without its material library, as with a missing one; the glTF has no buffer */
        CHECK(took < 30 && (i == 0 ? res == SB_OK && f.triangle_count == 1 : res == SB_ERR_MESH),
              "%s, naming a FIFO: %s in %.1f s", named[i].name, sb_result_name(res), took);
        sb_mesh_finish(&f);
        unlink(path);
    }
    unlink(fifo);
    snprintf(path, sizeof(path), "%s/big.obj", dir);
    int fd = open(path, O_CREAT | O_WRONLY, 0600);
    CHECK(fd >= 0 && ftruncate(fd, (off_t)(2ull << 30)) == 0, "a sparse 2 GiB file");
    if (fd >= 0)
        close(fd);
    CHECK(sb_mesh_load(path, NULL, &m) == SB_ERR_TOO_LARGE, "a 2 GiB file is refused before it is read");
    unlink(path);
    /* assimp-testmodels' broken glTF files */
    const char *broken[] = {
        MODELS "/glTF2/BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb",
        MODELS "/glTF2/IndexOutOfRange/AllIndicesOutOfRange.gltf", MODELS "/glTF2/MissingBin/BoxTextured.gltf",
        MODELS "/glTF2/RecursiveNodes/RecursiveNodes.gltf", MODELS "/glTF2/SchemaFailures/sceneWrongType.gltf"};
    for (size_t i = 0; i < sizeof(broken) / sizeof(broken[0]); i++) {
        enum sb_result res = sb_mesh_load(broken[i], NULL, &m);
        CHECK(res != SB_OK && m.triangle_count == 1, "%s: %s, %u triangles", broken[i], sb_result_name(res),
              m.triangle_count);
    }
    /* assimp drops the faces whose indices are out of range and keeps the rest */
    struct sb_mesh repaired = {0};
    CHECK(sb_mesh_load(MODELS "/glTF2/IndexOutOfRange/IndexOutOfRange.gltf", NULL, &repaired) == SB_OK &&
              repaired.triangle_count == 11,
          "IndexOutOfRange.gltf: the 11 valid triangles of 12 (%u)", repaired.triangle_count);
    sb_mesh_finish(&repaired);
    /* code-made triangles meet the same checks */
    double nan3[3] = {NAN, 0, 0};
    CHECK(sb_mesh_add_triangle(&m, nan3, b, c, material, "test") == SB_ERR_NUMERIC, "a NaN vertex from code");
    CHECK(sb_mesh_add_triangle(&m, a, b, c, 7, "test") == SB_ERR_OUT_OF_RANGE, "an unknown material");
    CHECK(sb_mesh_add_triangle(&m, a, a, c, material, "test") == SB_OK && m.dropped_degenerate == 1,
          "a zero-area triangle is dropped and counted");
    struct sb_mesh empty = {0};
    struct sb_bvh bvh;
    CHECK(sb_bvh_build(&empty, &bvh) == SB_ERR_MESH, "a BVH over no triangle");
    sb_mesh_finish(&m);
    rmdir(dir);
}

/* Many triangles with one centroid, more than one thread's share: the
 * builder must still halve them. */
static void test_coincident(void)
{
    struct sb_mesh m = {0};
    uint32_t mat;
    double grey[3] = {0.5, 0.5, 0.5};
    sb_mesh_add_material(&m, "grey", grey, &mat);
    for (int i = 0; i < 70000; i++) {
        double s = 1 + i * 1e-5;
        double a[3] = {-s, 0, -s}, b[3] = {s, 0, -s}, c[3] = {0, 0, 2 * s};
        sb_mesh_add_triangle(&m, a, b, c, mat, "coincident");
    }
    test_bvh_structure("coincident", &m);
    sb_mesh_finish(&m);
}

/* ---- levels: world files that place files --------------------------------------------------- */

/* What the log said while capturing (warnings and errors). */
struct captured {
    char text[2048];
};

static void capture_sink(void *user, enum sb_log_level level, const char *message)
{
    struct captured *c = user;
    size_t n = strlen(c->text);
    if (level <= SB_LOG_WARN && n < sizeof(c->text) - 1)
        snprintf(c->text + n, sizeof(c->text) - n, "%s\n", message);
}

static void capture_begin(struct captured *c)
{
    c->text[0] = '\0';
    sb_log_set_sink(capture_sink, c);
}

static void capture_end(void)
{
    sb_log_set_sink(NULL, NULL);
}

/* ---- textures ---------------------------------------------------------------------------- */

static uint32_t crc32_of(const uint8_t *p, size_t n)
{
    uint32_t c = 0xffffffffu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++)
            c = c >> 1 ^ (0xedb88320u & (0u - (c & 1)));
    }
    return ~c;
}

/* A PNG of a signature, an IHDR and an empty IDAT: what a decoder reads
 * before any texel. */
static void write_png_header(const char *path, uint32_t width, uint32_t height, uint8_t colour_type)
{
    uint8_t b[33 + 12] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R'};
    for (int i = 0; i < 4; i++) {
        b[16 + i] = (uint8_t)(width >> (24 - 8 * i));
        b[20 + i] = (uint8_t)(height >> (24 - 8 * i));
    }
    b[24] = 8; /* bit depth */
    b[25] = colour_type;
    uint32_t crc = crc32_of(b + 12, 17);
    for (int i = 0; i < 4; i++)
        b[29 + i] = (uint8_t)(crc >> (24 - 8 * i));
    memcpy(b + 37, "IDAT", 4);
    crc = crc32_of(b + 37, 4);
    for (int i = 0; i < 4; i++)
        b[41 + i] = (uint8_t)(crc >> (24 - 8 * i));
    FILE *f = fopen(path, "wb");
    fwrite(b, 1, sizeof(b), f);
    fclose(f);
}

/* A glTF of one triangle with texture coordinates, its material's base
 * colour the image `uri`. */
static void write_textured_gltf(const char *dir, const char *name, const char *uri)
{
    char path[512];
    const float data[15] = {0, 0, 0, 1, 0, 0, 0, 0, -1, /* positions */
                            0.25f, 0.25f, 0.75f, 0.25f, 0.25f, 1.0f};
    snprintf(path, sizeof(path), "%s/tri.bin", dir);
    FILE *f = fopen(path, "wb");
    fwrite(data, 1, sizeof(data), f);
    fclose(f);
    char text[2048];
    snprintf(text, sizeof(text),
             "{\"asset\": {\"version\": \"2.0\"}, \"buffers\": [{\"uri\": \"tri.bin\", \"byteLength\": 60}], "
             "\"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}, {\"buffer\": 0, \"byteOffset\": 36, "
             "\"byteLength\": 24}], \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, "
             "\"type\": \"VEC3\", \"min\": [0, 0, -1], \"max\": [1, 0, 0]}, {\"bufferView\": 1, "
             "\"componentType\": 5126, \"count\": 3, \"type\": \"VEC2\"}], \"images\": [{\"uri\": \"%s\"}], "
             "\"textures\": [{\"source\": 0}], \"materials\": [{\"name\": \"painted\", \"pbrMetallicRoughness\": "
             "{\"baseColorTexture\": {\"index\": 0}}}], \"meshes\": [{\"primitives\": [{\"attributes\": "
             "{\"POSITION\": 0, \"TEXCOORD_0\": 1}, \"material\": 0}]}], \"nodes\": [{\"mesh\": 0}], "
             "\"scenes\": [{\"nodes\": [0]}], \"scene\": 0}",
             uri);
    snprintf(path, sizeof(path), "%s/%s", dir, name);
    write_file(path, text);
}

/* Images a model names: decoded with the texture coordinates, and hostile
 * ones (truncated, huge, of no layout PNG has, not an image, outside the
 * model's folder) refused, naming the model and the image, the mesh left
 * as it was. */
static void test_textures(void)
{
    char dir[256], sub[300], path[600], model[600];
    CHECK(test_temp_dir("skybake-textures", dir, sizeof(dir)), "temporary directory");
    snprintf(sub, sizeof(sub), "%s/model", dir);
    CHECK(mkdir(sub, 0700) == 0, "a model folder");
    /* 4 x 2 texels: red, green, blue, white; then grey */
    uint8_t rgba[4 * 8] = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255};
    for (int i = 16; i < 32; i++)
        rgba[i] = i % 4 == 3 ? 255 : 128;
    snprintf(path, sizeof(path), "%s/good.png", sub);
    CHECK(sb_png_write(path, 4, 2, rgba) == SB_OK, "a PNG");
    snprintf(model, sizeof(model), "%s/good.gltf", sub);
    write_textured_gltf(sub, "good.gltf", "good.png");
    struct sb_mesh m = {0};
    enum sb_result res = sb_mesh_load(model, NULL, &m);
    CHECK(res == SB_OK && m.texture_count == 1 && m.uvs, "a textured glTF: %s, %u textures", sb_result_name(res),
          m.texture_count);
    if (!res && m.texture_count == 1 && m.uvs) {
        const struct sb_mesh_texture *t = &m.texture_list[0];
        CHECK(t->width == 4 && t->height == 2 && t->srgb && !memcmp(t->rgba, rgba, sizeof(rgba)),
              "the image's texels, as written (%u x %u)", t->width, t->height);
        CHECK(m.material_list[0].textures[SB_TEXTURE_BASE_COLOR] == 0, "the material's base colour texture");
        /* glTF's v runs down the image; the mesh's up (assimp turns it) */
        CHECK(m.uvs[0] == 0.25f && m.uvs[1] == 0.75f && m.uvs[5] == 0.0f, "texture coordinates (%g, %g) (%g)",
              m.uvs[0], m.uvs[1], m.uvs[5]);
    }
    char before[33], after[33];
    sb_mesh_hash(&m, before);

    /* a valid image, then broken copies of it */
    char *good = NULL;
    size_t good_size = 0;
    sb_read_file(AT_FDCWD, path, "good.png", 1 << 20, false, &good, &good_size);
    snprintf(path, sizeof(path), "%s/outside.png", dir);
    sb_png_write(path, 4, 2, rgba);
    free(good);
    /* cut inside its texels: the header reads, the texels end early */
    uint8_t *noise = malloc(4 * 64 * 64);
    for (int i = 0; i < 4 * 64 * 64; i++)
        noise[i] = (uint8_t)(i * 2654435761u >> 24);
    snprintf(path, sizeof(path), "%s/noise.png", sub);
    sb_png_write(path, 64, 64, noise);
    free(noise);
    sb_read_file(AT_FDCWD, path, "noise.png", 1 << 20, false, &good, &good_size);
    snprintf(path, sizeof(path), "%s/truncated.png", sub);
    FILE *f = fopen(path, "wb");
    fwrite(good, 1, good_size * 3 / 4, f);
    fclose(f);
    free(good);
    snprintf(path, sizeof(path), "%s/huge.png", sub);
    write_png_header(path, 65535, 65535, 6);
    snprintf(path, sizeof(path), "%s/layout.png", sub);
    write_png_header(path, 4, 4, 5); /* colour type 5: no such channel layout */
    snprintf(path, sizeof(path), "%s/text.png", sub);
    write_file(path, "not an image at all");
    char target[600];
    snprintf(target, sizeof(target), "%s/outside.png", dir);
    snprintf(path, sizeof(path), "%s/link.png", sub);
    CHECK(symlink(target, path) == 0, "a link out of the folder");
    static const struct {
        const char *uri;
        enum sb_result want;
        const char *says;
    } cases[] = {
        {"truncated.png", SB_ERR_IO, "libpng cannot read it"},
        {"huge.png", SB_ERR_TOO_LARGE, "65535 x 65535 texels"},
        {"layout.png", SB_ERR_IO, "libpng cannot read it"},
        {"text.png", SB_ERR_IO, "neither PNG nor JPEG"},
        {"../outside.png", SB_ERR_UNSAFE_PATH, "outside the model's folder"},
        {"link.png", SB_ERR_UNSAFE_PATH, "outside the model's folder"},
        {"/etc/passwd", SB_ERR_UNSAFE_PATH, "outside the model's folder"},
        {"missing.png", SB_ERR_IO, "missing.png"},
    };
    for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
        write_textured_gltf(sub, "hostile.gltf", cases[i].uri);
        snprintf(model, sizeof(model), "%s/hostile.gltf", sub);
        struct captured log;
        capture_begin(&log);
        res = sb_mesh_load(model, &(struct sb_mesh_load_params){.time_limit_s = 20}, &m);
        capture_end();
        sb_mesh_hash(&m, after);
        CHECK(res == cases[i].want && strstr(log.text, model) && strstr(log.text, cases[i].uri) &&
                  strstr(log.text, cases[i].says),
              "%s: %s, expected %s saying \"%s\", naming the model and the image: %s", cases[i].uri,
              sb_result_name(res), sb_result_name(cases[i].want), cases[i].says, log.text);
        CHECK(!strcmp(before, after) && m.texture_count == 1, "%s: the mesh changed on failure", cases[i].uri);
    }
    sb_mesh_finish(&m);
    char rm[700];
    snprintf(rm, sizeof(rm), "rm -rf '%s'", dir);
    CHECK(system(rm) == 0, "removing %s", dir);
}

/* A level from a scene whose world is `file` in `dir`. */
static enum sb_result load_level(const char *dir, const char *file, struct sb_level *level)
{
    char json[512];
    snprintf(json, sizeof(json), "{\"atmosphere\":{\"preset\":\"earth\"},\"world\":{\"file\":\"%s\"}}", file);
    struct sb_scene *scene = malloc(sizeof(*scene));
    enum sb_result res = scene ? sb_scene_parse(json, strlen(json), "level test", scene) : SB_ERR_NOMEM;
    if (!res)
        res = sb_level_load(&scene->world, dir, level, NULL, 0);
    else
        memset(level, 0, sizeof(*level));
    free(scene);
    return res;
}

/* The centre of the nth run of triangles of material `name` in a
 * flattened level (a copy's triangles lie together). */
static bool material_centre(const struct sb_mesh *m, const char *name, uint32_t nth, double centre[3])
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    uint32_t runs = 0;
    bool in_run = false;
    for (uint32_t t = 0; t < m->triangle_count; t++) {
        bool match = !strcmp(m->material_list[m->materials[t]].name, name);
        runs += match && !in_run;
        in_run = match;
        if (!match || runs != nth + 1)
            continue;
        for (int k = 0; k < 3; k++)
            for (int i = 0; i < 3; i++) {
                double v = m->positions[3 * (size_t)m->indices[3 * (size_t)t + k] + i];
                lo[i] = fmin(lo[i], v);
                hi[i] = fmax(hi[i], v);
            }
    }
    for (int i = 0; i < 3; i++)
        centre[i] = 0.5 * (lo[i] + hi[i]);
    return isfinite(lo[0]);
}

/*
 * A world file that places a world file (a box of its own and an OBJ
 * cube) twice and scatters the cube: each file read once, the copies where
 * the transforms compose to, the scatter on the ground, the same BVH bytes
 * on 1 and 3 threads; and every way such files can be wrong refused
 * before anything is allocated for it, naming the file.
 */
static void test_levels(void)
{
    char dir[256], path[400];
    CHECK(test_temp_dir("skybake-level", dir, sizeof(dir)), "temporary directory");
    snprintf(path, sizeof(path), "%s/cube.obj", dir);
    write_file(path, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                     "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n");
    snprintf(path, sizeof(path), "%s/house.json", dir);
    write_file(path, "{\"version\": 1, \"ground\": false, \"boxes\": [{\"center_m\": [2, 1, 0], \"size_m\": [1, 2, 1]}],"
                     " \"instances\": [{\"file\": \"cube.obj\", \"translate_m\": [0, 0, 5]}]}");
    snprintf(path, sizeof(path), "%s/world.json", dir);
    write_file(path, "{\"version\": 1, \"ground\": {\"size_m\": 400},"
                     " \"instances\": [{\"file\": \"house.json\", \"translate_m\": [30, 0, 0], \"rotate_deg\": [0, 90, 0]},"
                     "  {\"file\": \"house.json\", \"translate_m\": [-30, 0, 10], \"scale\": 2}],"
                     " \"scatter\": [{\"file\": \"cube.obj\", \"count\": 40, \"seed\": 7, \"area_m\": [-50, -50, 50, 50],"
                     "  \"scale\": [0.5, 1.5]}]}");
    struct sb_level level;
    enum sb_result res = load_level(dir, "world.json", &level);
    CHECK(res == SB_OK, "a level: %s", sb_result_name(res));
    /* meshes: the ground, the house's box, the cube (read once for 42 copies) */
    CHECK(level.mesh_count == 3 && level.instance_count == 1 + 2 * 2 + 40,
          "a level: %u meshes, %u instances (3 and 45)", level.mesh_count, level.instance_count);
    CHECK(level.placed_triangles == 2 + 2 * 12 + 2 * 12 + 40 * 12, "a level: %llu placed triangles",
          (unsigned long long)level.placed_triangles);
    struct sb_mesh flat = {0};
    CHECK(!res && sb_level_flatten(&level, &flat) == SB_OK && flat.triangle_count == level.placed_triangles,
          "flattened: %u triangles", flat.triangle_count);
    /* the house's box (2, 1, 0) turned 90 degrees about y: (0, 1, -2); then moved (30, 0, 0) */
    double c[3], c2[3];
    CHECK(material_centre(&flat, "boxes[0]", 0, c) && fabs(c[0] - 30) < 1e-4 && fabs(c[1] - 1) < 1e-4 &&
              fabs(c[2] + 2) < 1e-4,
          "the first house's box at (%g, %g, %g), expected (30, 1, -2)", c[0], c[1], c[2]);
    /* the second: scaled 2, moved (-30, 0, 10): (-26, 2, 10) */
    CHECK(material_centre(&flat, "boxes[0]", 1, c2) && fabs(c2[0] + 26) < 1e-4 && fabs(c2[1] - 2) < 1e-4 &&
              fabs(c2[2] - 10) < 1e-4,
          "the second house's box at (%g, %g, %g), expected (-26, 2, 10)", c2[0], c2[1], c2[2]);
    /* every scattered cube stands on the ground (y 0) */
    struct sb_bvh bvh = {0}, again = {0};
    float lo[3], hi[3];
    CHECK(sb_level_bounds_casting(&level, lo, hi) && lo[1] > -1e-4f, "the level's casters from y %g", lo[1]);
    sb_parallel_set_threads(1);
    CHECK(sb_level_build_bvh(&level, &bvh) == SB_OK, "the level's BVH");
    sb_parallel_set_threads(3);
    CHECK(sb_level_build_bvh(&level, &again) == SB_OK, "the level's BVH, 3 threads");
    sb_parallel_set_threads(0);
    char h1[33], h2[33];
    sb_bvh_hash(&bvh, h1);
    sb_bvh_hash(&again, h2);
    CHECK(!strcmp(h1, h2) && bvh.instance_count == level.instance_count, "the level's BVH on 1 and 3 threads: %s, %s",
          h1, h2);
    /* rays straight down agree with the flattened copy's */
    struct sb_bvh flat_bvh = {0};
    CHECK(sb_bvh_build(&flat, &flat_bvh) == SB_OK, "the flattened BVH");
    uint32_t differ = 0;
    for (int i = 0; i < 4000 && flat_bvh.nodes; i++) {
        float o[3] = {(float)(-60 + 120 * uniform()), 50.0f, (float)(-60 + 120 * uniform())}, d[3] = {0, -1, 0};
        struct sb_hit a, b;
        sb_bvh_intersect(&bvh, o, d, 0, 1e30f, false, &a);
        sb_bvh_intersect(&flat_bvh, o, d, 0, 1e30f, false, &b);
        differ += (a.triangle == SB_BVH_MISS) != (b.triangle == SB_BVH_MISS) || fabsf(a.t - b.t) > 1e-3f;
    }
    CHECK(differ == 0, "rays down: %u of 4000 differ between the level and its flattened copy", differ);
    sb_bvh_finish(&flat_bvh);
    sb_bvh_finish(&bvh);
    sb_bvh_finish(&again);
    sb_mesh_finish(&flat);
    char hash[33], again_hash[33];
    sb_level_hash(&level, hash);
    sb_level_finish(&level);
    /* read again: the same scatter, the same hash */
    CHECK(load_level(dir, "world.json", &level) == SB_OK, "the level again");
    sb_level_hash(&level, again_hash);
    CHECK(!strcmp(hash, again_hash), "the level read twice hashes the same (%s, %s)", hash, again_hash);
    sb_level_finish(&level);

    /* a glTF whose nodes place its wheels twice: parts, the wheels once,
     * the copies where the flat import puts them */
    snprintf(path, sizeof(path), "%s/truck.json", dir);
    write_file(path, "{\"version\": 1, \"ground\": false, \"instances\": [{\"file\": \"" MODELS
                     "/glTF/CesiumMilkTruck/CesiumMilkTruck.gltf\", \"translate_m\": [3, 0, -2]}]}");
    struct sb_mesh truck = {0}, placed = {0};
    CHECK(sb_mesh_load(MODELS "/glTF/CesiumMilkTruck/CesiumMilkTruck.gltf",
                       &(struct sb_mesh_load_params){.transform = {.translate_m = {3, 0, -2}}}, &truck) == SB_OK,
          "the milk truck, flat");
    res = load_level(dir, "truck.json", &level);
    uint32_t unique = 0;
    for (uint32_t m = 0; m < level.mesh_count; m++)
        unique += level.meshes[m].triangle_count;
    CHECK(res == SB_OK && level.instance_count > level.mesh_count && unique < level.placed_triangles &&
              level.placed_triangles == truck.triangle_count,
          "the milk truck as parts: %u meshes (%u triangles) placed %u times, %llu triangles (flat: %u)",
          level.mesh_count, unique, level.instance_count, (unsigned long long)level.placed_triangles,
          truck.triangle_count);
    float flo[3], fhi[3], plo[3], phi[3];
    CHECK(!res && sb_level_flatten(&level, &placed) == SB_OK && sb_mesh_bounds(&placed, plo, phi) &&
              sb_mesh_bounds(&truck, flo, fhi) && fabsf(plo[0] - flo[0]) < 1e-4f && fabsf(phi[0] - fhi[0]) < 1e-4f &&
              fabsf(plo[1] - flo[1]) < 1e-4f && fabsf(phi[1] - fhi[1]) < 1e-4f && fabsf(plo[2] - flo[2]) < 1e-4f &&
              fabsf(phi[2] - fhi[2]) < 1e-4f,
          "the truck's parts placed where the flat import puts them: (%g %g %g)-(%g %g %g) against (%g %g %g)-(%g %g %g)",
          plo[0], plo[1], plo[2], phi[0], phi[1], phi[2], flo[0], flo[1], flo[2], fhi[0], fhi[1], fhi[2]);
    sb_mesh_finish(&truck);
    sb_mesh_finish(&placed);
    sb_level_finish(&level);

    /* the same glTF named as a scene's world, with its automatic ground:
     * parts and the ground one more, whose casters' box (the probes'
     * grid) is the flat import's exactly, as is its ground */
    {
        struct sb_mesh whole = {0};
        struct sb_world_params wp = {.units_m = 1, .scale = 1};
        snprintf(wp.file, sizeof(wp.file), "%s", MODELS "/glTF/CesiumMilkTruck/CesiumMilkTruck.gltf");
        res = sb_level_load(&wp, "", &level, NULL, 0);
        enum sb_result whole_res = sb_mesh_load_world(&wp, "", &whole, NULL, 0);
        float llo[3], lhi[3], mlo[3], mhi[3];
        CHECK(!res && !whole_res && level.instance_count == level.mesh_count + 1 &&
                  level.placed_triangles == whole.triangle_count && sb_level_bounds_casting(&level, llo, lhi) &&
                  sb_mesh_bounds_casting(&whole, mlo, mhi) && !memcmp(llo, mlo, sizeof(llo)) &&
                  !memcmp(lhi, mhi, sizeof(lhi)),
              "the milk truck as a world: %u meshes placed %u times, %llu triangles (flat %u); casters' box "
              "(%g %g %g)-(%g %g %g) against (%g %g %g)-(%g %g %g)",
              level.mesh_count, level.instance_count, (unsigned long long)level.placed_triangles, whole.triangle_count,
              llo[0], llo[1], llo[2], lhi[0], lhi[1], lhi[2], mlo[0], mlo[1], mlo[2], mhi[0], mhi[1], mhi[2]);
        float glo[3], ghi[3], plo2[3], phi2[3];
        struct sb_mesh placed_world = {0};
        CHECK(!res && sb_level_flatten(&level, &placed_world) == SB_OK && sb_mesh_bounds(&placed_world, plo2, phi2) &&
                  sb_mesh_bounds(&whole, glo, ghi) && !memcmp(plo2, glo, sizeof(glo)) && !memcmp(phi2, ghi, sizeof(ghi)),
              "its ground where the flat import puts it: (%g %g %g)-(%g %g %g) against (%g %g %g)-(%g %g %g)", plo2[0],
              plo2[1], plo2[2], phi2[0], phi2[1], phi2[2], glo[0], glo[1], glo[2], ghi[0], ghi[1], ghi[2]);
        sb_mesh_finish(&placed_world);
        sb_mesh_finish(&whole);
        sb_level_finish(&level);
    }

    /* terrain: cells x cells quads, within its height, facing up, the same for a seed */
    char terrain_hash[2][33];
    for (int k = 0; k < 2; k++) {
        snprintf(path, sizeof(path), "%s/terrain%d.json", dir, k);
        char text[256];
        snprintf(text, sizeof(text),
                 "{\"version\": 1, \"ground\": false, \"terrain\": {\"size_m\": 400, \"cells\": 50, "
                 "\"height_m\": 12, \"seed\": %d}}",
                 k ? 8 : 7);
        write_file(path, text);
        struct sb_mesh t = {0};
        CHECK(sb_mesh_load(path, NULL, &t) == SB_OK && t.triangle_count == 2 * 50 * 50, "terrain: %u triangles",
              t.triangle_count);
        float tlo[3], thi[3];
        uint32_t down = 0;
        for (uint32_t i = 0; i < t.triangle_count; i++) {
            const float *p0 = &t.positions[9 * (size_t)i], *p1 = p0 + 3, *p2 = p0 + 6;
            double e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]}, e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
            down += e1[2] * e2[0] - e1[0] * e2[2] <= 0; /* the normal's y */
        }
        CHECK(sb_mesh_bounds(&t, tlo, thi) && tlo[0] == -200 && thi[2] == 200 && tlo[1] >= -12 && thi[1] <= 12 &&
                  thi[1] - tlo[1] > 6 && down == 0,
              "terrain: x %g..%g, y %g..%g (hills within 12 m), %u triangles facing down", tlo[0], thi[0], tlo[1],
              thi[1], down);
        sb_mesh_hash(&t, terrain_hash[k]);
        sb_mesh_finish(&t);
    }
    CHECK(strcmp(terrain_hash[0], terrain_hash[1]) != 0, "terrain: another seed, other hills");

    /* a world that places nothing: one mesh, hashed as before */
    snprintf(path, sizeof(path), "%s/plain.json", dir);
    write_file(path, "{\"version\": 1, \"boxes\": [{\"center_m\": [0, 1, 0], \"size_m\": [1, 2, 1]}]}");
    struct sb_mesh plain = {0};
    CHECK(load_level(dir, "plain.json", &level) == SB_OK && level.instance_count == 0 && level.mesh_count == 1,
          "a world file that places nothing is one mesh");
    CHECK(load_scene_world(dir, "plain.json", "", &plain) == SB_OK, "the same read as a mesh");
    char a[33], b[33];
    sb_level_hash(&level, a);
    sb_mesh_hash(&plain, b);
    CHECK(!strcmp(a, b), "its level hash is its mesh's (%s, %s)", a, b);
    sb_mesh_finish(&plain);
    sb_level_finish(&level);

    /* refused, naming the file: a cycle, itself, too deep, too many, missing, wrong */
    static const struct {
        const char *name, *text, *says;
        enum sb_result want;
    } bad[] = {
        {"self.json", "{\"version\": 1, \"instances\": [{\"file\": \"self.json\"}]}", "places itself", SB_ERR_MESH},
        {"a.json", "{\"version\": 1, \"instances\": [{\"file\": \"b.json\"}]}", "places itself", SB_ERR_MESH},
        {"missing.json", "{\"version\": 1, \"instances\": [{\"file\": \"nowhere.obj\"}]}", "nowhere.obj", SB_ERR_IO},
        {"many.json",
         "{\"version\": 1, \"scatter\": [{\"file\": \"cube.obj\", \"count\": 1048576, \"area_m\": [0, 0, 1, 1]},"
         "{\"file\": \"cube.obj\", \"count\": 1048576, \"area_m\": [0, 0, 1, 1]},"
         "{\"file\": \"cube.obj\", \"count\": 1048576, \"area_m\": [0, 0, 1, 1]},"
         "{\"file\": \"cube.obj\", \"count\": 1048576, \"area_m\": [0, 0, 1, 1]},"
         "{\"file\": \"cube.obj\", \"count\": 1048576, \"area_m\": [0, 0, 1, 1]}]}",
         "over the cap", SB_ERR_TOO_LARGE},
        {"nested.json", "{\"version\": 1, \"instances\": [{\"file\": \"thousand.json\"}, {\"file\": \"thousand.json\"},"
                        "{\"file\": \"thousand.json\"}, {\"file\": \"thousand.json\"}, {\"file\": \"thousand.json\"}]}",
         "over the cap", SB_ERR_TOO_LARGE},
        {"nofile.json", "{\"version\": 1, \"instances\": [{\"translate_m\": [0, 0, 0]}]}", "file: missing",
         SB_ERR_MISSING_FIELD},
        {"key.json", "{\"version\": 1, \"instances\": [{\"file\": \"cube.obj\", \"skew\": 1}]}", "skew",
         SB_ERR_UNKNOWN_KEY},
        {"area.json", "{\"version\": 1, \"scatter\": [{\"file\": \"cube.obj\", \"count\": 3, \"area_m\": [1, 0, 0, 1]}]}",
         "area_m", SB_ERR_OUT_OF_RANGE},
    };
    snprintf(path, sizeof(path), "%s/b.json", dir);
    write_file(path, "{\"version\": 1, \"ground\": false, \"instances\": [{\"file\": \"a.json\"}]}");
    /* 5 x 1000 x 1000 cubes, none of the files large */
    snprintf(path, sizeof(path), "%s/kilo.json", dir);
    write_file(path, "{\"version\": 1, \"ground\": false, \"scatter\": [{\"file\": \"cube.obj\", \"count\": 1000,"
                     " \"area_m\": [0, 0, 1, 1]}], \"boxes\": [{\"center_m\": [0, 0, 0], \"size_m\": [1, 1, 1]}]}");
    char *thousand = malloc(64 * 1024);
    if (thousand) {
        size_t n = (size_t)snprintf(thousand, 64 * 1024, "{\"version\": 1, \"ground\": false, \"instances\": [");
        for (int i = 0; i < 1000; i++)
            n += (size_t)snprintf(thousand + n, 64 * 1024 - n, "%s{\"file\": \"kilo.json\"}", i ? ", " : "");
        snprintf(thousand + n, 64 * 1024 - n, "]}");
        snprintf(path, sizeof(path), "%s/thousand.json", dir);
        write_file(path, thousand);
        free(thousand);
    }
    /* ten files deep */
    for (int i = 0; i < 10; i++) {
        char text[256];
        snprintf(path, sizeof(path), "%s/deep%d.json", dir, i);
        snprintf(text, sizeof(text), "{\"version\": 1, \"ground\": false, \"instances\": [{\"file\": \"%s\"}]}",
                 i < 9 ? "" : "cube.obj");
        if (i < 9)
            snprintf(text, sizeof(text),
                     "{\"version\": 1, \"ground\": false, \"instances\": [{\"file\": \"deep%d.json\"}]}", i + 1);
        write_file(path, text);
    }
    struct captured log = {0};
    for (size_t i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
        snprintf(path, sizeof(path), "%s/%s", dir, bad[i].name);
        write_file(path, bad[i].text);
        capture_begin(&log);
        res = load_level(dir, bad[i].name, &level);
        capture_end();
        CHECK(res == bad[i].want && strstr(log.text, bad[i].says) && level.mesh_count == 0,
              "%s: %s, expected %s, saying \"%s\": %s", bad[i].name, sb_result_name(res),
              sb_result_name(bad[i].want), bad[i].says, log.text);
    }
    capture_begin(&log);
    res = load_level(dir, "deep0.json", &level);
    capture_end();
    CHECK(res == SB_ERR_TOO_LARGE && strstr(log.text, "more than 8 deep"), "ten files deep: %s: %s",
          sb_result_name(res), log.text);
    /* a world file that places files is not one mesh */
    struct sb_mesh one = {0};
    snprintf(path, sizeof(path), "%s/world.json", dir);
    capture_begin(&log);
    res = sb_mesh_load(path, NULL, &one);
    capture_end();
    CHECK(res == SB_ERR_MESH && strstr(log.text, "scene's world"), "a level read as one mesh: %s: %s",
          sb_result_name(res), log.text);
    sb_mesh_finish(&one);
    test_remove_dir(dir);
}

int main(void)
{
    sb_log_set_level(SB_LOG_WARN);
    test_loading();
    test_glass();
    test_world_file();
    test_ground();
    test_hostile();
    test_coincident();
    test_levels();
    test_textures();

    struct sb_mesh house = {0}, well = {0}, room = {0}, soup = {0};
    uint32_t mat;
    double grey[3] = {0.5, 0.5, 0.5};
    CHECK(sb_mesh_load(IFC_HOUSE, &(struct sb_mesh_load_params){.transform = {.up_z = false}}, &house) == SB_OK,
          "the IFC house");
    sb_mesh_add_material(&well, "well", grey, &mat);
    CHECK(shape_well(&well, 1.0, 4.0, 64, 50.0, mat) == SB_OK, "a well");
    sb_mesh_add_material(&room, "room", grey, &mat);
    CHECK(shape_room(&room, (double[3]){0, 0, 0}, (double[3]){4, 3, 5}, 1.5, 3.5, 1.0, 2.2, mat) == SB_OK, "a room");
    sb_mesh_add_material(&soup, "soup", grey, &mat);
    for (int i = 0; i < 20000; i++) { /* overlapping, intersecting, thin triangles */
        double p[3][3];
        for (int k = 0; k < 3; k++)
            for (int c = 0; c < 3; c++)
                p[k][c] = (k ? p[0][c] : 20 * uniform()) + (k ? (uniform() - 0.5) * (c == 1 ? 0.05 : 2) : 0);
        sb_mesh_add_triangle(&soup, p[0], p[1], p[2], mat, "soup");
    }
    test_bvh_structure("IFC house", &house);
    test_bvh_structure("well", &well);
    test_bvh_structure("room", &room);
    test_bvh_structure("soup", &soup);
    /* Hills of 288,800 triangles: on 3 and 8 threads the top ranges are split
     * by every thread at once (over 16 chunks of 16,384), the next ones one
     * thread each, many at once, and the rest are tasks. */
    struct sb_mesh hills = {0};
    sb_mesh_add_material(&hills, "hills", grey, &mat);
    for (int j = 0; j < 380; j++)
        for (int i = 0; i < 380; i++) {
            double p[4][3];
            for (int k = 0; k < 4; k++) {
                double x = i + (k & 1), z = j + (k >> 1);
                p[k][0] = x;
                p[k][1] = 3 * sin(x / 13) * cos(z / 17) + 0.3 * sin(x * 0.9 + z * 0.7);
                p[k][2] = z;
            }
            sb_mesh_add_triangle(&hills, p[0], p[2], p[1], mat, "hills");
            sb_mesh_add_triangle(&hills, p[1], p[2], p[3], mat, "hills");
        }
    test_bvh_structure("hills", &hills);
    sb_mesh_finish(&hills);

    struct sb_vk *vk;
    if (test_vulkan(false, &vk) == SB_ERR_NO_DEVICE)
        return test_no_device();
    const struct sb_mesh *placed[] = {&house, &well, &room, &soup};
    test_instanced(vk, placed, 4);
    if (vk) {
        test_gpu_against_embree(vk, "IFC house", &house, 1u << 17);
        test_gpu_against_embree(vk, "well", &well, 1u << 15);
        test_gpu_against_embree(vk, "room", &room, 1u << 15);
        test_gpu_against_embree(vk, "soup", &soup, 1u << 16);
        CHECK(sb_vk_validation_messages(vk) == 0, "validation messages");
        sb_vk_destroy(&vk);
    }
    sb_mesh_finish(&house);
    sb_mesh_finish(&well);
    sb_mesh_finish(&room);
    sb_mesh_finish(&soup);
    return test_finish("test_geometry");
}
