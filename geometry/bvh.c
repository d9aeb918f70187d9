#include "bvh.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <xxhash.h>

#include "array.h"
#include "log.h"
#include "parallel.h"

#define BVH_BINS 32
/* SAH costs relative to one triangle test. */
#define BVH_COST_TRAVERSAL 1.0
#define BVH_COST_TRIANGLE 1.0
/* Ranges larger than twice a task (a task: n / (2 x threads), at least
 * BVH_TASK_MIN; on one thread the whole mesh) are split with every thread
 * binning and partitioning chunks of theirs (BVH_SPLIT_CHUNKS a thread, of
 * at least BVH_SPLIT_CHUNK_MIN triangles); those between one and two tasks
 * one thread each, many at once; each smaller one is built whole by one
 * thread. Every partition is stable and the layout is the one-thread
 * build's, so the bytes do not depend on how the work was shared. */
#define BVH_TASK_MIN 8192
#define BVH_SPLIT_CHUNKS 4
#define BVH_SPLIT_CHUNK_MIN 2048
/* The chunks of the steps that go over every triangle once. */
#define BVH_CHUNK 16384

/*
 * The build's large arrays (a million triangles: some 200 MB touched once)
 * on 2 MiB pages where the kernel grants them on request (Linux's
 * transparent huge pages in "madvise" mode, Debian's default): a 4 KiB
 * page a fault was a fifth of the one-thread build. free() releases them.
 */
#define BVH_HUGE_PAGE ((size_t)2 << 20)

static void *big_alloc(size_t bytes)
{
#ifdef MADV_HUGEPAGE
    if (bytes >= BVH_HUGE_PAGE) {
        size_t rounded = (bytes + BVH_HUGE_PAGE - 1) & ~(BVH_HUGE_PAGE - 1);
        void *p = aligned_alloc(BVH_HUGE_PAGE, rounded);
        if (p)
            madvise(p, rounded, MADV_HUGEPAGE); /* advice: refused, it is 4 KiB pages */
        return p;
    }
#endif
    return malloc(bytes);
}

/* min and max for the build's finite values: one instruction each, where
 * fminf and fmaxf's NaN rules cost a call. */
static inline float min_f(float a, float b)
{
    return a < b ? a : b;
}

static inline float max_f(float a, float b)
{
    return a > b ? a : b;
}

/* Four lanes, the fourth unused (0 in a triangle's box), so that the
 * compiler makes each loop over them one vector instruction. */
struct box {
    float min[4], max[4];
};

static void box_empty(struct box *b)
{
    for (int i = 0; i < 4; i++) {
        b->min[i] = FLT_MAX;
        b->max[i] = -FLT_MAX;
    }
}

static inline void box_grow(struct box *b, const struct box *o)
{
    for (int i = 0; i < 4; i++) {
        b->min[i] = min_f(b->min[i], o->min[i]);
        b->max[i] = max_f(b->max[i], o->max[i]);
    }
}

static inline void box_grow_point(struct box *b, const float p[4])
{
    for (int i = 0; i < 4; i++) {
        b->min[i] = min_f(b->min[i], p[i]);
        b->max[i] = max_f(b->max[i], p[i]);
    }
}

static inline double box_area(const struct box *b)
{
    double d[3];
    for (int i = 0; i < 3; i++)
        d[i] = b->max[i] > b->min[i] ? (double)b->max[i] - b->min[i] : 0.0;
    return d[0] * d[1] + d[1] * d[2] + d[2] * d[0];
}

/* A triangle while building: its padded box (prims[]) and its index in
 * the mesh (the same place of index[]). Its centroid is taken doubled,
 * min + max, everywhere. */
struct prim {
    struct box box;
};

static inline void prim_centroid(const struct prim *p, float c[4])
{
    for (int i = 0; i < 4; i++)
        c[i] = p->box.min[i] + p->box.max[i];
}

/* A node to split: the triangles [begin, end) of one of the two arrays a
 * partition goes between (side), their box and their (doubled) centroids'
 * box. */
struct range {
    uint32_t node, begin, end, depth, side;
    struct box box, centroids;
};

/* The triangles and their indices, and the arrays a split partitions them
 * into: a range's children are on the side its triangles are not, so that
 * each level moves a triangle once. */
struct sides {
    struct prim *prims[2];
    uint32_t *index[2];
};

/* Binned counts and boxes along the three axes. */
struct bins {
    struct box box[3][BVH_BINS];
    uint32_t count[3][BVH_BINS];
};

/* How centroids map to bins: bin = (c - lo) * scale, clamped to the
 * first `count`. A node of fewer triangles than BVH_BINS gets as many bins
 * as triangles, so that a node's cost follows its size. */
struct binning {
    float lo[3], scale[3];
    int count;
};

static struct binning binning_of(const struct box *centroids, uint32_t triangles)
{
    struct binning m = {.count = triangles < BVH_BINS ? (triangles < 2 ? 2 : (int)triangles) : BVH_BINS};
    for (int a = 0; a < 3; a++) {
        float extent = centroids->max[a] - centroids->min[a];
        m.lo[a] = centroids->min[a];
        m.scale[a] = extent > 0 ? m.count / extent : 0.0f;
    }
    return m;
}

static inline int bin_of(const struct binning *m, int axis, float c)
{
    int k = (int)((c - m->lo[axis]) * m->scale[axis]);
    return k < 0 ? 0 : k >= m->count ? m->count - 1 : k;
}

static void bins_empty(struct bins *b, const struct binning *m)
{
    for (int a = 0; a < 3; a++)
        for (int k = 0; k < m->count; k++) {
            box_empty(&b->box[a][k]);
            b->count[a][k] = 0;
        }
}

static void bins_fill(struct bins *b, const struct binning *m, const struct prim *prims, uint32_t begin, uint32_t end)
{
    bins_empty(b, m);
    for (uint32_t i = begin; i < end; i++) {
        float c[4];
        prim_centroid(&prims[i], c);
        for (int a = 0; a < 3; a++) {
            int k = bin_of(m, a, c[a]);
            b->count[a][k]++;
            box_grow(&b->box[a][k], &prims[i].box);
        }
    }
}

