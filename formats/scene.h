/*
 * Scene description (JSON; schema in docs/scene.md). Parsing resolves the
 * preset, applies overrides, and refuses unknown keys, duplicate keys, wrong
 * types and out-of-range values before any GPU work, logging the file, the
 * JSON path and the reason.
 */
#ifndef SB_SCENE_H
#define SB_SCENE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "product.h"
#include "result.h"

/* All lengths in km, all coefficients in 1/km, RGB triples in linear Rec.709
 * primaries as the literature gives them. */
struct sb_atmosphere_params {
    double ground_radius_km;
    double top_radius_km;
    double rayleigh_scattering_per_km[3];
    double rayleigh_scale_height_km;
    double mie_scattering_per_km[3];
    double mie_absorption_per_km[3];
    double mie_scale_height_km;
    double mie_g; /* Cornette-Shanks asymmetry, |g| < 1 */
    double ozone_absorption_per_km[3];
    double ozone_center_km;     /* the tent's peak altitude */
    double ozone_half_width_km; /* density falls linearly to 0 this far above and below */
    double ground_albedo[3];    /* Lambertian, [0, 1] */
    double solar_irradiance[3]; /* 1 makes every product a transfer function */
};

/* Where the scene's sky is looked at from, by default: skyview's camera and
 * the sky checks of the tests. Not used by the bakes. */
struct sb_scene_view {
    double altitude_km;       /* the camera above the ground, [0, 1e6] */
    double sun_elevation_deg; /* the sun above the horizon, [-90, 90] */
    double sun_azimuth_deg;   /* clockwise from north (-z), [-360, 360] [150]: skyview's default */
};

/* A Perlin fBm's lattice period (cells per texture) and octave count. */
struct sb_noise_octaves {
    uint32_t period;
    uint32_t octaves;
};

/*
 * The cloud noise textures (baker/clouds.h defines each noise and channel).
 * Sizes are texels per edge; periods and Worley cell counts are per texture
 * edge (each noise tiles the texture); every octave doubles the period.
 * Defaults in brackets; docs/scene.md gives the caps.
 */
struct sb_cloud_params {
    uint32_t seed;                         /* [0] */
    uint32_t shape_size;                   /* [128] */
    struct sb_noise_octaves shape_perlin;  /* Perlin-Worley's Perlin [4, 4 octaves] */
    uint32_t shape_worley_cells[3];        /* [4, 8, 16]: channel 0's Worley is the first */
    uint32_t detail_size;                  /* [32] */
    uint32_t detail_worley_cells[3];       /* [2, 4, 8] */
    uint32_t curl_size;                    /* [128] */
    struct sb_noise_octaves curl;          /* the potential's [4, 3 octaves] */
    uint32_t weather_size;                 /* [512] */
    struct sb_noise_octaves coverage;      /* [4, 5 octaves] */
    struct sb_noise_octaves precipitation; /* [8, 4 octaves] */
    struct sb_noise_octaves cloud_type;    /* [2, 3 octaves] */
};

void sb_cloud_params_default(struct sb_cloud_params *params);

/* Validate, logging "source: clouds.path: reason" for the first problem. */
enum sb_result sb_cloud_params_validate(const struct sb_cloud_params *params, const char *source);

/* The scene's "world": a mesh file (read by the baker through assimp,
 * geometry/mesh.h) and how it is placed. Defaults in brackets. */
#define SB_WORLD_MAX_OVERRIDES 16
struct sb_world_params {
    char file[1024];       /* as the scene gives it; relative to the scene file's directory */
    double units_m;        /* metres per file unit [1] */
    double scale;          /* [1] */
    bool up_z;             /* "up": "z" turns a z-up file y-up ["y"] */
    double rotate_deg[3];  /* about x, then y, then z [0] */
    double translate_m[3]; /* [0] */
    int override_count;
    struct {
        char material[64]; /* a material's name in the file, or "*" */
        double albedo[3];
    } overrides[SB_WORLD_MAX_OVERRIDES];
    /* "ground": what a mesh file stands on (a world file states its own):
     * false for none, else a square that receives shadows and casts none
     * (geometry/mesh.h, sb_mesh_ground). */
    struct {
        bool given;      /* the scene gave "ground" (for the normalised form) */
        bool none;       /* "ground": false */
        bool object;     /* an object: a ground even under a model that has its own */
        bool has_height; /* else at the model's lowest point or 0, the lower */
        double height_m;
        double size_m;    /* 0: 4 times the model's larger horizontal extent, at least 100 m [0] */
        double albedo[3]; /* [0.18] */
    } ground;
};

