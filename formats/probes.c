#include "probes.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <xxhash.h>

#include "config.h"
#include "io.h"
#include "log.h"

_Static_assert(SB_PROBES_SIGHT_SIDE == SB_PROBE_SIGHT_SIDE && SB_PROBES_SIGHT_WORDS == SB_PROBE_SIGHT_WORDS,
               "the files hold the masks the baker makes");

static const char magic[8] = {'S', 'B', 'P', 'R', 'O', 'B', 'E', 'S'};
#define BYTE_ORDER_MARK 0x01020304u

static void put_u32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static void put_f32(uint8_t *p, float f)
{
    uint32_t v;
    memcpy(&v, &f, 4);
    put_u32(p, v);
}

static float get_f32(const uint8_t *p)
{
    uint32_t v = get_u32(p);
    float f;
    memcpy(&f, &v, 4);
    return f;
}

static void put_u64(uint8_t *p, uint64_t v)
{
    put_u32(p, (uint32_t)v);
    put_u32(p + 4, (uint32_t)(v >> 32));
}

static uint64_t get_u64(const uint8_t *p)
{
    return get_u32(p) | (uint64_t)get_u32(p + 4) << 32;
}

/* The range a channel's values must lie in, by its name. */
static void channel_range(const char *name, double *lo, double *hi)
{
    *lo = -1e5;
    *hi = 1e5; /* positions and offsets (m): the mesh's 10 km extent and more */
    if (!strcmp(name, "valid")) {
        *lo = 0;
        *hi = 1;
    } else if (strstr(name, "_fraction")) {
        *lo = 0;
        *hi = 1;
    } else if (!strncmp(name, "sh.", 3)) { /* |c_k| <= the norm of a function in [0, 1]: sqrt(4 pi) */
        *lo = -3.5449077018110318;
        *hi = 3.5449077018110318;
    } else if (!strcmp(name, "dering_window")) {
        *lo = 0;
        *hi = 2;
    } else if (!strncmp(name, "bounce.", 7) || !strncmp(name, "sun.", 4) || !strncmp(name, "sun_shape.", 10)) {
        *lo = -SB_SKY_BOUNCE_LIMIT; /* probes.h */
        *hi = SB_SKY_BOUNCE_LIMIT;
    } else if (!strncmp(name, "irradiance.", 11)) { /* radiance's units: finite is all that is known */
        *lo = -3e38;
        *hi = 3e38;
    } else if (!strcmp(name, "mean_distance_m")) {
        *lo = 0;
    }
}

/* A file's bytes: `sight` detail probes' sight masks (0: none), `tiles`
 * tiles, values of value_bytes (4: fp32, 2: binary16). */
static size_t file_size(uint32_t header, uint32_t columns, uint32_t tiles, uint32_t sight, uint32_t probes,
                        uint32_t channels, uint32_t value_bytes)
{
    return header + (size_t)columns * SB_PROBES_COLUMN_BYTES + (size_t)tiles * SB_PROBES_TILE_BYTES +
           (size_t)sight * SB_PROBES_SIGHT_WORDS * 4 + (size_t)probes * channels * value_bytes + 8;
}

void sb_probe_layout_finish(struct sb_probe_layout *layout)
{
    free(layout->columns);
    free(layout->sight);
    free(layout->tiles);
    layout->columns = NULL;
    layout->sight = NULL;
    layout->tiles = NULL;
    layout->column_count = 0;
    layout->detail_count = 0;
    layout->tile_count = 0;
}

enum sb_result sb_probe_layout_copy(struct sb_probe_layout *to, const struct sb_probe_layout *from)
{
    *to = *from;
    to->columns = NULL;
    to->sight = NULL;
    to->tiles = NULL;
    size_t sight = from->sight ? (size_t)from->detail_count * SB_PROBES_SIGHT_WORDS * sizeof(*to->sight) : 0;
    if (from->column_count && !(to->columns = malloc(from->column_count * sizeof(*to->columns))))
        goto fail;
    if (sight && !(to->sight = malloc(sight)))
        goto fail;
    if (from->tile_count && !(to->tiles = malloc(from->tile_count * sizeof(*to->tiles))))
        goto fail;
    if (from->column_count)
        memcpy(to->columns, from->columns, from->column_count * sizeof(*to->columns));
    if (sight)
        memcpy(to->sight, from->sight, sight);
    if (from->tile_count)
        memcpy(to->tiles, from->tiles, from->tile_count * sizeof(*to->tiles));
    return SB_OK;
fail:
    free(to->columns);
    free(to->sight);
    memset(to, 0, sizeof(*to));
    return SB_ERR_NOMEM;
}

/* A tile's coordinates packed to sort by z, then x. */
static uint64_t tile_code(int64_t x, int64_t z)
{
    return (uint64_t)(z + INT32_MAX) << 32 | (uint64_t)(x + INT32_MAX);
}

static int32_t tile_x(uint64_t code)
{
    return (int32_t)((int64_t)(uint32_t)code - INT32_MAX);
}

static int32_t tile_z(uint64_t code)
{
    return (int32_t)((int64_t)(code >> 32) - INT32_MAX);
}

static int compare_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* The tile along an axis of coordinate `at` (m), within +-1e9 tiles
 * (a hostile file's grid may reach past any real one: never a cast out of
 * range). */
static int64_t tile_of_coordinate(double at, double side)
{
    double t = floor(at / side);
    return !(t >= -1e9) ? -1000000000 : t > 1e9 ? 1000000000 : (int64_t)t; /* NaN: the lowest */
}