/* Min, max and sums: the same whatever the order they are merged in. */
static void bins_merge(struct bins *into, const struct bins *b, const struct binning *m)
{
    for (int a = 0; a < 3; a++)
        for (int k = 0; k < m->count; k++) {
            box_grow(&into->box[a][k], &b->box[a][k]);
            into->count[a][k] += b->count[a][k];
        }
}

struct split {
    int axis, bin; /* the first bin on the right */
    struct box left, right;
};

/*
 * The best binned-SAH split of `count` triangles from their bins: false
 * when no split beats a leaf (must: when there is no split at all, the
 * centroids coinciding).
 */
static bool best_split(const struct bins *b, const struct binning *m, uint32_t count, double parent_area, bool must,
                       struct split *out)
{
    double best = must ? INFINITY : BVH_COST_TRIANGLE * count;
    double area_scale = fmax(parent_area, DBL_MIN);
    bool found = false;
    for (int axis = 0; axis < 3; axis++) {
        if (!(m->scale[axis] > 0))
            continue;
        /* right-to-left sweep of areas and counts, then left to right */
        double right_area[BVH_BINS];
        uint32_t right_count[BVH_BINS];
        /* an empty bin leaves the sweep's box, so its area, as it was:
         * the areas are taken only where a bin adds triangles (most bins of
         * a small node are empty) */
        struct box acc;
        box_empty(&acc);
        uint32_t n = 0;
        double area = 0.0; /* of the empty box */
        for (int k = m->count - 1; k > 0; k--) {
            if (b->count[axis][k]) {
                box_grow(&acc, &b->box[axis][k]);
                n += b->count[axis][k];
                area = box_area(&acc);
            }
            right_area[k] = area;
            right_count[k] = n;
        }
        box_empty(&acc);
        n = 0;
        area = 0.0;
        for (int k = 1; k < m->count; k++) {
            if (b->count[axis][k - 1]) {
                box_grow(&acc, &b->box[axis][k - 1]);
                n += b->count[axis][k - 1];
                area = box_area(&acc);
            }
            if (!n || !right_count[k])
                continue;
            double cost = BVH_COST_TRAVERSAL + BVH_COST_TRIANGLE *
                                                   (area * n + right_area[k] * right_count[k]) / area_scale;
            if (cost < best) {
                best = cost;
                out->axis = axis;
                out->bin = k;
                found = true;
            }
        }
    }
    if (found) {
        box_empty(&out->left);
        box_empty(&out->right);
        for (int k = 0; k < m->count; k++)
            box_grow(k < out->bin ? &out->left : &out->right, &b->box[out->axis][k]);
    }
    return found;
}

/* The boxes of prims[begin, end) and of their centroids. */
static void range_bounds(const struct prim *prims, uint32_t begin, uint32_t end, struct box *box,
                         struct box *centroids)
{
    box_empty(box);
    box_empty(centroids);
    for (uint32_t i = begin; i < end; i++) {
        float c[4];
        prim_centroid(&prims[i], c);
        box_grow(box, &prims[i].box);
        box_grow_point(centroids, c);
    }
}

/*
 * Split `r` into its children's ranges, partitioned stably onto the other
 * side (one thread): false when it stays a leaf.
 */
static bool split_serial(const struct sides *sides, const struct range *r, uint32_t max_leaf, struct range *left,
                         struct range *right)
{
    uint32_t count = r->end - r->begin;
    if (count <= 1 || r->depth >= SB_BVH_MAX_DEPTH)
        return false;
    const struct prim *prims = sides->prims[r->side];
    const uint32_t *index = sides->index[r->side];
    struct prim *to = sides->prims[!r->side];
    uint32_t *to_index = sides->index[!r->side];
    struct binning m = binning_of(&r->centroids, count);
    struct bins b;
    bins_fill(&b, &m, prims, r->begin, r->end);
    struct split s;
    bool must = count > max_leaf;
    uint32_t mid;
    if (best_split(&b, &m, count, box_area(&r->box), must, &s)) {
        uint32_t lefts = 0;
        for (int k = 0; k < s.bin; k++)
            lefts += b.count[s.axis][k];
        struct box lc, rc;
        box_empty(&lc);
        box_empty(&rc);
        mid = r->begin + lefts;
        uint32_t l = r->begin, w = mid;
        for (uint32_t i = r->begin; i < r->end; i++) {
            float c[4];
            prim_centroid(&prims[i], c);
            if (bin_of(&m, s.axis, c[s.axis]) < s.bin) {
                box_grow_point(&lc, c);
                to[l] = prims[i];
                to_index[l++] = index[i];
            } else {
                box_grow_point(&rc, c);
                to[w] = prims[i];
                to_index[w++] = index[i];
            }
        }
        left->box = s.left;
        right->box = s.right;
        left->centroids = lc;
        right->centroids = rc;
    } else if (must) {
        /* Coincident centroids: halve in the order they lie. */
        mid = r->begin + count / 2;
        memcpy(&to[r->begin], &prims[r->begin], count * sizeof(*prims));
        memcpy(&to_index[r->begin], &index[r->begin], count * sizeof(*index));
        range_bounds(prims, r->begin, mid, &left->box, &left->centroids);
        range_bounds(prims, mid, r->end, &right->box, &right->centroids);
    } else {
        return false;
    }
    left->begin = r->begin;
    left->end = right->begin = mid;
    right->end = r->end;
    left->depth = right->depth = r->depth + 1;
    left->side = right->side = !r->side;
    return true;
}

static void set_node(struct sb_bvh_node *node, const struct box *box, uint32_t first, uint32_t count)
{
    memcpy(node->min, box->min, sizeof(box->min));
    memcpy(node->max, box->max, sizeof(box->max));
    node->first = first;
    node->count = count;
}