/* The scene's "probes": where the sky-visibility probes go. */
#define SB_PROBES_MAX_EXPLICIT 256
#define SB_PROBES_MAX_BOUNCES 64 /* probes.bounces (baker/sky_bounce.h's SB_SKY_BOUNCE_MAX) */
/* A grid that follows the surface has at most this many layers (probes.h). */
#define SB_PROBES_MAX_LAYERS 8
/* Detail volumes a scene may give. */
#define SB_PROBES_MAX_VOLUMES 32
#define SB_PROBES_MAX_ONLY_TILES 64
struct sb_probe_params {
    double spacing_m;       /* a grid over the world's bounds, this far apart [2]; 0: none */
    double margin_m;        /* the grid's bounds: the world's, grown by this [0] */
    bool has_bounds;        /* the grid covers bounds_m instead of the world's bounds */
    double bounds_m[2][3];  /* min, max corners */
    uint32_t rays;          /* per probe, a multiple of 64 [2048] */
    double inside_fraction; /* more back-face hits than this: inside geometry [0.25] */
    /* layers_m given: the grid follows the surface, layer_count probes a
     * column at these heights (m, increasing) above the first surface a ray
     * down the column meets, instead of spacing_m apart in y [none] */
    int layer_count;
    double layers_m[SB_PROBES_MAX_LAYERS];
    /* Detail where geometry is: a lattice this far apart in brick columns
     * over every place a ray down passes a covered gap at least this high
     * (a room under its roof, the ground under an overhang;
     * formats/probes.h) [0: none] */
    double detail_spacing_m;
    /* boxes that force detail over their whole volume (`detail` true) or
     * forbid it in theirs, in order, the later winning */
    int detail_volume_count;
    struct sb_probe_volume {
        double min_m[3], max_m[3];
        bool detail;
    } detail_volumes[SB_PROBES_MAX_VOLUMES];
    /* the probe products' bytes at most, MB (1e6 bytes): a grid that
     * would take more is spaced wider until it fits, then the detail
     * coarsened until it fits in what the grid leaves [0: no budget] */
    double budget_mb;
    uint32_t bounce_rays;      /* sky_bounce: rays a probe for the surfaces it sees, a multiple of 64 [256] */
    uint32_t bounce_secondary; /* sky_bounce: rays from each surface hit, a multiple of 8 [64] */
    uint32_t sun_rays;         /* sun_bounce: rays a probe for the surfaces it sees, a multiple of 64 [1024] */
    uint32_t bounces;          /* sky_bounce: 1 to SB_PROBES_MAX_BOUNCES bounces, 0 every one [0] */
    /* Tiles this wide (m, squares from x = z = 0) that a bake redoes
     * alone when the world around them changed (docs/probes.md, "Tiles")
     * [0: none]; the rays' reach, past which a ray sees the sky [0: a
     * quarter of tile_m with tiles, else unlimited] */
    double tile_m, reach_m;
    /* Set by `skybake bake --tile X,Z` (not a scene field): bake these
     * tiles alone, the others left unbaked [none: every tile] */
    int only_tile_count;
    int32_t only_tiles[SB_PROBES_MAX_ONLY_TILES][2];
    int explicit_count;
    double positions_m[SB_PROBES_MAX_EXPLICIT][3];
};

void sb_probe_params_default(struct sb_probe_params *params);

/* Reflection probes (docs/reflections.md): the sky-only probe at the
 * view's altitude, then these, each with the box it stands for. */
#define SB_REFLECTION_MAX_PROBES 64
struct sb_reflection_params {
    uint32_t face_size;    /* texels along a cube face's edge, a power of two in [16, 1024] [128] */
    uint32_t samples;      /* GGX samples a texel of each rough level, a multiple of 16 in [16, 16384] [512] */
    uint32_t ambient_rays; /* rays from each captured surface for the sky's light, a multiple of 8 in [8, 1024] [64] */
    int probe_count;
    struct {
        double position_m[3];
        double box_m[2][3]; /* min, max corners: the box it is parallax-corrected against and blends over */
    } probes[SB_REFLECTION_MAX_PROBES];
};

void sb_reflection_params_default(struct sb_reflection_params *params);