/* Each grid and detail probe's tile, packed (tile_code), into code[]. */
static void tile_codes(const struct sb_probe_layout *l, double side, uint64_t *code)
{
    uint64_t grid = (uint64_t)l->grid[0] * l->grid[1] * l->grid[2], i = 0;
    for (; i < grid; i++) {
        double x = (double)l->origin_m[0] + (double)(i % l->grid[0]) * l->spacing_m[0];
        double z = (double)l->origin_m[2] + (double)(i / l->grid[0] / l->grid[1]) * l->spacing_m[2];
        code[i] = tile_code(tile_of_coordinate(x, side), tile_of_coordinate(z, side));
    }
    for (uint32_t c = 0; c < l->column_count; c++) {
        const struct sb_probe_column *col = &l->columns[c];
        double x = (double)l->detail_origin_m[0] + (double)col->x * SB_PROBES_BRICK * l->detail_spacing_m;
        double z = (double)l->detail_origin_m[2] + (double)col->z * SB_PROBES_BRICK * l->detail_spacing_m;
        uint64_t k = tile_code(tile_of_coordinate(x, side), tile_of_coordinate(z, side));
        for (uint64_t j = 0; j < (uint64_t)col->rows * SB_PROBES_BRICK * SB_PROBES_BRICK; j++)
            code[i++] = k;
    }
}

enum sb_result sb_probe_tiles_assign(struct sb_probe_layout *layout, float side, uint32_t *tile_of)
{
    uint64_t grid = (uint64_t)layout->grid[0] * layout->grid[1] * layout->grid[2];
    uint64_t n = grid + layout->detail_count;
    free(layout->tiles);
    layout->tiles = NULL;
    layout->tile_count = 0;
    if (layout->explicit_count || !(side >= 1.0f && side <= 1e4f))
        return SB_ERR_PROBES;
    if (!n)
        return SB_OK;
    uint64_t *code = malloc(n * sizeof(*code)), *sorted = malloc(n * sizeof(*sorted));
    if (!code || !sorted) {
        free(code);
        free(sorted);
        return SB_ERR_NOMEM;
    }
    tile_codes(layout, side, code);
    memcpy(sorted, code, n * sizeof(*code));
    qsort(sorted, n, sizeof(*sorted), compare_u64);
    uint64_t tiles = 0;
    for (uint64_t i = 0; i < n; i++)
        tiles += !i || sorted[i] != sorted[i - 1];
    enum sb_result res = tiles > SB_PROBES_MAX_TILES ? SB_ERR_TOO_LARGE : SB_OK;
    if (!res && !(layout->tiles = calloc(tiles, sizeof(*layout->tiles))))
        res = SB_ERR_NOMEM;
    for (uint64_t i = 0, t = 0; i < n && !res; i++) {
        if (i && sorted[i] == sorted[i - 1]) {
            layout->tiles[t - 1].probes++;
            continue;
        }
        layout->tiles[t++] = (struct sb_probe_tile){.x = tile_x(sorted[i]), .z = tile_z(sorted[i]), .probes = 1};
    }
    if (!res) {
        layout->tile_count = (uint32_t)tiles;
        layout->tile_m = side;
        for (uint64_t i = 0; i < n && tile_of; i++) /* the tiles hold every code */
            tile_of[i] = (uint32_t)sb_probe_tile_find(layout, tile_x(code[i]), tile_z(code[i]));
    }
    free(code);
    free(sorted);
    return res;
}

int64_t sb_probe_tile_find(const struct sb_probe_layout *layout, int32_t x, int32_t z)
{
    uint32_t lo = 0, hi = layout->tile_count;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        const struct sb_probe_tile *t = &layout->tiles[mid];
        if (t->z < z || (t->z == z && t->x < x))
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < layout->tile_count && layout->tiles[lo].x == x && layout->tiles[lo].z == z ? (int64_t)lo : -1;
}

/* A record's stored bytes into `out` (value_bytes a value). */
static void store_record(const float *values, uint32_t channels, uint32_t value_bytes, uint8_t *out)
{
    for (uint32_t c = 0; c < channels; c++, out += value_bytes) {
        if (value_bytes == 2) {
            uint16_t h = sb_half_from_float(values[c]);
            out[0] = (uint8_t)h;
            out[1] = (uint8_t)(h >> 8);
        } else {
            put_f32(out, values[c]);
        }
    }
}

uint64_t sb_probe_tile_content(const struct sb_probe_layout *layout, const struct sb_image *image, bool half,
                               const uint32_t *probes, uint32_t count)
{
    uint64_t grid = (uint64_t)layout->grid[0] * layout->grid[1] * layout->grid[2];
    uint32_t value_bytes = half ? 2 : 4;
    uint8_t record[4 * SB_IMAGE_MAX_CHANNELS];
    XXH3_state_t *state = XXH3_createState();
    if (!state)
        return 0;
    XXH3_64bits_reset(state);
    for (uint32_t j = 0; j < count; j++) {
        store_record(&image->data[(size_t)probes[j] * image->channel_count], image->channel_count, value_bytes, record);
        XXH3_64bits_update(state, record, (size_t)image->channel_count * value_bytes);
    }
    for (uint32_t j = 0; j < count && layout->sight; j++)
        if (probes[j] >= grid)
            for (int w = 0; w < SB_PROBES_SIGHT_WORDS; w++) {
                put_u32(record, layout->sight[(probes[j] - grid) * SB_PROBES_SIGHT_WORDS + w]);
                XXH3_64bits_update(state, record, 4);
            }
    uint64_t h = XXH3_64bits_digest(state);
    XXH3_freeState(state);
    return h;
}