/* A range built whole by one thread into nodes of its own (nodes[0] its
 * root, children indices local); its root goes where the top levels put
 * it, the rest from `base` on. */
struct task {
    struct range range;
    struct sb_bvh_node *nodes;
    uint32_t node_count, depth, max_leaf, root, base;
};

static void build_task(const struct sides *sides, struct task *t)
{
    /* One range per level at most waits on the stack, plus the one popped. */
    struct range stack[(SB_BVH_MAX_DEPTH + 2) * 2];
    int top = 0;
    stack[top++] = t->range;
    stack[0].node = 0;
    t->node_count = 1;
    while (top) {
        struct range r = stack[--top], left, right;
        if (r.depth > t->depth)
            t->depth = r.depth;
        if (!split_serial(sides, &r, SB_BVH_MAX_LEAF, &left, &right)) {
            /* the leaf's indices where write_triangles reads them */
            if (r.side)
                memcpy(&sides->index[0][r.begin], &sides->index[1][r.begin], (r.end - r.begin) * sizeof(uint32_t));
            set_node(&t->nodes[r.node], &r.box, r.begin, r.end - r.begin);
            if (r.end - r.begin > t->max_leaf)
                t->max_leaf = r.end - r.begin;
            continue;
        }
        left.node = t->node_count;
        right.node = t->node_count + 1;
        t->node_count += 2;
        set_node(&t->nodes[r.node], &r.box, left.node, 0);
        /* right first on the stack, so the left subtree is laid out first */
        stack[top++] = right;
        stack[top++] = left;
    }
}

/* ---- the steps every thread shares ---------------------------------------------------- */

struct builder {
    const struct sb_mesh *mesh;
    struct prim *prims, *scratch;
    uint32_t *index, *scratch_index; /* each triangle's in the mesh, moved with prims */
    struct sides sides; /* prims and index, scratch and scratch_index */
    struct sb_bvh *bvh;
    uint32_t task_prims; /* the largest range a task */
    struct task *tasks;
    uint32_t task_count, *task_order;
    /* The top levels: their nodes (children at these indices, not yet the
     * final ones), and each one's task (-1: split). */
    struct sb_bvh_node *top;
    int32_t *top_task;
    uint32_t top_count, top_capacity, task_capacity;
    /* ranges being split one thread each, and what each became */
    struct range *frontier, *frontier_next;
    struct {
        struct range left, right;
        bool split;
    } *split_out;
    uint32_t frontier_count;
    /* the range being split on every thread, in chunks of `chunk` */
    const struct range *range;
    uint32_t chunk, parallel_prims;
    struct binning binning;
    struct split split;
    uint32_t chunk_count;
    struct bins *chunk_bins;
    struct {
        uint32_t left, right; /* counts, then where the chunk's go */
        struct box left_centroids, right_centroids;
    } *chunks;
};

static uint32_t chunk_begin(const struct builder *b, uint32_t chunk)
{
    return b->range->begin + chunk * b->chunk;
}

static uint32_t chunk_end(const struct builder *b, uint32_t chunk)
{
    uint32_t end = chunk_begin(b, chunk) + b->chunk;
    return end < b->range->end ? end : b->range->end;
}

/* A triangle's box: its vertices, and where v0 + e1 and v0 + e2 round to
 * (what the triangle test sees), padded by a few ulps of the coordinates
 * and the triangle's extent, so that a hit the triangle test finds is
 * never outside its boxes (Ize 2013's concern). */
static void make_prims(void *user, int chunk)
{
    struct builder *b = user;
    const struct sb_mesh *mesh = b->mesh;
    uint32_t end = (uint32_t)chunk * BVH_CHUNK + BVH_CHUNK;
    end = end < mesh->triangle_count ? end : mesh->triangle_count;
    for (uint32_t t = (uint32_t)chunk * BVH_CHUNK; t < end; t++) {
        float v[3][4] = {{0}};
        struct prim *p = &b->prims[t];
        box_empty(&p->box);
        for (int k = 0; k < 3; k++) {
            memcpy(v[k], &mesh->positions[3 * (size_t)mesh->indices[3 * (size_t)t + k]], 3 * sizeof(float));
            box_grow_point(&p->box, v[k]);
        }
        for (int k = 1; k < 3; k++) {
            float r[4] = {0};
            for (int i = 0; i < 3; i++)
                r[i] = v[0][i] + (v[k][i] - v[0][i]);
            box_grow_point(&p->box, r);
        }
        for (int i = 0; i < 3; i++) {
            float pad = 1e-6f * (max_f(fabsf(p->box.min[i]), fabsf(p->box.max[i])) + (p->box.max[i] - p->box.min[i]));
            p->box.min[i] -= pad;
            p->box.max[i] += pad;
        }
        b->index[t] = t;
    }
}

static void chunk_bounds(void *user, int chunk)
{
    struct builder *b = user;
    struct bins *out = &b->chunk_bins[chunk];
    /* the box in box[0][0], the centroids' in box[1][0] */
    range_bounds(b->sides.prims[b->range->side], chunk_begin(b, (uint32_t)chunk), chunk_end(b, (uint32_t)chunk),
                 &out->box[0][0], &out->box[1][0]);
}

static void chunk_bin(void *user, int chunk)
{
    struct builder *b = user;
    bins_fill(&b->chunk_bins[chunk], &b->binning, b->sides.prims[b->range->side], chunk_begin(b, (uint32_t)chunk),
              chunk_end(b, (uint32_t)chunk));
}

static bool goes_left(const struct builder *b, const struct prim *p, float c[4])
{
    prim_centroid(p, c);
    return bin_of(&b->binning, b->split.axis, c[b->split.axis]) < b->split.bin;
}

static void chunk_count(void *user, int chunk)
{
    struct builder *b = user;
    const struct prim *prims = b->sides.prims[b->range->side];
    uint32_t left = 0, begin = chunk_begin(b, (uint32_t)chunk), end = chunk_end(b, (uint32_t)chunk);
    for (uint32_t i = begin; i < end; i++) {
        float c[4];
        left += goes_left(b, &prims[i], c);
    }
    b->chunks[chunk].left = left;
    b->chunks[chunk].right = end - begin - left;
}

