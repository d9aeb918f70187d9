/*
 * skyview's renderer: one frame is a chain of GPU passes on one queue,
 *   sky-view LUT -> aerial perspective -> shadow cascades -> scene -> sky ->
 *   exposure -> bloom -> tone mapping,
 * each bracketed by timestamps. The atmosphere comes from a pack (its
 * transmittance, multiple-scattering and ground-irradiance LUTs, and its
 * sky-visibility probes where it has them), read through formats/ and
 * uploaded once; the world from sb_world. With probes, the world's ambient
 * light is the probes' (relit every frame for the sun and sky: probes.glsl);
 * without, the sky's irradiance on open ground. Frames are
 * offscreen; their pixels are read back on request. One thread at a time.
 */
#ifndef SB_RUNTIME_RENDERER_H
#define SB_RUNTIME_RENDERER_H

#include <stdbool.h>
#include <stdint.h>

#include "context.h"
#include "pack.h"
#include "world.h"

/* How the scene pass finds the world's points (runtime/passes/scene.c). */
enum sb_scene_method {
    SB_SCENE_AUTO,   /* traced on a GPU, rasterised on a CPU device (llvmpipe) */
    SB_SCENE_RASTER, /* rasterised, shadows from cascaded shadow maps */
    SB_SCENE_TRACED, /* a ray a pixel through the world's BVH, shadows from shadow rays */
};

struct sb_lut3d;

/* The camera (struct sb_view's camera_m, y up from the planet's ground):
 * a world's valleys may take it this far under y 0; the atmosphere sees it
 * no lower than SB_CAMERA_LOWEST_ATMOSPHERE_M over the ground. */
#define SB_CAMERA_LOWEST_M 1e4
#define SB_CAMERA_LOWEST_ATMOSPHERE_M 0.01

/* Scene-linear grading (runtime/grading.c, passes/grade_linear.c): on the exposed frame (mid grey at
 * 0.18), before bloom and the tone curve. */
#define SB_GRADING_NEUTRAL_K 6504.0 /* D65's correlated colour temperature */
struct sb_grading {
    bool enabled;           /* false: none (as every setting neutral) */
    double white_balance_k; /* the colour temperature (K) of the light to render white, 1000 to 15000:
                               lower makes the frame cooler; SB_GRADING_NEUTRAL_K: none */
    double tint;            /* that light's offset from the locus, in Duv / 1000; positive: more magenta
                               (the frame turns greener); 0: none */
    double saturation;      /* about the luminance: 0 grey, 1 none */
    double contrast;        /* each channel 0.18 (c / 0.18)^contrast; 1: none */
};

/* The exposure's defaults: it adapts down to a moonlit night (the ground
 * under a full moon is about EV100 -3) and up past sunlit snow (16); under
 * dusk (EV100 5) it takes a third of a stop off a stop, so a moonlit night
 * is exposed 2.7 stops under a day's mid grey. */
#define SB_EARTH_SUN_LUX 128000.0 /* sun_illuminance_lux's default */
#define SB_EXPOSURE_MIN_EV100 (-5.0)
#define SB_EXPOSURE_MAX_EV100 18.0
#define SB_EXPOSURE_DIM_EV100 5.0
#define SB_EXPOSURE_DIM_STOPS (1.0 / 3.0)