/* The scene's "fog" (docs/fog.md): media near the ground that skyview
 * renders; the bakes do not read it. World y in metres; defaults in brackets. */
#define SB_FOG_MAX_VOLUMES 16
struct sb_fog_params {
    double extinction_per_m;  /* the height fog's extinction at base_altitude_m, [0, 10] [0.01]; 0: none */
    double base_altitude_m;   /* [0] */
    double falloff_height_m;  /* the density falls by e every this much higher, grows likewise lower, [1, 1e4] [50] */
    double albedo[3];         /* single-scattering albedo, [0, 1] [0.9] */
    double anisotropy;        /* Henyey-Greenstein g, [-0.95, 0.95] [0.6] */
    double noise_amount;      /* how much the baked cloud_detail noise thins the fog, [0, 1] [0; 0.6 with "noise"] */
    double noise_scale_m;     /* the noise's tile, [0.1, 1e4] [40] */
    double noise_wind_m_s[3]; /* how fast the noise drifts [2, 0, 0] */
    int volume_count;
    struct {
        double box_m[2][3];      /* min, max corners */
        double extinction_per_m; /* added inside the box, [0, 10] */
        double edge_m;           /* the density ramps up over this far inside the faces, [0, 1e3] [1] */
    } volumes[SB_FOG_MAX_VOLUMES];
};

void sb_fog_params_default(struct sb_fog_params *params);

/* The scene's "cloud_layer" (docs/clouds.md, "In skyview"): the volumetric
 * cloud layer skyview renders from the baked noise; the bakes do not read
 * it. Altitudes above the ground, lengths in metres; defaults in brackets. */
struct sb_cloud_layer_params {
    double base_altitude_m;      /* the layer's base, [0, 3e4] [1500] */
    double top_altitude_m;       /* its top, at least 100 m above the base, [100, 3e4] [4000] */
    double coverage;             /* 0: clear; 0.5: the weather map's coverage as baked; 1: overcast [0.4] */
    double extinction_per_m;     /* at density 1, [0, 1] [0.08] */
    double albedo[3];            /* single-scattering albedo, [0, 1] [0.99] */
    double weather_scale_m;      /* the weather map's tile, [100, 1e7] [40000] */
    double shape_scale_m;        /* cloud_shape's tile, on all three axes, [10, 1e6] [8000] */
    double detail_scale_m;       /* cloud_detail's tile, [1, 1e5] [700] */
    double erosion;              /* how much the detail noise erodes the shape's edges, [0, 1] [0.4] */
    double curl_scale_m;         /* cloud_curl's tile, [1, 1e6] [5000] */
    double curl_m;               /* how far the curl moves the detail noise, [0, 1e4] [200] */
    double wind_m_s[3];          /* the layer's drift [10, 0, 0] */
    double phase_forward_g;      /* the two Henyey-Greenstein lobes' g, [-0.95, 0.95] [0.8] */
    double phase_backward_g;     /* [-0.95, 0.95] [-0.3] */
    double phase_forward_weight; /* the forward lobe's share, [0, 1] [0.7] */
    uint32_t scattering_octaves; /* multiple-scattering octaves (Wrenninge; Hillaire 2016), [1, 8] [4] */
};

void sb_cloud_layer_params_default(struct sb_cloud_layer_params *params);

struct sb_scene {
    char name[64];
    char preset[32];
    struct sb_atmosphere_params atmosphere;
    bool has_clouds;               /* a "clouds" object was given */
    struct sb_cloud_params clouds; /* the defaults unless given */
    /* Products the scene asks for, before dependencies are pulled in
     * (without a "products" list: the atmosphere's). */
    bool wants[SB_PRODUCT_COUNT];
    /* Largest relative error against the fp64 reference each atmosphere
     * product may have (0: none asked; the product's default settings). The
     * cloud noise matches its reference exactly and takes none. */
    double tolerance[SB_PRODUCT_COUNT];
    bool has_view;
    struct sb_scene_view view; /* 2 m up, the sun at 30 degrees unless the scene says */
    bool has_world;
    struct sb_world_params world;
    char directory[1024]; /* the scene file's directory, for the world's file ("" from memory: the current one) */
    bool has_probes;
    struct sb_probe_params probes;
    bool has_reflections;
    struct sb_reflection_params reflections;
    bool has_fog;
    struct sb_fog_params fog;
    bool has_cloud_layer; /* a "cloud_layer" was given (skyview draws the defaults' layer otherwise) */
    struct sb_cloud_layer_params cloud_layer;
};