/* Stable: each chunk's triangles go to the places the counts gave it, on
 * the other side. */
static void chunk_scatter(void *user, int chunk)
{
    struct builder *b = user;
    uint32_t side = b->range->side;
    const struct prim *prims = b->sides.prims[side];
    const uint32_t *index = b->sides.index[side];
    struct prim *to = b->sides.prims[!side];
    uint32_t *to_index = b->sides.index[!side];
    uint32_t l = b->chunks[chunk].left, r = b->chunks[chunk].right;
    struct box *lc = &b->chunks[chunk].left_centroids, *rc = &b->chunks[chunk].right_centroids;
    box_empty(lc);
    box_empty(rc);
    for (uint32_t i = chunk_begin(b, (uint32_t)chunk); i < chunk_end(b, (uint32_t)chunk); i++) {
        float c[4];
        if (goes_left(b, &prims[i], c)) {
            to_index[l] = index[i];
            to[l++] = prims[i];
            box_grow_point(lc, c);
        } else {
            to_index[r] = index[i];
            to[r++] = prims[i];
            box_grow_point(rc, c);
        }
    }
}

/* Split a range too large for one thread: binned and partitioned (stably)
 * by chunks on every thread. Such a range always splits, but at the depth
 * limit. */
static bool split_parallel(struct builder *b, const struct range *r, struct range *left, struct range *right)
{
    if (r->depth >= SB_BVH_MAX_DEPTH)
        return false;
    uint32_t count = r->end - r->begin, chunks = BVH_SPLIT_CHUNKS * (uint32_t)sb_parallel_threads();
    b->range = r;
    b->binning = binning_of(&r->centroids, count);
    b->chunk = (count + chunks - 1) / chunks;
    b->chunk = b->chunk > BVH_SPLIT_CHUNK_MIN ? b->chunk : BVH_SPLIT_CHUNK_MIN;
    b->chunk_count = (count + b->chunk - 1) / b->chunk;
    sb_parallel_for((int)b->chunk_count, chunk_bin, b);
    struct bins all;
    bins_empty(&all, &b->binning);
    for (uint32_t c = 0; c < b->chunk_count; c++)
        bins_merge(&all, &b->chunk_bins[c], &b->binning);
    uint32_t mid;
    if (best_split(&all, &b->binning, r->end - r->begin, box_area(&r->box), true, &b->split)) {
        sb_parallel_for((int)b->chunk_count, chunk_count, b);
        uint32_t l = r->begin, total_left = 0;
        for (uint32_t c = 0; c < b->chunk_count; c++)
            total_left += b->chunks[c].left;
        uint32_t rr = r->begin + total_left;
        for (uint32_t c = 0; c < b->chunk_count; c++) {
            uint32_t nl = b->chunks[c].left, nr = b->chunks[c].right;
            b->chunks[c].left = l;
            b->chunks[c].right = rr;
            l += nl;
            rr += nr;
        }
        sb_parallel_for((int)b->chunk_count, chunk_scatter, b);
        mid = r->begin + total_left;
        left->side = right->side = !r->side;
        left->box = b->split.left;
        right->box = b->split.right;
        box_empty(&left->centroids);
        box_empty(&right->centroids);
        for (uint32_t c = 0; c < b->chunk_count; c++) {
            box_grow(&left->centroids, &b->chunks[c].left_centroids);
            box_grow(&right->centroids, &b->chunks[c].right_centroids);
        }
    } else {
        /* Coincident centroids: halve in the order they lie. */
        mid = r->begin + (r->end - r->begin) / 2;
        range_bounds(b->sides.prims[r->side], r->begin, mid, &left->box, &left->centroids);
        range_bounds(b->sides.prims[r->side], mid, r->end, &right->box, &right->centroids);
        left->side = right->side = r->side;
    }
    left->begin = r->begin;
    left->end = right->begin = mid;
    right->end = r->end;
    left->depth = right->depth = r->depth + 1;
    return true;
}

static int larger_task_first(const void *a, const void *b, void *user)
{
    const struct task *tasks = user;
    const struct range *ra = &tasks[*(const uint32_t *)a].range, *rb = &tasks[*(const uint32_t *)b].range;
    uint32_t na = ra->end - ra->begin, nb = rb->end - rb->begin;
    return na != nb ? (na < nb) - (na > nb) : (ra->begin > rb->begin) - (ra->begin < rb->begin);
}

static void run_task(void *user, int index)
{
    struct builder *b = user;
    build_task(&b->sides, &b->tasks[b->task_order[index]]);
}

/* A task's nodes into their places: its root where the top level left it,
 * the rest from its base on, children indices made global. */
static void place_task(void *user, int index)
{
    struct builder *b = user;
    const struct task *t = &b->tasks[index];
    for (uint32_t i = 0; i < t->node_count; i++) {
        struct sb_bvh_node n = t->nodes[i];
        if (!n.count)
            n.first = t->base + n.first - 1;
        b->bvh->nodes[i ? t->base + i - 1 : t->root] = n;
    }
}

static void write_triangles(void *user, int chunk)
{
    struct builder *b = user;
    const struct sb_mesh *mesh = b->mesh;
    uint32_t end = (uint32_t)chunk * BVH_CHUNK + BVH_CHUNK;
    end = end < b->bvh->triangle_count ? end : b->bvh->triangle_count;
    for (uint32_t i = (uint32_t)chunk * BVH_CHUNK; i < end; i++) {
        uint32_t t = b->index[i];
        const float *v[3];
        for (int k = 0; k < 3; k++)
            v[k] = &mesh->positions[3 * (size_t)mesh->indices[3 * (size_t)t + k]];
        struct sb_bvh_triangle *out = &b->bvh->triangles[i];
        for (int c = 0; c < 3; c++) {
            out->v0[c] = v[0][c];
            out->e1[c] = v[1][c] - v[0][c];
            out->e2[c] = v[2][c] - v[0][c];
        }
        out->triangle = t;
        out->material = mesh->materials[t];
        out->pad = 0;
    }
}