int64_t sb_probe_detail_index(const struct sb_probe_layout *layout, uint64_t grid_count, int32_t x, int32_t y,
                              int32_t z)
{
    if (x < 0 || z < 0 || y < 0)
        return -1;
    int32_t bx = x / SB_PROBES_BRICK, bz = z / SB_PROBES_BRICK;
    uint32_t lo = 0, hi = layout->column_count;
    uint64_t first = grid_count;
    while (lo < hi) {
        uint32_t mid = lo + (hi - lo) / 2;
        const struct sb_probe_column *c = &layout->columns[mid];
        if (c->z < bz || (c->z == bz && c->x < bx))
            lo = mid + 1;
        else
            hi = mid;
    }
    if (lo == layout->column_count || layout->columns[lo].x != bx || layout->columns[lo].z != bz)
        return -1;
    const struct sb_probe_column *c = &layout->columns[lo];
    if (y < c->y0 || (uint32_t)(y - c->y0) >= c->rows)
        return -1;
    /* the columns before it: their rows, summed (the runtime keeps them in a table) */
    for (uint32_t i = 0; i < lo; i++)
        first += (uint64_t)layout->columns[i].rows * SB_PROBES_BRICK * SB_PROBES_BRICK;
    return (int64_t)(first +
                     ((uint64_t)(y - c->y0) * SB_PROBES_BRICK + (uint32_t)(z % SB_PROBES_BRICK)) * SB_PROBES_BRICK +
                     (uint32_t)(x % SB_PROBES_BRICK));
}

/* Probe `mask`'s sight of q, its lattice point at `lattice` (probes.glsl's
 * probe_sees, in fp64). */
static double sight_of(const uint32_t *mask, const double lattice[3], const double q[3], double spacing)
{
    const double side = SB_PROBES_SIGHT_SIDE;
    double t[3], f[3];
    int b[3];
    for (int k = 0; k < 3; k++) {
        t[k] = fmin(fmax(((q[k] - lattice[k]) / spacing + 1.0) * 0.5 * side - 0.5, 0.0), side - 1.0);
        b[k] = (int)fmin(floor(t[k]), side - 2.0);
        f[k] = t[k] - b[k];
    }
    double seen = 0;
    for (int corner = 0; corner < 8; corner++) {
        int o[3] = {corner & 1, corner >> 1 & 1, corner >> 2 & 1};
        uint32_t bit = (uint32_t)(((b[2] + o[2]) * SB_PROBES_SIGHT_SIDE + b[1] + o[1]) * SB_PROBES_SIGHT_SIDE + b[0] + o[0]);
        if (mask[bit >> 5] >> (bit & 31) & 1u)
            seen += (o[0] ? f[0] : 1 - f[0]) * (o[1] ? f[1] : 1 - f[1]) * (o[2] ? f[2] : 1 - f[2]);
    }
    return seen;
}

double sb_probe_detail_sight(const struct sb_probe_layout *layout, uint64_t grid_count, const float *valid,
                             size_t valid_stride, const double q[3])
{
    if (!layout->detail_count || !(layout->detail_spacing_m > 0))
        return -1;
    double h = layout->detail_spacing_m, best = -1;
    int32_t cell[3];
    for (int k = 0; k < 3; k++) {
        double at = floor((q[k] - layout->detail_origin_m[k]) / h);
        if (!(at >= 0 && at < SB_PROBES_MAX_LATTICE))
            return -1;
        cell[k] = (int32_t)at;
    }
    for (int corner = 0; corner < 8; corner++) {
        int32_t x = cell[0] + (corner & 1), y = cell[1] + (corner >> 1 & 1), z = cell[2] + (corner >> 2 & 1);
        int64_t i = sb_probe_detail_index(layout, grid_count, x, y, z);
        if (i < 0)
            continue;
        best = fmax(best, 0.0);
        if (valid[(size_t)i * valid_stride] == 0)
            continue;
        double lattice[3] = {layout->detail_origin_m[0] + x * h, layout->detail_origin_m[1] + y * h,
                             layout->detail_origin_m[2] + z * h};
        best = fmax(best, layout->sight ? sight_of(&layout->sight[((uint64_t)i - grid_count) * SB_PROBES_SIGHT_WORDS],
                                                   lattice, q, h)
                                        : 1.0);
    }
    return best;
}

void sb_probes_content_hash(const struct sb_image *image, const struct sb_probe_layout *layout,
                            char out[SB_HASH_HEX_SIZE])
{
    sb_image_content_hash(image, out);
    if (!layout->sight)
        return;
    static const char tag[] = "skybake-probe-sight-v1";
    XXH3_state_t *state = XXH3_createState();
    XXH3_128bits_reset(state);
    XXH3_128bits_update(state, tag, sizeof(tag));
    XXH3_128bits_update(state, out, SB_HASH_HEX_SIZE - 1);
    uint8_t chunk[4096];
    uint64_t n = (uint64_t)layout->detail_count * SB_PROBES_SIGHT_WORDS;
    for (uint64_t i = 0; i < n;) {
        size_t k = 0;
        for (; k + 4 <= sizeof(chunk) && i < n; k += 4, i++)
            put_u32(chunk + k, layout->sight[i]);
        XXH3_128bits_update(state, chunk, k);
    }
    XXH128_hash_t h = XXH3_128bits_digest(state);
    XXH3_freeState(state);
    snprintf(out, SB_HASH_HEX_SIZE, "%016llx%016llx", (unsigned long long)h.high64, (unsigned long long)h.low64);
}

