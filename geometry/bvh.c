#include "bvh.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <xxhash.h>

#include "log.h"

#define BVH_BINS 32
/* SAH costs relative to one triangle test. */
#define BVH_COST_TRAVERSAL 1.0
#define BVH_COST_TRIANGLE 1.0

struct box {
    float min[3], max[3];
};

static void box_empty(struct box *b)
{
    for (int i = 0; i < 3; i++) {
        b->min[i] = FLT_MAX;
        b->max[i] = -FLT_MAX;
    }
}

static void box_grow(struct box *b, const struct box *o)
{
    for (int i = 0; i < 3; i++) {
        b->min[i] = fminf(b->min[i], o->min[i]);
        b->max[i] = fmaxf(b->max[i], o->max[i]);
    }
}

static void box_grow_point(struct box *b, const float p[3])
{
    for (int i = 0; i < 3; i++) {
        b->min[i] = fminf(b->min[i], p[i]);
        b->max[i] = fmaxf(b->max[i], p[i]);
    }
}

static double box_area(const struct box *b)
{
    double d[3];
    for (int i = 0; i < 3; i++)
        d[i] = b->max[i] > b->min[i] ? (double)b->max[i] - b->min[i] : 0.0;
    return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
}

struct builder {
    const struct sb_mesh *mesh;
    struct box *bounds; /* per mesh triangle */
    float (*centroid)[3];
    uint32_t *order; /* mesh triangle indices, partitioned in place */
    struct sb_bvh *bvh;
};

struct task {
    uint32_t node, begin, end, depth;
};

/* Make node a leaf of order[begin, end). */
static void make_leaf(struct builder *b, struct sb_bvh_node *node, uint32_t begin, uint32_t end)
{
    node->first = begin;
    node->count = end - begin;
    if (node->count > b->bvh->max_leaf)
        b->bvh->max_leaf = node->count;
}

/*
 * The best binned-SAH split of order[begin, end) within centroid bounds
 * `cb`: its axis and the first bin on the right. Returns false when no
 * split beats a leaf (or the centroids coincide).
 */
static bool find_split(struct builder *b, uint32_t begin, uint32_t end, const struct box *cb, double parent_area,
                       int *best_axis, int *best_bin, bool must)
{
    double best = must ? INFINITY : BVH_COST_TRIANGLE * (end - begin);
    bool found = false;
    for (int axis = 0; axis < 3; axis++) {
        float lo = cb->min[axis], extent = cb->max[axis] - cb->min[axis];
        if (!(extent > 0))
            continue;
        struct box bins[BVH_BINS];
        uint32_t counts[BVH_BINS] = {0};
        for (int k = 0; k < BVH_BINS; k++)
            box_empty(&bins[k]);
        float scale = BVH_BINS / extent;
        for (uint32_t i = begin; i < end; i++) {
            uint32_t t = b->order[i];
            int k = (int)((b->centroid[t][axis] - lo) * scale);
            k = k < 0 ? 0 : k >= BVH_BINS ? BVH_BINS - 1 : k;
            counts[k]++;
            box_grow(&bins[k], &b->bounds[t]);
        }
        /* right-to-left sweep of areas and counts, then left to right */
        double right_area[BVH_BINS];
        uint32_t right_count[BVH_BINS];
        struct box acc;
        box_empty(&acc);
        uint32_t n = 0;
        for (int k = BVH_BINS - 1; k > 0; k--) {
            box_grow(&acc, &bins[k]);
            n += counts[k];
            right_area[k] = box_area(&acc);
            right_count[k] = n;
        }
        box_empty(&acc);
        n = 0;
        for (int k = 1; k < BVH_BINS; k++) {
            box_grow(&acc, &bins[k - 1]);
            n += counts[k - 1];
            if (!n || !right_count[k])
                continue;
            double cost = BVH_COST_TRAVERSAL + BVH_COST_TRIANGLE *
                                                   (box_area(&acc) * n + right_area[k] * right_count[k]) /
                                                   fmax(parent_area, DBL_MIN);
            if (cost < best) {
                best = cost;
                *best_axis = axis;
                *best_bin = k;
                found = true;
            }
        }
    }
    return found;
}

static void node_bounds(struct builder *b, struct sb_bvh_node *node, uint32_t begin, uint32_t end, struct box *cb)
{
    struct box nb;
    box_empty(&nb);
    box_empty(cb);
    for (uint32_t i = begin; i < end; i++) {
        uint32_t t = b->order[i];
        box_grow(&nb, &b->bounds[t]);
        box_grow_point(cb, b->centroid[t]);
    }
    memcpy(node->min, nb.min, sizeof(nb.min));
    memcpy(node->max, nb.max, sizeof(nb.max));
}