struct sb_renderer_params {
    uint32_t width, height;                        /* 0: 1280 x 720 */
    uint32_t shadow_size;                          /* texels per side of each cascade; 0: 2048 */
    double shadow_distance_m;                      /* where the last cascade ends; 0: 250 */
    int tonemap;                                   /* SB_TONEMAP_AGX (0, the default), _ACES or _GT */
    double exposure_compensation_ev;               /* added to the metered exposure; 0: none */
    double exposure_min_ev100, exposure_max_ev100; /* the range the exposure adapts within (EV at ISO 100 of
                                        the luminance metered, K = 12.5, with sun_illuminance_lux); both 0:
                                        SB_EXPOSURE_MIN_EV100 to SB_EXPOSURE_MAX_EV100 */
    double dim_compensation;                       /* stops taken off the exposure a stop the metered luminance is under
                                                      SB_EXPOSURE_DIM_EV100; 0: SB_EXPOSURE_DIM_STOPS; negative: none */
    double bloom_strength;                         /* 0: 0.15; negative: no bloom */
    bool no_probes;                                /* light the world with the sky alone even if the pack has probes */
    bool no_reflections;          /* leave the pack's reflection probes unread (the sky model's specular) */
    bool no_contact_shadows;      /* the raster scene's shadows from the cascades alone (no screen-space
                                     contact shadows) */
    bool baked_reflections;       /* read the cubes as baked, scaled by the sky's light under another sun,
                                     though the pack's reflection_surfaces could relight them */
    uint32_t relight_cubes;       /* reflection cubes relit a frame at most when the lights move (0: 2);
                                     a frame that snaps relights every stale one */
    bool relight_always;          /* relight relight_cubes cubes every frame, whether the lights moved or not:
                                     what a moving sun costs, for benchmarks */
    bool no_textures;             /* the world's materials without their textures (their factors alone) */
    bool no_fog;                  /* leave out the scene's fog */
    uint32_t fog_tile_px;         /* a froxel's width and height in pixels; 0: 8 */
    uint32_t fog_slices;          /* froxel slices, [2, 256]; 0: 64 */
    double fog_far_m;             /* where the froxel volume ends (then the height fog in closed form); 0: 256 */
    bool no_clouds;               /* leave out the cloud layer */
    uint32_t cloud_scale;         /* clouds traced at one pixel in scale x scale a frame: 1, 2 or 4; 0: 2 */
    uint32_t cloud_steps;         /* view march steps at most, [8, 1024]; 0: 128 */
    uint32_t cloud_light_steps;   /* light march steps toward the sun, [1, SB_CLOUD_MAX_LIGHT_STEPS]; 0: 6 */
    uint32_t cloud_shadow_size;   /* texels per side of the clouds' shadow map, [16, 4096]; 0: 512 */
    int debug;                    /* SB_DEBUG_* (view_gpu.h): the scene pass writes one term; 0: the frame */
    bool no_far_shadows;          /* raster: nothing shadowed past the last cascade (no far map) */
    bool whole_shadow_maps;       /* clear and draw every cascade whole, not only where casters
                                     project (runtime/shadows.h); the same frame, slower */
    bool generic_shaders;         /* never the scene's shaders specialised to the pack (no probes, no
                                     reflection probes) and the frame (aerial perspective from its
                                     volume alone); the same frame, slower on llvmpipe */
    enum sb_scene_method scene;   /* how the scene pass finds the world's points */
    const struct sb_lut3d *grade; /* a .cube LUT (grade.c), read during sb_renderer_create only; NULL:
                                     none. It grades the display-referred 8-bit frame, or with
                                     grade_log the scene-linear one in ACEScct before the tone curve */
    bool grade_log;               /* the LUT's input is ACEScct, not the sRGB-encoded frame */
    struct sb_grading grading;    /* scene-linear grading; zeroed: none */
    bool purkinje;                /* the Purkinje shift in dim light (purkinje.c) */
    double local_contrast;        /* local tone mapping (local_tonemap.c): the base layer's contrast about
                                     the frame's pivot, (0, 1]; 0 or 1: none */
    double sun_illuminance_lux;   /* the sun's illuminance above the atmosphere, what makes the pack's
                                     radiance absolute for the Purkinje shift; 0: 128000 (the earth's) */
    const float *post_input;      /* width x height x 3 floats in the pack's units, or NULL: every frame
                                     post-processes this image instead of the lit one (read during
                                     sb_renderer_create only; non-finite values read as 0) */
};

/* The grading's colour matrix (rows, linear Rec.709): white balance, then
 * saturation; the chromaticity (CIE 1931 xy) it renders white for a colour
 * temperature and tint; whether a grading changes nothing. */
void sb_grading_matrix(const struct sb_grading *grading, double m[3][3]);
void sb_grading_white(double kelvin, double tint, double xy[2]);
bool sb_grading_is_neutral(const struct sb_grading *grading);
/* The Planckian locus (CIE 1931 xy; Krystek's approximation, 1000 to 15000 K). */
void sb_planckian_xy(double kelvin, double xy[2]);
/* Linear Rec.709 to CIE XYZ and to ACES AP1: physics/colour.h. */