enum sb_result sb_probes_write(const char *path, const struct sb_probe_layout *layout, const struct sb_image *image,
                               bool half)
{
    /* the oldest version that holds the layout and the values: without
     * layers or detail, in fp32, version 1, and the files are what they
     * were */
    uint32_t version = layout->tile_count ? 6
                       : half             ? 5
                       : layout->sight    ? 4
                       : layout->column_count ? 3
                       : layout->layer_count  ? 2
                                              : 1;
    uint32_t header = version >= 3   ? SB_PROBES_HEADER_BYTES
                      : version == 2 ? SB_PROBES_HEADER_BYTES_V2
                                     : SB_PROBES_HEADER_BYTES_V1;
    uint32_t sight = layout->sight && layout->column_count ? layout->detail_count : 0, value_bytes = half ? 2 : 4;
    if (half && sb_image_find_not_half(image) >= 0) {
        sb_error("%s: values that binary16 does not hold exactly, for a file stored as half", path);
        return SB_ERR_NUMERIC;
    }
    size_t size = file_size(header, layout->column_count, layout->tile_count, sight, image->width,
                            image->channel_count, value_bytes);
    uint8_t *bytes = calloc(1, size);
    if (!bytes)
        return SB_ERR_NOMEM;
    memcpy(bytes, magic, 8);
    put_u32(bytes + 8, version);
    put_u32(bytes + 12, BYTE_ORDER_MARK);
    put_u32(bytes + 16, header);
    put_u32(bytes + 20, image->channel_count);
    put_u32(bytes + 24, image->width);
    for (int i = 0; i < 3; i++) {
        put_u32(bytes + 28 + 4 * i, layout->grid[i]);
        put_f32(bytes + 44 + 4 * i, layout->origin_m[i]);
        put_f32(bytes + 56 + 4 * i, layout->spacing_m[i]);
    }
    put_u32(bytes + 40, layout->explicit_count);
    put_u32(bytes + 68, layout->ray_count);
    memcpy(bytes + 72, layout->key, strnlen(layout->key, 32));
    if (layout->layer_count) {
        put_u32(bytes + 104, layout->layer_count);
        for (uint32_t l = 0; l < layout->layer_count; l++)
            put_f32(bytes + 108 + 4 * l, layout->layers_m[l]);
    }
    uint8_t *p = bytes + header;
    if (version >= 3 && layout->column_count) {
        put_f32(bytes + 140, layout->detail_spacing_m);
        for (int k = 0; k < 3; k++)
            put_f32(bytes + 144 + 4 * k, layout->detail_origin_m[k]);
        put_u32(bytes + 156, layout->column_count);
        put_u32(bytes + 160, layout->detail_count);
        for (uint32_t c = 0; c < layout->column_count; c++, p += SB_PROBES_COLUMN_BYTES) {
            const struct sb_probe_column *col = &layout->columns[c];
            put_u32(p, (uint32_t)col->x);
            put_u32(p + 4, (uint32_t)col->z);
            put_u32(p + 8, (uint32_t)col->y0);
            put_u32(p + 12, col->rows);
        }
    }
    if (layout->tile_count) {
        put_f32(bytes + 172, layout->tile_m);
        put_f32(bytes + 176, layout->reach_m);
        put_u32(bytes + 180, layout->tile_count);
        for (uint32_t t = 0; t < layout->tile_count; t++, p += SB_PROBES_TILE_BYTES) {
            const struct sb_probe_tile *tile = &layout->tiles[t];
            put_u32(p, (uint32_t)tile->x);
            put_u32(p + 4, (uint32_t)tile->z);
            put_u32(p + 8, tile->probes);
            put_u32(p + 12, tile->flags);
            for (int i = 0; i < 16 && tile->key[0]; i++) {
                unsigned v;
                sscanf(tile->key + 2 * i, "%2x", &v);
                p[16 + i] = (uint8_t)v;
            }
            put_u64(p + 32, tile->content);
        }
    }
    if (sight) {
        put_u32(bytes + 164, SB_PROBES_SIGHT_SIDE);
        for (uint64_t i = 0; i < (uint64_t)sight * SB_PROBES_SIGHT_WORDS; i++, p += 4)
            put_u32(p, layout->sight[i]);
    }
    if (version >= 5)
        put_u32(bytes + 168, value_bytes);
    for (uint32_t i = 0; i < image->width; i++, p += (size_t)value_bytes * image->channel_count)
        store_record(&image->data[(size_t)i * image->channel_count], image->channel_count, value_bytes, p);
    put_u64(p, XXH3_64bits(bytes, size - 8));

    enum sb_result res = sb_write_file(path, bytes, size, "probe file");
    free(bytes);
    return res;
}

/* A version 3 file's detail: its lattice and brick columns, checked
 * (finite, in range, sorted, their probes summing to `detail`); nonzero
 * on a problem, logged. */
