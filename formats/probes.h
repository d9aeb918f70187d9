/*
 * Probe files (.sbprobes): a set of probes with one record each (fp32, or binary16), in
 * skybake's own small binary format (docs/pack.md, "Probe files"). Little
 * endian throughout:
 *
 *   offset  size  field
 *        0     8  magic "SBPROBES"
 *        8     4  format version (1; 2: a grid that follows the surface; 3:
 *                 detail; 4: detail with its sight masks; 5: values stored
 *                 as binary16; 6: tiles)
 *       12     4  byte-order mark 0x01020304
 *       16     4  header bytes (112; version 2: 152)
 *       20     4  channels per probe
 *       24     4  probe count (grid probes, then explicit ones)
 *       28    12  grid probes along x, y, z (0 0 0: no grid)
 *       40     4  explicit probes
 *       44    12  the grid's first probe, metres
 *       56    12  the grid's spacing, metres
 *       68     4  rays per probe
 *       72    32  the bake key that produced it, lowercase hex
 *   version 1:
 *      104     8  reserved, zero
 *   version 2:
 *      104     4  layers L (1 to 8): the grid's y counts them
 *      108    32  each layer's height above the surface, metres, increasing
 *                 (float32; past L, zero)
 *      140    12  reserved, zero
 *   version 3 (detail):
 *      104    36  as version 2, but L may be 0 (a uniform grid, or none)
 *      140     4  the detail's spacing, metres
 *      144    12  the detail lattice's first probe, metres
 *      156     4  brick columns C (1 to 2^18)
 *      160     4  detail probes D
 *      164    28  reserved, zero
 *   version 4 (detail with its sight masks):
 *      104    60  as version 3
 *      164     4  the sight masks' samples along an axis: SB_PROBES_SIGHT_SIDE (8)
 *      168    24  reserved, zero
 *   version 5 (values as binary16):
 *      104    64  as version 4, but C may be 0 (no detail: bytes 140 to
 *                 163 zero) and byte 164 0 (no sight masks; 8 needs detail)
 *      168     4  bytes a value: 2
 *      172    20  reserved, zero
 *   version 6 (tiles):
 *      104    64  as version 5
 *      168     4  bytes a value: 2 (binary16) or 4 (fp32)
 *      172     4  the tiles' side, metres (float32, 1 to 1e4)
 *      176     4  the rays' reach, metres (float32, > 0: past it a ray sees
 *                 the sky)
 *      180     4  tiles T (1 to SB_PROBES_MAX_TILES)
 *      184     8  reserved, zero
 *   header     -  versions 3 to 6: C brick columns of 16 bytes: x, z
 *                 (int32, in bricks of SB_PROBES_BRICK lattice steps), the
 *                 lowest lattice row y0 (int32) and the rows (uint32), in
 *                 increasing z then x, each once
 *      then    -  version 6: T tiles of 40 bytes: x, z (int32: the tile
 *                 covers x to x + 1 sides along x from 0, likewise z), its
 *                 probes (uint32, >= 1), flags (uint32: bit 0 baked, the
 *                 rest zero), the XXH3-128 bake key of its probes (16
 *                 bytes, high half first, big endian; zero when not baked)
 *                 and the XXH3-64 of their stored records then sight masks
 *                 (uint64; zero when not baked, and so are its records), in
 *                 increasing z then x, each once
 *      then    -  versions 4 and 5: D sight masks of 64 bytes, detail probe by
 *                 detail probe: 16 uint32, bit b (word b / 32, bit b % 32)
 *                 set when the probe sees sample point b = (k 8 + j) 8 + i
 *                 of the 8 lattice cells around its lattice point, at that
 *                 point plus ((i, j, k) + 0.5) / 4 - 1 spacings (shaders/
 *                 config.h, SB_PROBE_SIGHT_*)
 *      then    -  probe count x channels x float32 (version 5: IEEE
 *                 binary16), probe by probe
 *      end     8  XXH3-64 of every byte before it
 *
 * A grid of layers follows the surface: its probes stand in columns (x, z
 * as a uniform grid's, x fastest, then the layer, then z), the probe of
 * layer l at its height above the first surface a ray straight down its
 * column met (the position channels say where each is). Its y origin is 0
 * and its y spacing the distance over the top layer that a runtime fades
 * the probes' light over. A file without layers is written as version 1,
 * byte for byte as before.
 *
 * Detail (version 3) is a sparse lattice of probes where geometry is:
 * brick columns SB_PROBES_BRICK x SB_PROBES_BRICK lattice columns across,
 * each as many rows high as the geometry under it needs. Brick column
 * (x, z) with rows y0.. y0 + rows - 1 holds the lattice probes (4x + i,
 * y, 4z + k), i, k < 4, stored y by y, then k, then i (x fastest), at
 * origin + spacing x (lattice index). Detail probes come after the grid's
 * and before the explicit ones, brick column by brick column.
 *
 * Tiles (version 6) split a grid and its detail by where they stand, in
 * squares `side` metres across from x = z = 0, so that a bake can redo the
 * tiles whose world changed and keep the rest (docs/probes.md, "Tiles"): a
 * grid probe belongs to the tile its column stands in, a detail probe to
 * the tile of its brick column's first lattice column
 * (sb_probe_tiles_assign). A file with tiles has no explicit probes. A
 * tile not baked (a bake of some tiles alone) holds zeros: its probes are
 * invalid.
 *
 * The reader trusts nothing: every field is checked against the format's
 * caps and the others before anything is allocated, the size must match
 * exactly (no truncation, nothing trailing), the checksum must hold and
 * every value must be finite and in its channel's range. A newer version
 * is SB_ERR_VERSION ("rebake needed"), never a guess.
 */