static void build(struct builder *b, struct task *stack)
{
    struct sb_bvh *bvh = b->bvh;
    int top = 0;
    stack[top++] = (struct task){0, 0, bvh->triangle_count, 0};
    bvh->node_count = 1;
    while (top) {
        struct task task = stack[--top];
        struct sb_bvh_node *node = &bvh->nodes[task.node];
        struct box cb;
        node_bounds(b, node, task.begin, task.end, &cb);
        if (task.depth > bvh->depth)
            bvh->depth = task.depth;
        uint32_t count = task.end - task.begin;
        if (count <= 1 || task.depth >= SB_BVH_MAX_DEPTH) {
            make_leaf(b, node, task.begin, task.end);
            continue;
        }
        struct box nb;
        memcpy(nb.min, node->min, sizeof(nb.min));
        memcpy(nb.max, node->max, sizeof(nb.max));
        int axis = 0, bin = 0;
        uint32_t mid;
        if (find_split(b, task.begin, task.end, &cb, box_area(&nb), &axis, &bin, count > SB_BVH_MAX_LEAF)) {
            float lo = cb.min[axis], scale = BVH_BINS / (cb.max[axis] - cb.min[axis]);
            uint32_t i = task.begin, j = task.end;
            while (i < j) {
                int k = (int)((b->centroid[b->order[i]][axis] - lo) * scale);
                k = k < 0 ? 0 : k >= BVH_BINS ? BVH_BINS - 1 : k;
                if (k < bin) {
                    i++;
                } else {
                    uint32_t tmp = b->order[i];
                    b->order[i] = b->order[--j];
                    b->order[j] = tmp;
                }
            }
            mid = i;
        } else if (count > SB_BVH_MAX_LEAF) {
            /* Coincident centroids: halve in index order. */
            mid = task.begin + count / 2;
        } else {
            make_leaf(b, node, task.begin, task.end);
            continue;
        }
        uint32_t left = bvh->node_count;
        bvh->node_count += 2;
        node->first = left;
        node->count = 0;
        /* right first on the stack, so the left subtree is laid out first */
        stack[top++] = (struct task){left + 1, mid, task.end, task.depth + 1};
        stack[top++] = (struct task){left, task.begin, mid, task.depth + 1};
    }
}

enum sb_result sb_bvh_build(const struct sb_mesh *mesh, struct sb_bvh *bvh)
{
    memset(bvh, 0, sizeof(*bvh));
    uint32_t n = mesh->triangle_count;
    if (!n) {
        sb_error("BVH: the mesh has no triangle");
        return SB_ERR_MESH;
    }
    struct builder b = {.mesh = mesh, .bvh = bvh};
    b.bounds = malloc(n * sizeof(*b.bounds));
    b.centroid = malloc(n * sizeof(*b.centroid));
    b.order = malloc(n * sizeof(*b.order));
    /* One task per level at most waits on the stack, plus the one popped. */
    struct task *stack = malloc((SB_BVH_MAX_DEPTH + 2) * 2 * sizeof(*stack));
    bvh->nodes = calloc(2 * (size_t)n, sizeof(*bvh->nodes));
    bvh->triangles = calloc(n, sizeof(*bvh->triangles));
    if (!b.bounds || !b.centroid || !b.order || !stack || !bvh->nodes || !bvh->triangles) {
        free(b.bounds);
        free(b.centroid);
        free(b.order);
        free(stack);
        sb_bvh_finish(bvh);
        return SB_ERR_NOMEM;
    }
    bvh->triangle_count = n;
    for (uint32_t t = 0; t < n; t++) {
        /* The vertices, and where v0 + e1 and v0 + e2 round to (what the
         * triangle test sees), padded by a few ulps of the coordinates
         * and the triangle's extent, so that a hit the triangle test finds
         * is never outside its boxes (Ize 2013's concern). */
        const float *v[3];
        struct box *tb = &b.bounds[t];
        box_empty(tb);
        for (int k = 0; k < 3; k++) {
            v[k] = &mesh->positions[3 * (size_t)mesh->indices[3 * (size_t)t + k]];
            box_grow_point(tb, v[k]);
        }
        for (int k = 1; k < 3; k++) {
            float r[3];
            for (int i = 0; i < 3; i++)
                r[i] = v[0][i] + (v[k][i] - v[0][i]);
            box_grow_point(tb, r);
        }
        for (int i = 0; i < 3; i++) {
            float pad = 1e-6f * (fmaxf(fabsf(tb->min[i]), fabsf(tb->max[i])) + (tb->max[i] - tb->min[i]));
            tb->min[i] -= pad;
            tb->max[i] += pad;
            b.centroid[t][i] = 0.5f * (tb->min[i] + tb->max[i]);
        }
        b.order[t] = t;
    }
    build(&b, stack);
    for (uint32_t i = 0; i < n; i++) {
        uint32_t t = b.order[i];
        const float *v[3];
        for (int k = 0; k < 3; k++)
            v[k] = &mesh->positions[3 * (size_t)mesh->indices[3 * (size_t)t + k]];
        struct sb_bvh_triangle *out = &bvh->triangles[i];
        for (int c = 0; c < 3; c++) {
            out->v0[c] = v[0][c];
            out->e1[c] = v[1][c] - v[0][c];
            out->e2[c] = v[2][c] - v[0][c];
        }
        out->triangle = t;
        out->material = mesh->materials[t];
    }
    free(b.bounds);
    free(b.centroid);
    free(b.order);
    free(stack);
    return SB_OK;
}