static int check_detail(const uint8_t *b, uint32_t header, uint32_t columns, uint32_t detail, const char *source,
                        struct sb_probe_layout *layout)
{
    float spacing = get_f32(b + 140);
    if (!(spacing >= 0.01f && spacing <= 1000.0f)) {
        sb_error("%s: detail spacing %g m: expected 0.01 to 1000", source, spacing);
        return 1;
    }
    for (int k = 0; k < 3; k++) {
        layout->detail_origin_m[k] = get_f32(b + 144 + 4 * k);
        if (!(fabsf(layout->detail_origin_m[k]) <= 1e5f)) {
            sb_error("%s: the detail lattice's origin %c is %g: expected a finite value within 1e5 m", source, "xyz"[k],
                     layout -> detail_origin_m[k]);
            return 1;
        }
    }
    layout->detail_spacing_m = spacing;
    struct sb_probe_column *c = malloc(columns * sizeof(*c));
    if (!c) {
        sb_error("%s: out of memory for %u brick columns", source, columns);
        return 1;
    }
    uint64_t sum = 0;
    const int32_t most = SB_PROBES_MAX_LATTICE / SB_PROBES_BRICK;
    for (uint32_t i = 0; i < columns; i++) {
        const uint8_t *r = b + header + (size_t)i * SB_PROBES_COLUMN_BYTES;
        c[i] = (struct sb_probe_column){(int32_t)get_u32(r), (int32_t)get_u32(r + 4), (int32_t)get_u32(r + 8),
                                        get_u32(r + 12)};
        bool in_range = c[i].x >= 0 && c[i].x < most && c[i].z >= 0 && c[i].z < most && c[i].y0 >= 0 &&
                        c[i].rows >= 1 && (uint64_t)c[i].y0 + c[i].rows <= SB_PROBES_MAX_LATTICE;
        bool after = !i || c[i].z > c[i - 1].z || (c[i].z == c[i - 1].z && c[i].x > c[i - 1].x);
        if (!in_range || !after) {
            sb_error("%s: brick column %u (x %d, z %d, rows %d + %u): %s", source, i, c[i].x, c[i].z, c[i].y0,
                     c[i].rows,
                     in_range ? "not after the one before it (increasing z, then x)"
                              : "out of the lattice's range (x, z, y0 >= 0, rows >= 1, 65536 steps)");
            free(c);
            return 1;
        }
        sum += (uint64_t)c[i].rows * SB_PROBES_BRICK * SB_PROBES_BRICK;
    }
    if (sum != detail) {
        sb_error("%s: the brick columns hold %llu probes, the header says %u", source, (unsigned long long)sum, detail);
        free(c);
        return 1;
    }
    layout->columns = c;
    layout->column_count = columns;
    layout->detail_count = detail;
    return 0;
}

/* A version 4 file's sight masks (`sight` of them at p; none: 0): every
 * bit pattern is a mask; nonzero when out of memory, logged. */
static int read_sight(const uint8_t *p, uint32_t sight, const char *source, struct sb_probe_layout *layout)
{
    if (!sight)
        return 0;
    uint64_t n = (uint64_t)sight * SB_PROBES_SIGHT_WORDS;
    uint32_t *words = malloc(n * sizeof(*words));
    if (!words) {
        sb_error("%s: out of memory for %u sight masks", source, sight);
        return 1;
    }
    for (uint64_t i = 0; i < n; i++)
        words[i] = get_u32(p + 4 * i);
    layout->sight = words;
    return 0;
}

/* A version 6 file's tiles (`tiles` records at p), checked against the
 * tiles the layout's probes fall in, each baked tile's content against
 * its records (at `values`) and sight masks (at `sight`; NULL: none), and
 * each other tile's records and masks zero; nonzero on a problem, logged. */