/* A top node: a task's root, or room for a split's children. */
static enum sb_result add_task(struct builder *b, const struct range *r)
{
    if (!sb_array_grow((void **)&b->tasks, b->task_count, &b->task_capacity, sizeof(*b->tasks)))
        return SB_ERR_NOMEM;
    b->top_task[r->node] = (int32_t)b->task_count;
    b->tasks[b->task_count++] = (struct task){.range = *r};
    return SB_OK;
}

/* Children for top node `r`, split into left and right. */
static enum sb_result add_split(struct builder *b, const struct range *r, struct range *left, struct range *right)
{
    if (b->top_count + 2 > b->top_capacity) {
        uint32_t more = 2 * b->top_capacity;
        struct sb_bvh_node *top = realloc(b->top, more * sizeof(*top));
        if (top)
            b->top = top;
        int32_t *task = top ? realloc(b->top_task, more * sizeof(*task)) : NULL;
        if (!task)
            return SB_ERR_NOMEM;
        b->top_task = task;
        b->top_capacity = more;
    }
    left->node = b->top_count;
    right->node = b->top_count + 1;
    b->top_count += 2;
    set_node(&b->top[r->node], &r->box, left->node, 0);
    b->top_task[r->node] = -1;
    if (r->depth > b->bvh->depth)
        b->bvh->depth = r->depth;
    return SB_OK;
}

static void split_one(void *user, int i)
{
    struct builder *b = user;
    b->split_out[i].split = split_serial(&b->sides, &b->frontier[i], SB_BVH_MAX_LEAF,
                                         &b->split_out[i].left, &b->split_out[i].right);
}

/*
 * The top levels, until every range is a task: ranges over two tasks one
 * at a time, each by every thread (fewer of them than threads); then the
 * rest level by level, each range by one thread, many at once. The order
 * they are split in changes nothing: lay_out places the nodes.
 */
static enum sb_result build_top(struct builder *b)
{
    struct sb_bvh *bvh = b->bvh;
    struct range stack[(SB_BVH_MAX_DEPTH + 2) * 2];
    int top = 0;
    struct range root = {.node = 0, .begin = 0, .end = bvh->triangle_count};
    b->range = &root;
    b->chunk = BVH_CHUNK;
    b->chunk_count = (bvh->triangle_count + BVH_CHUNK - 1) / BVH_CHUNK;
    sb_parallel_for((int)b->chunk_count, chunk_bounds, b);
    box_empty(&root.box);
    box_empty(&root.centroids);
    for (uint32_t c = 0; c < b->chunk_count; c++) {
        box_grow(&root.box, &b->chunk_bins[c].box[0][0]);
        box_grow(&root.centroids, &b->chunk_bins[c].box[1][0]);
    }
    b->top = malloc(64 * sizeof(*b->top));
    b->top_task = malloc(64 * sizeof(*b->top_task));
    /* each range there holds over task_prims triangles, none twice */
    size_t most = bvh->triangle_count / b->task_prims + 1;
    b->frontier = malloc(most * sizeof(*b->frontier));
    b->frontier_next = malloc(most * sizeof(*b->frontier_next));
    b->split_out = malloc(most * sizeof(*b->split_out));
    if (!b->top || !b->top_task || !b->frontier || !b->frontier_next || !b->split_out)
        return SB_ERR_NOMEM;
    b->top_capacity = 64;
    b->top_count = 1;
    enum sb_result res = SB_OK;
    stack[top++] = root;
    while (top && !res) {
        struct range r = stack[--top], left, right;
        uint32_t count = r.end - r.begin;
        if (count <= b->task_prims)
            res = add_task(b, &r);
        else if (count <= b->parallel_prims)
            b->frontier[b->frontier_count++] = r;
        else if (!split_parallel(b, &r, &left, &right))
            res = add_task(b, &r); /* the depth limit: a leaf */
        else if (!(res = add_split(b, &r, &left, &right))) {
            stack[top++] = right;
            stack[top++] = left;
        }
    }
    while (b->frontier_count && !res) {
        sb_parallel_for((int)b->frontier_count, split_one, b);
        uint32_t next = 0;
        for (uint32_t i = 0; i < b->frontier_count && !res; i++) {
            struct range r = b->frontier[i], left = b->split_out[i].left, right = b->split_out[i].right;
            if (!b->split_out[i].split) {
                res = add_task(b, &r);
                continue;
            }
            if ((res = add_split(b, &r, &left, &right)))
                break;
            const struct range *children[2] = {&left, &right};
            for (int c = 0; c < 2 && !res; c++) {
                if (children[c]->end - children[c]->begin <= b->task_prims)
                    res = add_task(b, children[c]);
                else
                    b->frontier_next[next++] = *children[c];
            }
        }
        struct range *swap = b->frontier;
        b->frontier = b->frontier_next;
        b->frontier_next = swap;
        b->frontier_count = next;
    }
    return res;
}

/* Where every node goes, as the one-thread build lays them out (its stack,
 * the right child pushed first): a split node's children side by side at
 * the next free place, a task's subtree whole from the next free place on;
 * then the top nodes written there. */
static enum sb_result lay_out(struct builder *b)
{
    uint32_t *place = malloc(b->top_count * sizeof(*place)), next = 1;
    uint32_t stack[(SB_BVH_MAX_DEPTH + 2) * 2];
    int top = 0;
    if (!place)
        return SB_ERR_NOMEM;
    place[0] = 0;
    stack[top++] = 0;
    while (top) {
        uint32_t node = stack[--top];
        if (b->top_task[node] >= 0) {
            struct task *t = &b->tasks[b->top_task[node]];
            t->root = place[node];
            t->base = next;
            next += t->node_count - 1;
            continue;
        }
        struct sb_bvh_node n = b->top[node];
        place[n.first] = next;
        place[n.first + 1] = next + 1;
        next += 2;
        stack[top++] = n.first + 1;
        stack[top++] = n.first;
    }
    for (uint32_t node = 0; node < b->top_count; node++) {
        if (b->top_task[node] >= 0)
            continue;
        struct sb_bvh_node n = b->top[node];
        n.first = place[n.first];
        b->bvh->nodes[place[node]] = n;
    }
    b->bvh->node_count = next;
    free(place);
    return SB_OK;
}