#ifndef SB_PROBES_H
#define SB_PROBES_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "image.h"
#include "result.h"
#include "scene.h"

#define SB_PROBES_VERSION 6
#define SB_PROBES_HEADER_BYTES_V1 112
#define SB_PROBES_HEADER_BYTES_V2 152
#define SB_PROBES_HEADER_BYTES 192
#define SB_PROBES_BRICK 4                /* a brick column's lattice columns along x and along z */
#define SB_PROBES_MAX_COLUMNS (1u << 18) /* brick columns in a file */
#define SB_PROBES_MAX_LATTICE (1 << 16)  /* lattice steps along an axis */
#define SB_PROBES_COLUMN_BYTES 16
#define SB_PROBES_MAX_COUNT (1u << 20)
#define SB_PROBES_MAX_GRID 1024 /* probes along one axis */
/* The detail probes' sight masks (version 4): SB_PROBES_SIGHT_SIDE^3 bits
 * a probe in SB_PROBES_SIGHT_WORDS words (shaders/config.h's
 * SB_PROBE_SIGHT_*, which bake them). */
#define SB_PROBES_SIGHT_SIDE 8
#define SB_PROBES_SIGHT_WORDS 16
#define SB_PROBES_MAX_TILES (1u << 16)
#define SB_PROBES_TILE_BYTES 40
#define SB_PROBES_TILE_BAKED 1u /* a tile's flags: its probes were baked */

/* The sky-visibility product's channels (docs/pack.md): where the probe
 * is (after any push out of geometry) and how far it was moved; 1 when
 * valid (0: inside geometry, not to be used); the fractions of its rays
 * that met a back face or anything, their mean distance; the deringing
 * window applied (sh.h); the order-2 SH of the sky's visibility. */
#define SB_SKY_VISIBILITY_CHANNELS                                                                                     \
    "position.x,position.y,position.z,offset.x,offset.y,offset.z,valid,back_fraction,hit_fraction,"                    \
    "mean_distance_m,dering_window,sh.0,sh.1,sh.2,sh.3,sh.4,sh.5,sh.6,sh.7,sh.8"