static int read_tiles(const uint8_t *p, uint32_t tiles, float side, const uint8_t *values, uint32_t channels,
                      uint32_t value_bytes, const uint8_t *sight, const char *source, struct sb_probe_layout *layout)
{
    uint64_t grid = (uint64_t)layout->grid[0] * layout->grid[1] * layout->grid[2];
    uint64_t n = grid + layout->detail_count;
    struct sb_probe_layout expect = *layout; /* its own tiles, nothing else owned */
    expect.tiles = NULL;
    uint32_t *tile_of = malloc((n ? n : 1) * sizeof(*tile_of)), *order = malloc((n ? n : 1) * sizeof(*order)),
             *first = calloc((size_t)tiles + 1, sizeof(*first));
    struct sb_probe_tile *t = calloc(tiles, sizeof(*t));
    int bad = !tile_of || !order || !first || !t;
    if (bad)
        sb_error("%s: out of memory for %u tiles", source, tiles);
    if (!bad && (bad = sb_probe_tiles_assign(&expect, side, tile_of) != SB_OK))
        sb_error("%s: the probes fall in more than %u tiles of %g m", source, SB_PROBES_MAX_TILES, side);
    if (!bad && (bad = expect.tile_count != tiles))
        sb_error("%s: %u tiles, but the probes fall in %u tiles of %g m", source, tiles, expect.tile_count, side);
    for (uint32_t i = 0; i < tiles && !bad; i++) {
        const uint8_t *r = p + (size_t)i * SB_PROBES_TILE_BYTES;
        t[i].x = (int32_t)get_u32(r);
        t[i].z = (int32_t)get_u32(r + 4);
        t[i].probes = get_u32(r + 8);
        t[i].flags = get_u32(r + 12);
        t[i].content = get_u64(r + 32);
        bool keyed = false;
        for (int k = 0; k < 16; k++)
            keyed |= r[16 + k] != 0;
        if (t[i].x != expect.tiles[i].x || t[i].z != expect.tiles[i].z || t[i].probes != expect.tiles[i].probes) {
            sb_error("%s: tile %u (x %d, z %d, %u probes): the probes make tile %u x %d, z %d of %u probes", source, i,
                     t[i].x, t[i].z, t[i].probes, i, expect.tiles[i].x, expect.tiles[i].z, expect.tiles[i].probes);
            bad = 1;
        } else if (t[i].flags & ~SB_PROBES_TILE_BAKED) {
            sb_error("%s: tile %u: flags 0x%x, only bit 0 (baked) is defined", source, i, t[i].flags);
            bad = 1;
        } else if (!(t[i].flags & SB_PROBES_TILE_BAKED) && (keyed || t[i].content)) {
            sb_error("%s: tile %u is not baked but has a key or a content hash", source, i);
            bad = 1;
        }
        if (!bad && keyed)
            for (int k = 0; k < 16; k++)
                snprintf(t[i].key + 2 * k, 3, "%02x", r[16 + k]);
    }
    /* each tile's probes in order: a counting sort */
    for (uint64_t i = 0; i < n && !bad; i++)
        first[tile_of[i] + 1]++;
    for (uint32_t i = 0; i < tiles && !bad; i++)
        first[i + 1] += first[i];
    for (uint64_t i = 0; i < n && !bad; i++)
        order[first[tile_of[i]]++] = (uint32_t)i;
    for (uint32_t i = tiles; i > 0 && !bad; i--)
        first[i] = first[i - 1];
    if (!bad)
        first[0] = 0;
    size_t record = (size_t)channels * value_bytes, mask = 4 * SB_PROBES_SIGHT_WORDS;
    XXH3_state_t *state = bad ? NULL : XXH3_createState();
    bad |= !state;
    for (uint32_t i = 0; i < tiles && !bad; i++) {
        bool baked = t[i].flags & SB_PROBES_TILE_BAKED, zero = true;
        XXH3_64bits_reset(state);
        for (uint32_t j = first[i]; j < first[i + 1]; j++) {
            const uint8_t *at = values + order[j] * record;
            if (baked)
                XXH3_64bits_update(state, at, record);
            for (size_t k = 0; k < record && !baked; k++)
                zero &= at[k] == 0;
        }
        for (uint32_t j = first[i]; j < first[i + 1] && sight; j++) {
            if (order[j] < grid)
                continue;
            const uint8_t *at = sight + (order[j] - grid) * mask;
            if (baked)
                XXH3_64bits_update(state, at, mask);
            for (size_t k = 0; k < mask && !baked; k++)
                zero &= at[k] == 0;
        }
        if (baked && XXH3_64bits_digest(state) != t[i].content) {
            sb_error("%s: tile %u (x %d, z %d): its probes do not hash to its content", source, i, t[i].x, t[i].z);
            bad = 1;
        } else if (!baked && !zero) {
            sb_error("%s: tile %u (x %d, z %d) is not baked but its probes are not zero", source, i, t[i].x, t[i].z);
            bad = 1;
        }
    }
    XXH3_freeState(state);
    free(expect.tiles);
    free(tile_of);
    free(order);
    free(first);
    if (bad) {
        free(t);
        return 1;
    }
    layout->tiles = t;
    layout->tile_count = tiles;
    layout->tile_m = side;
    return 0;
}