enum sb_result sb_bvh_build(const struct sb_mesh *mesh, struct sb_bvh *bvh)
{
    memset(bvh, 0, sizeof(*bvh));
    uint32_t n = mesh->triangle_count;
    if (!n) {
        sb_error("BVH: the mesh has no triangle");
        return SB_ERR_MESH;
    }
    uint32_t chunks = (n + BVH_CHUNK - 1) / BVH_CHUNK;
    int threads = sb_parallel_threads();
    struct builder b = {.mesh = mesh, .bvh = bvh};
    b.task_prims = threads <= 1 ? n : n / (2 * (uint32_t)threads) > BVH_TASK_MIN ? n / (2 * (uint32_t)threads)
                                                                                : BVH_TASK_MIN;
    b.parallel_prims = b.task_prims > UINT32_MAX / 2 ? UINT32_MAX : 2 * b.task_prims;
    b.prims = big_alloc(n * sizeof(*b.prims));
    b.scratch = big_alloc(n * sizeof(*b.scratch));
    b.index = big_alloc(n * sizeof(*b.index));
    b.scratch_index = big_alloc(n * sizeof(*b.scratch_index));
    b.sides = (struct sides){{b.prims, b.scratch}, {b.index, b.scratch_index}};
    /* the most chunks of a pass: the whole mesh's, or a split's */
    uint32_t split_chunks = BVH_SPLIT_CHUNKS * (uint32_t)threads;
    b.chunk_bins = malloc((chunks > split_chunks ? chunks : split_chunks) * sizeof(*b.chunk_bins));
    b.chunks = malloc((chunks > split_chunks ? chunks : split_chunks) * sizeof(*b.chunks));
    /* the tasks' own nodes: a task of c triangles has at most 2c - 1 */
    struct sb_bvh_node *task_nodes = big_alloc(2 * (size_t)n * sizeof(*task_nodes));
    bvh->nodes = big_alloc(2 * (size_t)n * sizeof(*bvh->nodes));
    bvh->triangles = big_alloc(n * sizeof(*bvh->triangles));
    enum sb_result res = SB_ERR_NOMEM;
    bool begun = false;
    if (!b.prims || !b.scratch || !b.index || !b.scratch_index || !b.chunk_bins || !b.chunks || !task_nodes || !bvh->nodes || !bvh->triangles)
        goto done;
    bvh->triangle_count = n;
    sb_status_begin("BVH: %u triangles on %d threads", n, sb_parallel_threads());
    begun = true;
    double t0 = sb_now_s();
    sb_parallel_for((int)chunks, make_prims, &b);
    double t1 = sb_now_s();
    if ((res = build_top(&b)))
        goto done;
    for (uint32_t i = 0; i < b.task_count; i++)
        b.tasks[i].nodes = &task_nodes[2 * (size_t)b.tasks[i].range.begin];
    /* the largest tasks first, so that no thread is left with one at the end */
    b.task_order = malloc(b.task_count * sizeof(*b.task_order));
    if (!b.task_order) {
        res = SB_ERR_NOMEM;
        goto done;
    }
    for (uint32_t i = 0; i < b.task_count; i++)
        b.task_order[i] = i;
    qsort_r(b.task_order, b.task_count, sizeof(*b.task_order), larger_task_first, b.tasks);
    double t2 = sb_now_s();
    sb_parallel_for((int)b.task_count, run_task, &b);
    double t3 = sb_now_s();
    for (uint32_t i = 0; i < b.task_count; i++) {
        const struct task *t = &b.tasks[i];
        bvh->depth = t->depth > bvh->depth ? t->depth : bvh->depth;
        bvh->max_leaf = t->max_leaf > bvh->max_leaf ? t->max_leaf : bvh->max_leaf;
    }
    if ((res = lay_out(&b)))
        goto done;
    sb_parallel_for((int)b.task_count, place_task, &b);
    sb_parallel_for((int)chunks, write_triangles, &b);
    sb_debug("BVH: %u triangles on %d threads: boxes %.1f ms, top levels %.1f ms (%u nodes), %u tasks %.1f ms, "
             "layout %.1f ms",
             n, threads, 1e3 * (t1 - t0), 1e3 * (t2 - t1), b.top_count, b.task_count, 1e3 * (t3 - t2),
             1e3 * (sb_now_s() - t3));
done:
    if (begun)
        sb_status_end();
    free(b.prims);
    free(b.scratch);
    free(b.index);
    free(b.scratch_index);
    free(b.chunk_bins);
    free(b.chunks);
    free(b.tasks);
    free(b.task_order);
    free(b.top);
    free(b.top_task);
    free(b.frontier);
    free(b.frontier_next);
    free(b.split_out);
    free(task_nodes);
    if (res)
        sb_bvh_finish(bvh);
    return res;
}

/* ---- two levels: a BVH a mesh, a top level over the instances ------------------------------ */

/* The inverse of an affine 3 x 4 (rows); false when not finite or singular. */
static bool invert_affine(const double m[3][4], double out[3][4])
{
    double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                 m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                 m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    double scale = 0.0;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++) {
            if (!isfinite(m[r][c]))
                return false;
            if (c < 3)
                scale = fmax(scale, fabs(m[r][c]));
        }
    if (!isfinite(det) || fabs(det) <= 1e-12 * scale * scale * scale)
        return false;
    double inv[3][3];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) {
            int r1 = (c + 1) % 3, r2 = (c + 2) % 3, c1 = (r + 1) % 3, c2 = (r + 2) % 3;
            inv[r][c] = (m[r1][c1] * m[r2][c2] - m[r1][c2] * m[r2][c1]) / det;
        }
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++)
            out[r][c] = inv[r][c];
        out[r][3] = -(inv[r][0] * m[0][3] + inv[r][1] * m[1][3] + inv[r][2] * m[2][3]);
    }
    return true;
}