#define SB_SKY_VISIBILITY_CHANNEL_COUNT 20
/* Where each of those channels is in a probe's record (tests/test_formats.c
 * checks them against the names). */
enum sb_sky_visibility_channel {
    SB_SKY_VISIBILITY_POSITION = 0, /* x, y, z: m */
    SB_SKY_VISIBILITY_OFFSET = 3,   /* x, y, z: the push out of geometry, m */
    SB_SKY_VISIBILITY_VALID = 6,
    SB_SKY_VISIBILITY_BACK_FRACTION = 7,
    SB_SKY_VISIBILITY_HIT_FRACTION = 8,
    SB_SKY_VISIBILITY_MEAN_DISTANCE = 9,
    SB_SKY_VISIBILITY_DERING_WINDOW = 10,
    SB_SKY_VISIBILITY_SH = 11, /* the SH coefficients, 9 of them */
};
#ifndef __cplusplus
_Static_assert(SB_SKY_VISIBILITY_SH + 9 == SB_SKY_VISIBILITY_CHANNEL_COUNT, "the SH are the last channels");
#endif

/* The sky-bounce product's channels (docs/probes.md, "Bounce"): the
 * one-bounce transfer B[m][k] per colour, m < 4 the order-1 SH of the
 * direction at the probe, k < 9 the order-2 SH of the light reaching the
 * surfaces its rays hit: channel "bounce.m.k.c", m, then k, then r, g, b. */
#define SB_BOUNCE_3(m, k) "bounce." #m "." #k ".r,bounce." #m "." #k ".g,bounce." #m "." #k ".b"
#define SB_BOUNCE_9(m)                                                                                                 \
    SB_BOUNCE_3(m, 0)                                                                                                  \
    "," SB_BOUNCE_3(m, 1) "," SB_BOUNCE_3(m, 2) "," SB_BOUNCE_3(m, 3) "," SB_BOUNCE_3(m, 4) "," SB_BOUNCE_3(           \
        m, 5) "," SB_BOUNCE_3(m, 6) "," SB_BOUNCE_3(m, 7) "," SB_BOUNCE_3(m, 8)
#define SB_SKY_BOUNCE_CHANNELS SB_BOUNCE_9(0) "," SB_BOUNCE_9(1) "," SB_BOUNCE_9(2) "," SB_BOUNCE_9(3)
#define SB_SKY_BOUNCE_CHANNEL_COUNT 108

/* The sun-bounce product's channels (docs/probes.md, "The sun"): its
 * table's grey constant band "sun.i.k" at each of its 12 x 12 directions
 * (config.h, SB_SUN_SIDE: column i, row k of the octahedral map; i
 * fastest), then its shape "sun_shape.m.c" (baker/sky_bounce.h). */
#define SB_SUN_ROW(k)                                                                                                  \
    "sun.0." #k ",sun.1." #k ",sun.2." #k ",sun.3." #k ",sun.4." #k ",sun.5." #k ",sun.6." #k ",sun.7." #k             \
    ",sun.8." #k ",sun.9." #k ",sun.10." #k ",sun.11." #k
#define SB_SUN_SHAPE(m) "sun_shape." #m ".r,sun_shape." #m ".g,sun_shape." #m ".b"
#define SB_SUN_BOUNCE_CHANNELS                                                                                         \
    SB_SUN_ROW(0) "," SB_SUN_ROW(1) "," SB_SUN_ROW(2) "," SB_SUN_ROW(3) "," SB_SUN_ROW(4) "," SB_SUN_ROW(             \
        5) "," SB_SUN_ROW(6) "," SB_SUN_ROW(7) "," SB_SUN_ROW(8) "," SB_SUN_ROW(9) "," SB_SUN_ROW(10) "," SB_SUN_ROW(  \
        11) "," SB_SUN_SHAPE(0) "," SB_SUN_SHAPE(1) "," SB_SUN_SHAPE(2) "," SB_SUN_SHAPE(3)