enum sb_result sb_probes_parse(const void *data, size_t size, const char *source, const char *channel_names,
                               uint32_t max_probes, struct sb_probe_layout *layout, struct sb_image *image)
{
    const uint8_t *b = data;
    memset(layout, 0, sizeof(*layout));
    memset(image, 0, sizeof(*image));
    if (size < 16 || memcmp(b, magic, 8) != 0) {
        sb_error("%s: not a skybake probe file (magic)", source);
        return SB_ERR_PROBES;
    }
    uint32_t version = get_u32(b + 8);
    if (version > SB_PROBES_VERSION || version == 0) {
        sb_error("%s: probe file version %u; this skybake reads 1 to %d: rebake needed", source, version,
                 SB_PROBES_VERSION);
        return SB_ERR_VERSION;
    }
    if (get_u32(b + 12) != BYTE_ORDER_MARK) {
        sb_error("%s: byte-order mark 0x%08x, expected 0x%08x (little endian)", source, get_u32(b + 12),
                 BYTE_ORDER_MARK);
        return SB_ERR_PROBES;
    }
    if (size < SB_PROBES_HEADER_BYTES_V1 + 8) {
        sb_error("%s: %zu bytes, shorter than the header and checksum", source, size);
        return SB_ERR_BAD_IMAGE;
    }
    uint32_t header = get_u32(b + 16), channels = get_u32(b + 20), count = get_u32(b + 24);
    uint32_t grid[3] = {get_u32(b + 28), get_u32(b + 32), get_u32(b + 36)}, explicit_count = get_u32(b + 40);
    uint32_t expect_header = version == 1   ? SB_PROBES_HEADER_BYTES_V1
                             : version == 2 ? SB_PROBES_HEADER_BYTES_V2
                                            : SB_PROBES_HEADER_BYTES;
    if (header != expect_header) {
        sb_error("%s: header of %u bytes, version %u has %u", source, header, version, expect_header);
        return SB_ERR_PROBES;
    }
    if (size < header + 8) {
        sb_error("%s: %zu bytes, shorter than the header and checksum", source, size);
        return SB_ERR_BAD_IMAGE;
    }
    uint32_t layers = version == 1 ? 0 : get_u32(b + 104);
    if ((version == 2 && layers < 1) ||
        (version > 1 && (layers > SB_PROBES_MAX_LAYERS || (layers && layers != grid[1])))) {
        sb_error("%s: %u layers in a grid %u high: %d to %d, the grid's y", source, layers, grid[1],
                 version == 2 ? 1 : 0, SB_PROBES_MAX_LAYERS);
        return SB_ERR_PROBES;
    }
    /* versions 3 and 4 hold detail (4: with sight masks); version 5 may
     * (no brick columns: none), with masks or not */
    uint32_t columns = version >= 3 ? get_u32(b + 156) : 0, detail = version >= 3 ? get_u32(b + 160) : 0;
    bool has_detail = columns > 0;
    if ((version == 3 || version == 4 || columns) && (columns < 1 || columns > SB_PROBES_MAX_COLUMNS)) {
        sb_error("%s: %u brick columns of detail: 1 to %u", source, columns, SB_PROBES_MAX_COLUMNS);
        return SB_ERR_PROBES;
    }
    uint32_t side = version >= 4 ? get_u32(b + 164) : 0;
    if ((version == 4 || side) && (side != SB_PROBES_SIGHT_SIDE || !has_detail)) {
        sb_error("%s: sight masks of %u samples an axis%s: this skybake reads %d, over detail", source, side,
                 has_detail ? "" : " without detail", SB_PROBES_SIGHT_SIDE);
        return SB_ERR_PROBES;
    }
    uint32_t sight = side ? detail : 0;
    uint32_t value_bytes = version >= 5 ? get_u32(b + 168) : 4;
    if (version == 6 ? value_bytes != 2 && value_bytes != 4 : value_bytes != (version == 5 ? 2u : 4u)) {
        sb_error("%s: values of %u bytes: version %u stores %s", source, value_bytes, version,
                 version == 6   ? "binary16 (2) or fp32 (4)"
                 : version == 5 ? "binary16 (2)"
                                : "fp32 (4)");
        return SB_ERR_PROBES;
    }
    uint32_t tiles = version == 6 ? get_u32(b + 180) : 0;
    float tile_m = version == 6 ? get_f32(b + 172) : 0, reach_m = version == 6 ? get_f32(b + 176) : 0;
    if (version == 6 && (tiles < 1 || tiles > SB_PROBES_MAX_TILES || !(tile_m >= 1 && tile_m <= 1e4f) ||
                         !(reach_m > 0 && reach_m <= 1e5f) || explicit_count)) {
        sb_error("%s: %u tiles of %g m, rays reaching %g m, %u explicit probes: expected 1 to %u tiles of 1 to 1e4 m, "
                 "a reach in (0, 1e5] m and no explicit probes",
                 source, tiles, tile_m, reach_m, explicit_count, SB_PROBES_MAX_TILES);
        return SB_ERR_PROBES;
    }
    struct sb_image names = {0};
    sb_image_set_channel_names(&names, channel_names);
    uint32_t expect = 0;
    while (expect < SB_IMAGE_MAX_CHANNELS && names.channel_names[expect][0])
        expect++;
    if (channels != expect) {
        sb_error("%s: %u channels a probe, the product has %u (%s)", source, channels, expect, channel_names);
        return SB_ERR_BAD_IMAGE;
    }
    uint64_t grid_count = 1;
    for (int i = 0; i < 3; i++) {
        if (grid[i] > SB_PROBES_MAX_GRID || (!grid[i]) != (!grid[0])) {
            sb_error("%s: grid %u x %u x %u: each 1 to %u, or all 0", source, grid[0], grid[1], grid[2],
                     SB_PROBES_MAX_GRID);
            return SB_ERR_PROBES;
        }
        grid_count *= grid[i];
    }
    if (!count || count > max_probes || count > SB_PROBES_MAX_COUNT ||
        grid_count + detail + (uint64_t)explicit_count != count) {
        sb_error("%s: %u probes (grid %llu, detail %u, explicit %u): expected their sum, 1 to %u", source, count,
                 (unsigned long long)grid_count, detail, explicit_count,
                 max_probes < SB_PROBES_MAX_COUNT ? max_probes : SB_PROBES_MAX_COUNT);
        return SB_ERR_PROBES;
    }
    size_t expect_size = file_size(header, columns, tiles, sight, count, channels, value_bytes);
    if (size != expect_size) {
        sb_error("%s: %zu bytes, %u brick columns, %u tiles, %u sight masks and %u probes of %u channels take %zu",
                 source, size, columns, tiles, sight, count, channels, expect_size);
        return SB_ERR_BAD_IMAGE;
    }
    if (get_u64(b + size - 8) != XXH3_64bits(b, size - 8)) {
        sb_error("%s: the checksum does not match: the file was changed or corrupted", source);
        return SB_ERR_HASH_MISMATCH;
    }
    for (uint32_t i = version == 1 ? 104 : 108 + 4 * layers; i < header; i++)
        if (b[i] && !(has_detail && i >= 140 && i < 164) && !(sight && i >= 164 && i < 168) &&
            !(version >= 5 && i >= 168 && i < 172) && !(version == 6 && i >= 172 && i < 184)) {
            sb_error("%s: reserved header byte %u is not zero", source, i);
            return SB_ERR_PROBES;
        }
    for (uint32_t l = 0; l < layers; l++) {
        float h = get_f32(b + 108 + 4 * l);
        if (!(h >= 0 && h <= 1e4) || (l && !(h > layout->layers_m[l - 1]))) {
            sb_error("%s: layer %u at %g m: expected heights in [0, 1e4] m, each above the one before", source, l, h);
            memset(layout, 0, sizeof(*layout));
            return SB_ERR_PROBES;
        }
        layout->layers_m[l] = h;
    }
    layout->layer_count = layers;
    for (int i = 0; i < 3; i++) {
        layout->grid[i] = grid[i];
        layout->origin_m[i] = get_f32(b + 44 + 4 * i);
        layout->spacing_m[i] = get_f32(b + 56 + 4 * i);
        if (!isfinite(layout->origin_m[i]) || !isfinite(layout->spacing_m[i]) ||
            (grid[0] && !(layout->spacing_m[i] > 0))) {
            sb_error("%s: grid origin or spacing %d is not finite, or a spacing not positive", source, i);
            memset(layout, 0, sizeof(*layout));
            return SB_ERR_PROBES;
        }
    }
    layout->explicit_count = explicit_count;
    layout->ray_count = get_u32(b + 68);
    for (int i = 0; i < 32; i++) {
        char c = (char)b[72 + i];
        if (!(c >= '0' && c <= '9') && !(c >= 'a' && c <= 'f') && !(c == 0 && i == 0)) {
            sb_error("%s: the bake key is not 32 lowercase hex digits (or empty)", source);
            memset(layout, 0, sizeof(*layout));
            return SB_ERR_PROBES;
        }
        if (c == 0)
            break;
    }
    memcpy(layout->key, b + 72, 32);
    layout->key[32] = '\0';
    const uint8_t *tile_records = b + header + (size_t)columns * SB_PROBES_COLUMN_BYTES;
    const uint8_t *masks = tile_records + (size_t)tiles * SB_PROBES_TILE_BYTES;
    const uint8_t *values = masks + (size_t)sight * SB_PROBES_SIGHT_WORDS * 4;
    if ((has_detail && (check_detail(b, header, columns, detail, source, layout) ||
                        read_sight(masks, sight, source, layout))) ||
        (tiles && read_tiles(tile_records, tiles, tile_m, values, channels, value_bytes, sight ? masks : NULL,
                             source, layout))) {
        sb_probe_layout_finish(layout);
        memset(layout, 0, sizeof(*layout));
        return SB_ERR_PROBES;
    }
    layout->reach_m = reach_m;
    enum sb_result res = sb_image_init(image, count, 1, channels);
    if (res) {
        sb_probe_layout_finish(layout);
        memset(layout, 0, sizeof(*layout));
        return res;
    }
    sb_image_set_channel_names(image, channel_names);
    const uint8_t *p = values;
    layout->half = value_bytes == 2;
    for (uint32_t c = 0; c < channels && !res; c++) {
        double lo, hi;
        channel_range(image->channel_names[c], &lo, &hi);
        for (uint32_t i = 0; i < count; i++) {
            const uint8_t *at = p + value_bytes * ((size_t)i * channels + c);
            float v = value_bytes == 2 ? sb_half_to_float((uint16_t)(at[0] | at[1] << 8)) : get_f32(at);
            bool flag = !strcmp(image->channel_names[c], "valid"); /* 0 or 1, nothing between */
            if (!isfinite(v) || v < lo || v > hi || (flag && v != 0.0f && v != 1.0f)) {
                sb_error("%s: probe %u channel %s is %g, expected a finite value in [%g, %g]", source, i,
                         image->channel_names[c], v, lo, hi);
                res = SB_ERR_NUMERIC;
                break;
            }
            image->data[(size_t)i * channels + c] = v;
        }
    }
    if (res) {
        sb_image_finish(image);
        sb_probe_layout_finish(layout);
        memset(layout, 0, sizeof(*layout));
    }
    return res;
}