/* The world box of a mesh's root box placed by `to_world`, padded as a
 * triangle's (make_prims). */
static void instance_box(const struct sb_bvh_node *root, const double to_world[3][4], struct box *box)
{
    box_empty(box);
    for (int corner = 0; corner < 8; corner++) {
        double p[3] = {corner & 1 ? root->max[0] : root->min[0], corner & 2 ? root->max[1] : root->min[1],
                       corner & 4 ? root->max[2] : root->min[2]};
        float w[4] = {0};
        for (int r = 0; r < 3; r++)
            w[r] = (float)(to_world[r][0] * p[0] + to_world[r][1] * p[1] + to_world[r][2] * p[2] + to_world[r][3]);
        box_grow_point(box, w);
    }
    for (int i = 0; i < 3; i++) {
        float pad = 1e-6f * (max_f(fabsf(box->min[i]), fabsf(box->max[i])) + (box->max[i] - box->min[i]));
        box->min[i] -= pad;
        box->max[i] += pad;
    }
}

/* The top level over `n` instance boxes (serial: the meshes' builds take
 * the threads): one instance a leaf (first: its index, for now), split by
 * SAH, or halved in order where SAH finds nothing or the depth left would
 * not hold the rest halved. */
static uint32_t build_instance_top(const struct sides *sides, uint32_t n, struct sb_bvh_node *nodes, uint32_t *depth)
{
    struct range stack[(SB_BVH_MAX_DEPTH + 2) * 2];
    int top = 0;
    stack[top].begin = 0;
    stack[top].end = n;
    stack[top].depth = 0;
    stack[top].node = 0;
    stack[top].side = 0;
    range_bounds(sides->prims[0], 0, n, &stack[top].box, &stack[top].centroids);
    top++;
    uint32_t node_count = 1;
    *depth = 0;
    while (top) {
        struct range r = stack[--top], left, right;
        uint32_t count = r.end - r.begin;
        *depth = r.depth > *depth ? r.depth : *depth;
        if (count == 1) {
            set_node(&nodes[r.node], &r.box, sides->index[r.side][r.begin], SB_BVH_INSTANCE_LEAF);
            continue;
        }
        uint32_t levels = 0; /* to halve `count` down to ones */
        while ((1u << levels) < count)
            levels++;
        if (r.depth + levels >= SB_BVH_MAX_DEPTH ||
            !split_serial(sides, &r, 1, &left, &right)) {
            uint32_t mid = r.begin + count / 2;
            left = right = r;
            left.end = right.begin = mid;
            range_bounds(sides->prims[r.side], left.begin, left.end, &left.box, &left.centroids);
            range_bounds(sides->prims[r.side], right.begin, right.end, &right.box, &right.centroids);
            left.depth = right.depth = r.depth + 1;
        }
        left.node = node_count;
        right.node = node_count + 1;
        node_count += 2;
        set_node(&nodes[r.node], &r.box, left.node, 0);
        stack[top++] = right;
        stack[top++] = left;
    }
    return node_count;
}