/* Tolerances a scene may ask for: [SB_TOLERANCE_MIN, SB_TOLERANCE_MAX]. */
#define SB_TOLERANCE_MIN 1e-7
#define SB_TOLERANCE_MAX 0.5

/* Hillaire 2020's Earth. */
void sb_atmosphere_preset_earth(struct sb_atmosphere_params *params);
/* A thin, dusty Mars-like atmosphere (illustrative values, see scene.c). */
void sb_atmosphere_preset_mars(struct sb_atmosphere_params *params);

/* Whether Mie scatters more than Rayleigh at the ground in every channel
 * (mars's dust, the haze; not the earth, whose red is 41% Mie). */
bool sb_atmosphere_dusty(const struct sb_atmosphere_params *params);

/* Whether it is a dust with a peaked phase as well (|g| at least
 * SB_ORDERS_DUST_MAX_G: the haze, not mars): such an atmosphere's orders
 * are read across the sun's azimuth log-trigonometrically by day
 * (physics.h's sb_orders_log_azimuth), on 4 uniform nodes. */
bool sb_atmosphere_peaked_dust(const struct sb_atmosphere_params *params);

/* The medium in which the orders product computes orders 2 and up: the
 * atmosphere itself (returns 0), or, where Mie's phase is a narrow
 * forward peak (g at least SB_ORDERS_DELTA_M_G: the haze), its delta-M
 * scaling (Wiscombe 1977): the peak's share f = g^2 of Mie's scattering
 * carried on as unscattered light (its extinction less f times its
 * scattering), the rest scattering with g / (1 + g); returns f. The
 * orders' grid (the functions below) follows this medium, whose light the
 * table holds. */
double sb_orders_medium(const struct sb_atmosphere_params *params, struct sb_atmosphere_params *medium);

/* The orders product's mu nodes for an atmosphere: SB_ORDERS_MU_DUST where
 * it is dusty and its phase broad (|g| below SB_ORDERS_DUST_MAX_G; mars's
 * 0.65: a dust's light that changes over tens of degrees, which 64 nodes
 * read on a line across the zenith's 38 degree cell), else SB_ORDERS_MU.
 * A peaked phase (the haze's 0.99) keeps 64: its peak is beyond any mu
 * grid, and on 128 nodes the haze measured the same (docs/accuracy.md). */
int sb_orders_mu_nodes(const struct sb_atmosphere_params *params);

/* The orders' azimuth nodes: SB_ORDERS_NU_DUST where a view reads them
 * log-trigonometrically (sb_atmosphere_peaked_dust: through every node,
 * which view.glsl's read is written for), else SB_ORDERS_NU (twice as
 * many: on 4, the earth at 4 and 6 degrees below the horizon read 4.5 and
 * 9% rms low, on 8 about 2%; mars at 4 below 13.8% and 4.6%, read
 * linearly on 8 close about the sun: docs/accuracy.md). */
int sb_orders_nu_nodes(const struct sb_atmosphere_params *params);

/* The orders' sun cosine nodes: SB_ORDERS_MU_S for the air (half of them
 * below 0.1: on 24, with the azimuth nodes about the sun, the earth at 4
 * degrees below the horizon read 1.8% rms, on 36 0.9%, docs/accuracy.md),
 * SB_ORDERS_MU_S_DUST for a dust (sb_atmosphere_dusty), whose twilight
 * these do not settle. */
int sb_orders_mu_s_nodes(const struct sb_atmosphere_params *params);

/* Read and validate a scene file. On failure the scene is left zeroed. */
enum sb_result sb_scene_load(const char *path, struct sb_scene *scene);

/* Same from memory; source names the origin in messages. */
enum sb_result sb_scene_parse(const char *json, size_t size, const char *source, struct sb_scene *scene);

/* Validate parameters, logging "source: path: reason" for the first problem. */
enum sb_result sb_atmosphere_validate(const struct sb_atmosphere_params *params, const char *source);

/*
 * The normalised scene as compact JSON with every parameter resolved, keys in
 * a fixed order and numbers written to round-trip. Its hash identifies the
 * scene. Returns a malloc'd string (caller frees) or NULL on allocation failure.
 */
char *sb_scene_normalized_json(const struct sb_scene *scene);

#endif