void sb_bvh_finish(struct sb_bvh *bvh)
{
    free(bvh->nodes);
    free(bvh->triangles);
    memset(bvh, 0, sizeof(*bvh));
}

void sb_bvh_hash(const struct sb_bvh *bvh, char out[33])
{
    XXH3_state_t *st = XXH3_createState();
    XXH3_128bits_reset(st);
    XXH3_128bits_update(st, bvh->nodes, (size_t)bvh->node_count * sizeof(*bvh->nodes));
    XXH3_128bits_update(st, bvh->triangles, (size_t)bvh->triangle_count * sizeof(*bvh->triangles));
    XXH128_hash_t h = XXH3_128bits_digest(st);
    XXH3_freeState(st);
    snprintf(out, 33, "%016llx%016llx", (unsigned long long)h.high64, (unsigned long long)h.low64);
}

/* ---- traversal: the CPU twin of bvh.glsl ------------------------------------------------ */

static float dot3(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const float a[3], const float b[3], float out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* Möller-Trumbore, both faces; writes t, u, v and the face on a hit in (tmin, tmax). */
static bool hit_triangle(const struct sb_bvh_triangle *tri, const float o[3], const float d[3], float tmin, float tmax,
                         struct sb_hit *hit)
{
    float p[3], q[3], s[3];
    cross3(d, tri->e2, p);
    float det = dot3(tri->e1, p);
    if (det == 0.0f)
        return false;
    float inv = 1.0f / det;
    for (int i = 0; i < 3; i++)
        s[i] = o[i] - tri->v0[i];
    float u = dot3(s, p) * inv;
    if (u < 0.0f || u > 1.0f)
        return false;
    cross3(s, tri->e1, q);
    float v = dot3(d, q) * inv;
    if (v < 0.0f || u + v > 1.0f)
        return false;
    float t = dot3(tri->e2, q) * inv;
    if (!(t > tmin && t < tmax))
        return false;
    hit->t = t;
    hit->u = u;
    hit->v = v;
    hit->back_face = det < 0.0f;
    return true;
}

/* Slab test; the entry distance in *t_enter. */
static bool hit_box(const struct sb_bvh_node *n, const float o[3], const float inv_d[3], float tmin, float tmax,
                    float *t_enter)
{
    float t0 = tmin, t1 = tmax;
    for (int i = 0; i < 3; i++) {
        float a = (n->min[i] - o[i]) * inv_d[i], b = (n->max[i] - o[i]) * inv_d[i];
        t0 = fmaxf(t0, fminf(a, b));
        t1 = fminf(t1, fmaxf(a, b));
    }
    *t_enter = t0;
    return t0 <= t1;
}

bool sb_bvh_intersect(const struct sb_bvh *bvh, const float o[3], const float d[3], float tmin, float tmax, bool any,
                      struct sb_hit *hit)
{
    float inv_d[3];
    for (int i = 0; i < 3; i++) /* a zero component: a huge but finite slope keeps the slabs NaN-free */
        inv_d[i] = 1.0f / (fabsf(d[i]) > 1e-30f ? d[i] : copysignf(1e-30f, d[i]));
    hit->triangle = SB_BVH_MISS;
    uint32_t stack[SB_BVH_MAX_DEPTH + 1];
    int top = 0;
    uint32_t node = 0;
    float t_enter;
    if (!hit_box(&bvh->nodes[0], o, inv_d, tmin, tmax, &t_enter))
        return false;
    for (;;) {
        const struct sb_bvh_node *n = &bvh->nodes[node];
        if (n->count) {
            for (uint32_t i = n->first; i < n->first + n->count; i++) {
                struct sb_hit h;
                if (hit_triangle(&bvh->triangles[i], o, d, tmin, tmax, &h)) {
                    tmax = h.t;
                    h.triangle = bvh->triangles[i].triangle;
                    *hit = h;
                    if (any)
                        return true;
                }
            }
        } else {
            float ta, tb;
            bool a = hit_box(&bvh->nodes[n->first], o, inv_d, tmin, tmax, &ta);
            bool b = hit_box(&bvh->nodes[n->first + 1], o, inv_d, tmin, tmax, &tb);
            if (a && b) {
                uint32_t near = tb < ta ? n->first + 1 : n->first;
                stack[top++] = near == n->first ? n->first + 1 : n->first;
                node = near;
                continue;
            }
            if (a || b) {
                node = a ? n->first : n->first + 1;
                continue;
            }
        }
        if (!top)
            break;
        node = stack[--top];
    }
    return hit->triangle != SB_BVH_MISS;
}