#define SB_SUN_BOUNCE_CHANNEL_COUNT (144 + 12)
/* The bounce's values are within this: |B| <= 4 pi max|Y_m| max|g_k| / pi,
 * |g_k| <= pi max|Y_k| (m < 4, k < 9); the sun table's are clamped to it. */
#define SB_SKY_BOUNCE_LIMIT 6.7079

/* The reflection probes' channels (docs/reflections.md): where the probe
 * is, the box it stands for (min, max corners; the sky-only probe's is
 * zero), and the order-2 SH of the irradiance its cube sees (the cosine
 * convolution of its radiance, per colour): channel "irradiance.k.c". */
#define SB_IRRADIANCE_3(k) "irradiance." #k ".r,irradiance." #k ".g,irradiance." #k ".b"
#define SB_REFLECTION_PROBES_CHANNELS                                                                                                                              \
    "position.x,position.y,position.z,box_min.x,box_min.y,box_min.z,box_max.x,box_max.y,box_max.z," SB_IRRADIANCE_3(0) "," SB_IRRADIANCE_3(1) "," SB_IRRADIANCE_3( \
        2) "," SB_IRRADIANCE_3(3) "," SB_IRRADIANCE_3(4) "," SB_IRRADIANCE_3(5) "," SB_IRRADIANCE_3(6) "," SB_IRRADIANCE_3(7) "," SB_IRRADIANCE_3(8)
#define SB_REFLECTION_PROBES_CHANNEL_COUNT 36

/* A brick column of the detail lattice (the file's record). */
struct sb_probe_column {
    int32_t x, z;  /* in bricks from the lattice's origin, >= 0 */
    int32_t y0;    /* its lowest row, lattice steps from the origin, >= 0 */
    uint32_t rows; /* >= 1; y0 + rows <= SB_PROBES_MAX_LATTICE */
};

/* A tile of a layout (the file's record). */
struct sb_probe_tile {
    int32_t x, z;     /* it covers [x, x + 1) x [z, z + 1) tile sides */
    uint32_t probes;  /* the layout's probes that belong to it, >= 1 */
    uint32_t flags;   /* SB_PROBES_TILE_BAKED */
    char key[33];     /* its bake key, 32 lowercase hex digits ("" when not baked) */
    uint64_t content; /* XXH3-64 of its stored records then sight masks (0 when not baked) */
};

/* Where the probes are: a grid (x fastest), detail, then explicit ones.
 * A layout with detail owns its columns: copy it with
 * sb_probe_layout_copy, free it with sb_probe_layout_finish. */
struct sb_probe_layout {
    uint32_t grid[3];
    uint32_t explicit_count;
    float origin_m[3];
    float spacing_m[3];
    uint32_t ray_count;
    char key[33]; /* the bake key, or "" */
    /* 0: a uniform grid; else grid[1] layers that follow the surface, at
     * these heights above it (m, increasing) */
    uint32_t layer_count;
    float layers_m[SB_PROBES_MAX_LAYERS];
    /* detail: column_count brick columns holding detail_count probes
     * (0: none) */
    float detail_spacing_m;
    float detail_origin_m[3];
    uint32_t detail_count;
    uint32_t column_count;
    struct sb_probe_column *columns; /* owned */
    /* the detail probes' sight masks (version 4; NULL: none):
     * detail_count x SB_PROBES_SIGHT_WORDS */
    uint32_t *sight; /* owned */
    bool half;       /* read: the values were stored as binary16 (version 5) */
    /* tiles (version 6; tile_count 0: none): in increasing z, then x */
    float tile_m, reach_m;
    uint32_t tile_count;
    struct sb_probe_tile *tiles; /* owned */
};

/* Free a layout's columns, sight masks and tiles (and zero them); a
 * zeroed layout is accepted. */
void sb_probe_layout_finish(struct sb_probe_layout *layout);
/* *to = *from with its own copy of the columns, sight masks and tiles
 * (SB_ERR_NOMEM: *to zeroed). */