enum sb_result sb_probes_read(const char *path, const char *channel_names, uint32_t max_probes,
                              struct sb_probe_layout *layout, struct sb_image *image)
{
    memset(layout, 0, sizeof(*layout));
    memset(image, 0, sizeof(*image));
    int fd = sb_open_regular(AT_FDCWD, path, false, NULL);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0) {
        sb_error("%s: cannot read: %s", path, errno == EINVAL ? "not a regular file" : strerror(errno));
        if (fd >= 0)
            close(fd);
        return SB_ERR_IO;
    }
    size_t largest = file_size(SB_PROBES_HEADER_BYTES, SB_PROBES_MAX_COUNT / (SB_PROBES_BRICK * SB_PROBES_BRICK),
                               SB_PROBES_MAX_TILES, SB_PROBES_MAX_COUNT, SB_PROBES_MAX_COUNT, SB_IMAGE_MAX_CHANNELS, 4);
    if (!S_ISREG(st.st_mode) || (uint64_t)st.st_size > largest) {
        sb_error("%s: not a regular file of at most %zu bytes", path, largest);
        close(fd);
        return S_ISREG(st.st_mode) ? SB_ERR_TOO_LARGE : SB_ERR_IO;
    }
    size_t size = (size_t)st.st_size;
    uint8_t *bytes = malloc(size ? size : 1);
    enum sb_result res = bytes ? SB_OK : SB_ERR_NOMEM;
    if (!res && !sb_read_all(fd, bytes, size)) {
        sb_error("%s: cannot read: %s", path, errno ? strerror(errno) : "shorter than it was");
        res = SB_ERR_IO;
    }
    close(fd);
    if (!res)
        res = sb_probes_parse(bytes, size, path, channel_names, max_probes, layout, image);
    free(bytes);
    return res;
}