/* The fog's and clouds' history is dropped when the sun moves more than
 * this between two frames (degrees): their lighting would lag behind it. */
#define SB_SUN_HISTORY_LIMIT_DEG 0.2

/* What one frame looks at. Angles in radians; lengths in metres. */
struct sb_view {
    double camera_m[3];                  /* in the world: y up, the origin on the ground */
    double yaw, pitch;                   /* view direction: azimuth clockwise from -z (north) toward +x, elevation */
    double fov_y;                        /* vertical field of view; 0: 50 degrees */
    double sun_azimuth;                  /* same convention as yaw */
    double sun_elevation;                /* above the horizon; negative below */
    bool moon;                           /* the moon is in the sky (runtime/moon.h): it lights the sky and, with the
                                            sun down, the world */
    double moon_azimuth, moon_elevation; /* as the sun's */
    double moon_distance_km;  /* from the camera; 0: its mean, 384,400 km. Its radius and brightness follow */
    double dt_s;              /* time since the previous frame, for exposure adaptation; 0: 1/60 s */
    bool snap_exposure;       /* a cut: take the metered exposure at once, drop the fog's and clouds' history */
    double time_s;            /* what the fog's noise and the clouds drift with (s) */
    bool fixed_pre_exposure;  /* store this frame at the radiance scale times 2^pre_exposure_stops instead
                                 of the scale its exposure sets (pre-exposure, renderer.c); the frame reads
                                 back the same away from the halves' limits. false: automatic */
    int pre_exposure_stops;   /* with fixed_pre_exposure, [-16, 24] */
    uint32_t disabled_passes; /* bit 1 << SB_PASS_x: leave that pass out of this frame, where the frame is
                                 whole without it (fog, fog apply, clouds, purkinje, local tonemap, grade
                                 linear, bloom, grade; others are drawn anyway). Its time reads 0. A pass
                                 left out drops its history (fog, clouds); the clouds' shadow stays; the
                                 fog left out leaves out fog apply too */
    bool isolate_passes;      /* a full barrier after each pass, so that each pass's time is its own: the
                                 render graph's barriers alone let passes that do not depend on each other
                                 overlap, and a GPU (or llvmpipe, whose compute runs behind its timestamps)
                                 then books one pass's work to another. The same frame, slower */
};

enum sb_pass {
    SB_PASS_SKY_VIEW,
    SB_PASS_PROBES,
    SB_PASS_REFLECTIONS,
    SB_PASS_AERIAL_PERSPECTIVE,
    SB_PASS_SHADOWS,
    SB_PASS_CLOUD_SHADOW,
    SB_PASS_FOG,
    SB_PASS_SCENE,
    SB_PASS_CONTACT_SHADOWS,
    SB_PASS_SKY,
    SB_PASS_CLOUDS,
    SB_PASS_FOG_APPLY,
    SB_PASS_PURKINJE,
    SB_PASS_EXPOSURE,
    SB_PASS_LOCAL_TONEMAP,
    SB_PASS_GRADE_LINEAR,
    SB_PASS_BLOOM,
    SB_PASS_TONEMAP,
    SB_PASS_GRADE,
    SB_PASS_COUNT,
};

/* "sky-view", "probes", "reflections", "aerial perspective", "shadows", "cloud shadow", "fog", "scene",
 * "contact shadows", "sky", "clouds", "fog apply", "purkinje", "exposure", "local tonemap", "grade linear",
 * "bloom", "tonemap", "grade". */
const char *sb_pass_name(enum sb_pass pass);

/* The switches a viewer offers, from the passes' table: one for each
 * optional pass that needs no other, leaving out with it the optional
 * passes that need it (the fog takes its application along). Masks of
 * 1 << SB_PASS_x, in pass order, into toggles[]; returns their number. */
int sb_pass_toggles(uint32_t toggles[SB_PASS_COUNT]);

struct sb_frame_timings {
    bool valid;               /* false when the queue has no timestamps */
    double ms[SB_PASS_COUNT]; /* GPU time of each pass (its own with sb_view.isolate_passes) */
    double total_ms;          /* from the first pass's start to the last one's end */
};

struct sb_renderer;