enum sb_result sb_bvh_build_instanced(const struct sb_mesh *const *meshes, uint32_t mesh_count,
                                      const struct sb_bvh_instance *instances, uint32_t instance_count,
                                      struct sb_bvh *bvh)
{
    memset(bvh, 0, sizeof(*bvh));
    if (!instance_count || instance_count > SB_BVH_MISS / 4) {
        sb_error("BVH: %u instances (1 to %u)", instance_count, SB_BVH_MISS / 4);
        return instance_count ? SB_ERR_TOO_LARGE : SB_ERR_MESH;
    }
    for (uint32_t i = 0; i < instance_count; i++) {
        double inverse[3][4];
        if (instances[i].mesh >= mesh_count || !invert_affine(instances[i].to_world, inverse)) {
            sb_error("BVH: instance %u: %s", i,
                     instances[i].mesh >= mesh_count ? "of no mesh" : "its transform is not finite and invertible");
            return SB_ERR_MESH;
        }
    }
    struct sb_bvh *blas = calloc(mesh_count, sizeof(*blas));
    uint32_t *node_base = calloc(mesh_count, sizeof(*node_base));
    struct prim *prims = malloc(2 * (size_t)instance_count * sizeof(*prims));
    uint32_t *index = malloc(2 * (size_t)instance_count * sizeof(*index));
    struct sb_bvh_node *top = malloc(2 * (size_t)instance_count * sizeof(*top));
    enum sb_result res = blas && node_base && prims && index && top ? SB_OK : SB_ERR_NOMEM;
    uint64_t triangles = 0, nodes = 0, materials = 0;
    for (uint32_t m = 0; m < mesh_count && !res; m++) {
        res = sb_bvh_build(meshes[m], &blas[m]);
        triangles += blas[m].triangle_count;
        nodes += blas[m].node_count;
        materials += meshes[m]->material_count;
    }
    uint32_t top_count = 0, top_depth = 0;
    if (!res) {
        for (uint32_t i = 0; i < instance_count; i++) {
            instance_box(&blas[instances[i].mesh].nodes[0], instances[i].to_world, &prims[i].box);
            index[i] = i;
        }
        struct sides sides = {{prims, prims + instance_count}, {index, index + instance_count}};
        top_count = build_instance_top(&sides, instance_count, top, &top_depth);
        nodes += top_count + 2 * (uint64_t)instance_count;
        if (triangles >= SB_BVH_BACK_FACE || nodes >= SB_BVH_BACK_FACE || materials >= SB_BVH_BACK_FACE) {
            sb_error("BVH: %llu triangles, %llu nodes: past 2^31", (unsigned long long)triangles,
                     (unsigned long long)nodes);
            res = SB_ERR_TOO_LARGE;
        }
    }
    if (!res) {
        bvh->nodes = big_alloc(nodes * sizeof(*bvh->nodes));
        bvh->triangles = big_alloc(triangles * sizeof(*bvh->triangles));
        if (!bvh->nodes || !bvh->triangles)
            res = SB_ERR_NOMEM;
    }
    if (!res) {
        bvh->node_count = (uint32_t)nodes;
        bvh->triangle_count = (uint32_t)triangles;
        bvh->instance_count = instance_count;
        /* the top level, its leaves pointing at the records */
        for (uint32_t k = 0; k < top_count; k++) {
            bvh->nodes[k] = top[k];
            if (top[k].count == SB_BVH_INSTANCE_LEAF)
                bvh->nodes[k].first = top_count + 2 * top[k].first;
        }
        /* each mesh's nodes and triangles, offset */
        uint32_t next_node = top_count + 2 * instance_count, next_triangle = 0, next_material = 0;
        for (uint32_t m = 0; m < mesh_count; m++) {
            node_base[m] = next_node;
            for (uint32_t k = 0; k < blas[m].node_count; k++) {
                struct sb_bvh_node n = blas[m].nodes[k];
                n.first += n.count ? next_triangle : next_node;
                bvh->nodes[next_node + k] = n;
            }
            for (uint32_t k = 0; k < blas[m].triangle_count; k++) {
                struct sb_bvh_triangle t = blas[m].triangles[k];
                t.triangle += next_triangle;
                t.material += next_material;
                bvh->triangles[next_triangle + k] = t;
            }
            next_node += blas[m].node_count;
            next_triangle += blas[m].triangle_count;
            next_material += meshes[m]->material_count;
            bvh->depth = blas[m].depth > bvh->depth ? blas[m].depth : bvh->depth;
            bvh->max_leaf = blas[m].max_leaf > bvh->max_leaf ? blas[m].max_leaf : bvh->max_leaf;
        }
        bvh->depth += top_depth + 1;
        /* the records */
        for (uint32_t i = 0; i < instance_count; i++) {
            double inverse[3][4];
            invert_affine(instances[i].to_world, inverse);
            struct sb_bvh_instance_record rec = {.root = node_base[instances[i].mesh], .instance = i};
            for (int r = 0; r < 3; r++)
                for (int c = 0; c < 4; c++)
                    rec.to_object[r][c] = (float)inverse[r][c];
            memcpy(&bvh->nodes[top_count + 2 * i], &rec, sizeof(rec));
        }
    }
    for (uint32_t m = 0; blas && m < mesh_count; m++)
        sb_bvh_finish(&blas[m]);
    free(blas);
    free(node_base);
    free(prims);
    free(index);
    free(top);
    if (res)
        sb_bvh_finish(bvh);
    return res;
}

_Static_assert(sizeof(struct sb_bvh_instance_record) == 2 * sizeof(struct sb_bvh_node), "a record is two nodes");

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

static void inverse_direction(const float d[3], float inv_d[3])
{
    for (int i = 0; i < 3; i++) /* a zero component: a huge but finite slope keeps the slabs NaN-free */
        inv_d[i] = 1.0f / (fabsf(d[i]) > 1e-30f ? d[i] : copysignf(1e-30f, d[i]));
}

/* The stack entry that ends an instance's subtree: back to the world's ray. */
#define LEAVE_INSTANCE SB_BVH_MISS

bool sb_bvh_intersect(const struct sb_bvh *bvh, const float world_o[3], const float world_d[3], float tmin, float tmax,
                      bool any, struct sb_hit *hit)
{
    float o[3], d[3], inv_d[3];
    memcpy(o, world_o, sizeof(o));
    memcpy(d, world_d, sizeof(d));
    inverse_direction(d, inv_d);
    hit->triangle = SB_BVH_MISS;
    hit->instance = SB_BVH_NO_INSTANCE;
    uint32_t instance = SB_BVH_NO_INSTANCE;
    /* the top level's path, the instance's end, the mesh's path */
    uint32_t stack[2 * SB_BVH_MAX_DEPTH + 3];
    int top = 0;
    uint32_t node = 0;
    float t_enter;
    if (!hit_box(&bvh->nodes[0], o, inv_d, tmin, tmax, &t_enter))
        return false;
    for (;;) {
        const struct sb_bvh_node *n = &bvh->nodes[node];
        if (n->count == SB_BVH_INSTANCE_LEAF) {
            /* Into the mesh's space: an affine map keeps t. */
            struct sb_bvh_instance_record rec;
            memcpy(&rec, &bvh->nodes[n->first], sizeof(rec));
            for (int r = 0; r < 3; r++) {
                const float *m = rec.to_object[r];
                o[r] = m[0] * world_o[0] + m[1] * world_o[1] + m[2] * world_o[2] + m[3];
                d[r] = m[0] * world_d[0] + m[1] * world_d[1] + m[2] * world_d[2];
            }
            inverse_direction(d, inv_d);
            instance = rec.instance;
            stack[top++] = LEAVE_INSTANCE;
            node = rec.root;
            continue;
        }
        if (n->count) {
            for (uint32_t i = n->first; i < n->first + n->count; i++) {
                struct sb_hit h;
                if (hit_triangle(&bvh->triangles[i], o, d, tmin, tmax, &h)) {
                    tmax = h.t;
                    h.triangle = bvh->triangles[i].triangle;
                    h.instance = instance;
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
        for (;;) {
            if (!top)
                return hit->triangle != SB_BVH_MISS;
            node = stack[--top];
            if (node != LEAVE_INSTANCE)
                break;
            memcpy(o, world_o, sizeof(o));
            memcpy(d, world_d, sizeof(d));
            inverse_direction(d, inv_d);
            instance = SB_BVH_NO_INSTANCE;
        }
    }
}