enum sb_result sb_probe_layout_copy(struct sb_probe_layout *to, const struct sb_probe_layout *from);

/*
 * The tiles `side` metres across that a layout's grid and detail probes
 * fall in (formats/probes.h: a grid probe by its column, a detail probe by
 * its brick column's first lattice column), into layout->tiles (their
 * probe counts set, flags, keys and contents zero) with tile_m = side; and
 * (tile_of may be NULL) each probe's tile, an index into them. A layout
 * with explicit probes has no tiles, nor does a side outside 1 to 1e4 m:
 * SB_ERR_PROBES. SB_ERR_TOO_LARGE past SB_PROBES_MAX_TILES.
 */
enum sb_result sb_probe_tiles_assign(struct sb_probe_layout *layout, float side, uint32_t *tile_of);

/* The index of tile (x, z) among the layout's tiles, or -1. */
int64_t sb_probe_tile_find(const struct sb_probe_layout *layout, int32_t x, int32_t z);

/* XXH3-64 of a tile's probes' records as a file stores them (binary16
 * when `half`), then their sight masks: what its record's content holds.
 * probes[]: the tile's `count` probes, in increasing index. */
uint64_t sb_probe_tile_content(const struct sb_probe_layout *layout, const struct sb_image *image, bool half,
                               const uint32_t *probes, uint32_t count);
/* The index among a layout's probes of detail lattice probe (x, y, z), or
 * -1 when no brick column holds it (a binary search over the columns). */
int64_t sb_probe_detail_index(const struct sb_probe_layout *layout, uint64_t grid_count, int32_t x, int32_t y,
                              int32_t z);
/* How well the detail probes around point q (m) see it: the most, over
 * the 8 lattice probes of q's cell that stand in a brick column and are
 * valid (valid[i] != 0 for the layout's probe i), of their sight of q as
 * skyview reads it (their mask interpolated trilinearly: probes.glsl's
 * probe_sees); 1 for such a probe without sight masks. -1 when no detail
 * probe stands around q. */
double sb_probe_detail_sight(const struct sb_probe_layout *layout, uint64_t grid_count, const float *valid,
                             size_t valid_stride, const double q[3]);

/* The content hash of a probe product (pack.h): the records' (image.h's
 * sb_image_content_hash) and, where the layout has them, the sight
 * masks' (a layout without is hashed as before them). */
void sb_probes_content_hash(const struct sb_image *image, const struct sb_probe_layout *layout,
                            char out[SB_HASH_HEX_SIZE]);

/* Write the probes (image: width = probe count, height = depth = 1, the
 * channels in the product's order) with their layout, their values as
 * fp32 or (`half`) binary16, which must hold each exactly
 * (sb_image_round_to_half; SB_ERR_NUMERIC otherwise). Atomic only as the
 * pack is (the writer's temporary directory). */
enum sb_result sb_probes_write(const char *path, const struct sb_probe_layout *layout, const struct sb_image *image,
                               bool half);

/*
 * Parse a probe file's bytes (source names it in messages). channel_names
 * (comma-separated) must be the file's channels, in order; max_probes caps
 * the count. On success *image holds the records and *layout the layout;
 * on failure both are zeroed. Codes: SB_ERR_PROBES (not a probe file, or a
 * header field out of range), SB_ERR_VERSION, SB_ERR_BAD_IMAGE (size,
 * counts or channels that do not match), SB_ERR_HASH_MISMATCH (checksum),
 * SB_ERR_NUMERIC (a value not finite or out of its range), SB_ERR_NOMEM.
 */
enum sb_result sb_probes_parse(const void *bytes, size_t size, const char *source, const char *channel_names,
                               uint32_t max_probes, struct sb_probe_layout *layout, struct sb_image *image);

/* Read and parse the file at path (at most the largest legal size). */
enum sb_result sb_probes_read(const char *path, const char *channel_names, uint32_t max_probes,
                              struct sb_probe_layout *layout, struct sb_image *image);

#endif