/*
 * Whether this build can draw `pack`'s orders tables (orders and
 * spectral_orders): the grid their settings record (`top_km`, `nu_power`;
 * docs/pack.md) is the one it reads; SB_ERR_VERSION naming the field
 * otherwise ("rebake needed": the same shape read between the wrong
 * nodes). No device needed; sb_renderer_create checks it too.
 */
enum sb_result sb_renderer_check_pack(const struct sb_pack *pack);

/*
 * Create a renderer for `pack` (which must hold transmittance,
 * multiscattering and irradiance_ground; SB_ERR_USAGE naming the missing
 * product otherwise; orders on the grid this build reads,
 * sb_renderer_check_pack) and `world` (copied; both may be freed
 * afterwards). `vk` must have been created with graphics.
 */
enum sb_result sb_renderer_create(struct sb_vk *vk, const struct sb_pack *pack, const struct sb_world *world,
                                  const struct sb_renderer_params *params, struct sb_renderer **renderer);
void sb_renderer_destroy(struct sb_renderer **renderer);

/* Render one frame and wait for it. With readback, the frame's pixels can
 * be read afterwards. `timings` may be NULL. */
enum sb_result sb_renderer_render(struct sb_renderer *renderer, const struct sb_view *view, bool readback,
                                  struct sb_frame_timings *timings);

/* The last frame rendered with readback, top row first:
 * - ldr: width * height * 4 bytes, sRGB-encoded RGBA;
 * - hdr: width * height * 3 floats, linear radiance in the pack's units
 *   (those of its solar irradiance), before exposure and post-processing;
 * - post_hdr: the same after the passes that post-process it in place (the
 *   Purkinje shift, local tone mapping, scene-linear grading): what bloom
 *   and the tone curve take, divided by the exposure again (hdr itself when
 *   none of them runs);
 * - sky_view: SB_SKY_VIEW_WIDTH * SB_SKY_VIEW_HEIGHT * 3 floats, likewise. */
void sb_renderer_size(const struct sb_renderer *renderer, uint32_t *width, uint32_t *height);
const uint8_t *sb_renderer_ldr(const struct sb_renderer *renderer);
void sb_renderer_hdr(const struct sb_renderer *renderer, float *rgb);
void sb_renderer_post_hdr(const struct sb_renderer *renderer, float *rgb);
void sb_renderer_sky_view(const struct sb_renderer *renderer, float *rgb);
/* The aerial-perspective volume's in-scattered radiance, SB_AERIAL_SIZE^3
 * rgb texels (x, y: the screen's columns, z: the distance slices), in the
 * pack's units: its last frame read back (zeros until one was). */
void sb_renderer_aerial(const struct sb_renderer *renderer, float *rgb);

/* What the last frame read back was stored at in the HDR target: radiance
 * in the pack's units times this is the half it held (pre-exposure; the
 * post_hdr and sky_view images too). */
double sb_renderer_stored_scale(const struct sb_renderer *renderer);

/* The exposure state after the last frame: adapted log2 luminance, the
 * exposure multiplier, this frame's metered log2 luminance, and the pixels
 * in the metering window. */
void sb_renderer_exposure(const struct sb_renderer *renderer, float state[4]);
/* A log2 luminance of the exposure's state (the pack's units) as EV at
 * ISO 100 (K = 12.5; the pack made absolute by sun_illuminance_lux). */
double sb_renderer_ev100(const struct sb_renderer *renderer, double log2_luminance);

/* Where a world point lands in the last frame's image (pixels, x right, y
 * down); false when it is behind the camera. */
bool sb_renderer_project(const struct sb_renderer *renderer, const double world_m[3], double pixel[2]);

/* The unit direction of the last frame's view ray through `pixel` (x
 * right, y down; a pixel's centre is at its index plus one half), from the
 * camera; the reverse of sb_renderer_project. */
void sb_renderer_pixel_ray(const struct sb_renderer *renderer, const double pixel[2], double direction[3]);

/* The reflection cubes as the scene pass read them in the last frame
 * (relit where the pack has reflection_surfaces), or NULL without any:
 * cube by cube, each its chain level by level (faces as OpenEXR lays
 * them), 4 floats a texel (rgb, 0), in the pack's units. */
const float *sb_renderer_reflection_cubes(const struct sb_renderer *r, uint32_t *count, uint32_t *face_size,
                                          uint32_t *levels);

#endif
