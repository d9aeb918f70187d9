/*
 * skyview: render a pack headless and write the frames.
 *
 * Exit codes: 0 success; 1 rendering or writing failed; 2 bad command line,
 * pack or world; 3 no Vulkan device; 4 validation layers reported messages.
 */
#include <cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "clouds_gpu.h"
#include "compute.h"
#include "config.h"
#include "contact_sheet.h"
#include "context.h"
#include "default_world.h"
#include "exr.h"
#include "io.h"
#include "level.h"
#include "load.h"
#include "log.h"
#include "lut3d.h"
#include "mesh.h"
#include "pack.h"
#include "pngfile.h"
#include "renderer.h"
#include "scene.h"
#include "skybake_version.h"
#include "sun_path.h"
#include "transform.h"
#include "video.h"
#include "viewer.h"
#include "window.h"
#include "world.h"

enum {
    EXIT_RENDER_FAILED = 1,
    EXIT_USAGE = 2,
    EXIT_NO_DEVICE = 3,
    EXIT_VALIDATION = 4,
};

#define DEG (M_PI / 180.0)

static void usage(FILE *f)
{
    fprintf(f, "usage: skyview PACK -o OUT_DIR [options]\n"
               "       skyview PACK --window [-o OUT_DIR] [options]\n"
               "       skyview --version | --help\n"
               "\n"
               "Renders the world lit by the atmosphere of PACK (a skybake pack), offscreen,\n"
               "and writes OUT_DIR/frame_0000.png, ... (8-bit sRGB); a day (--time-of-day) as\n"
               "OUT_DIR/day.mp4 or PNGs, or its contact sheet; or shows it in a window.\n"
               "\n"
               "options:\n"
               "  -o, --output DIR        where the frames go (created if missing)\n"
               "  --size WxH              frame size (default 1280x720)\n"
               "  --frames N              frames to render (default 1; with --bench 30; a sweep:\n"
               "                          enough to keep the history; --window: until closed)\n"
               "  --sun-elevation DEG     the sun above the horizon (default 30)\n"
               "  --sun-azimuth DEG       clockwise from north, -z (default 150)\n"
               "  --moon EL,AZ            the moon at that elevation and azimuth (degrees; its\n"
               "                          phase from where the sun is); with the sun down it\n"
               "                          lights the world (default: none, or with\n"
               "                          --time-of-day the moon of the place and date)\n"
               "  --no-moon               no moon, with --time-of-day either\n"
               "  --camera X,Y,Z[,YAW,PITCH[,FOV]]\n"
               "                          metres (y up, origin on the planet's ground; a\n"
               "                          world's valleys may go 10 km under it) and degrees: yaw\n"
               "                          clockwise from north, pitch above the horizontal,\n"
               "                          vertical field of view (default 0,2,0,0,3,50; under\n"
               "                          the world's surface, lifted onto it; when that cannot\n"
               "                          see the world, one that frames it)\n"
               "  --world FILE            the world: a skybake world file (.json) or a mesh assimp\n"
               "                          reads (default: the world the pack's probes were baked\n"
               "                          against, else the built-in data/worlds/test.json)\n"
               "  --no-probes             light the world with the sky alone, ignoring the pack's\n"
               "                          sky-visibility probes\n"
               "  --no-far-shadows        raster: nothing shadowed past the last cascade (no far\n"
               "                          map over the world's casters)\n"
               "  --no-contact-shadows    the raster scene's shadows from the cascades alone,\n"
               "                          without the screen-space contact shadows\n"
               "  --no-reflections        the sky model's ambient specular, ignoring the pack's\n"
               "                          reflection probes\n"
               "  --baked-reflections     the reflection cubes as baked (scaled by the sky's light\n"
               "                          under another sun), though the pack could relight them\n"
               "  --relight N             reflection cubes relit a frame at most as the sun moves\n"
               "                          (default 2; a still relights every one)\n"
               "  --relight-always        relight that many every frame, the sun moving or not:\n"
               "                          what a day's sweep costs, for --bench\n"
               "  --no-textures           the world's materials without their images (their\n"
               "                          colours and factors alone)\n"
               "  --no-fog                leave out the scene's fog\n"
               "  --fog-tile PX           a froxel's width and height in pixels (default 8)\n"
               "  --fog-slices N          froxel slices, 2 to 256 (default 64)\n"
               "  --fog-far M             where the froxel volume ends, metres (default 256);\n"
               "                          the height fog goes on beyond it in closed form\n"
               "  --no-clouds             leave out the cloud layer (drawn when the pack has the\n"
               "                          cloud noise; the scene's cloud_layer shapes it)\n"
               "  --cloud-scale N         trace the clouds at one pixel in N x N a frame, the rest\n"
               "                          reprojected: 1, 2 or 4 (default 2)\n"
               "  --cloud-steps N         view march steps at most, 8 to 1024 (default 128)\n"
               "  --cloud-light-steps N   steps toward the sun, 1 to 16 (default 6)\n"
               "  --cloud-shadow-size N   texels per side of the clouds' shadow map over 16 km,\n"
               "                          16 to 4096 (default 512)\n"
               "  --tonemap agx|aces|gt   tone mapper (default agx)\n"
               "  --grade FILE.cube       grade through a 3D LUT (.cube, trilinear): by default the\n"
               "                          tone-mapped sRGB frame, each 8-bit code in and out (a\n"
               "                          neutral LUT leaves the frame unchanged)\n"
               "  --grade-space srgb|acescct\n"
               "                          the LUT's input: the sRGB frame (default), or the exposed\n"
               "                          scene-linear frame in ACEScct, before the tone curve\n"
               "  --white-balance K[,TINT]\n"
               "                          render light of colour temperature K (1000 to 15000)\n"
               "                          white; TINT moves that light off the Planckian locus,\n"
               "                          in Duv/1000, positive toward magenta (default 6504,0:\n"
               "                          none; D65 is 6504 K)\n"
               "  --saturation S          about the luminance, before the tone curve: 0 grey, 1 none\n"
               "                          (default), up to 4\n"
               "  --contrast C            before the tone curve, each channel 0.18 (c / 0.18)^C:\n"
               "                          1 none (default), 0.25 to 4\n"
               "  --local-contrast C      local tone mapping: the large-scale contrast about the\n"
               "                          frame's mean (bilateral grid, detail kept), 0.25 to 1;\n"
               "                          1: none (default 0.7)\n"
               "  --no-purkinje           no Purkinje shift (by default dim light, below 5 cd/m^2,\n"
               "                          shifts toward blue as the eye's rods see it)\n"
               "  --sun-lux LUX           the sun's illuminance above the atmosphere, which makes\n"
               "                          the pack's radiance absolute for the Purkinje shift\n"
               "                          and the EV range (default 128000, the earth's)\n"
               "  --exposure EV           exposure compensation (default 0)\n"
               "  --ev-range MIN,MAX      the luminance the exposure adapts within, as EV at ISO\n"
               "                          100 (default -5,18: a moonlit night to sunlit snow)\n"
               "  --dim-compensation S    stops taken off the exposure a stop under dusk (EV100\n"
               "                          5), so nights stay darker than days (default 0.333;\n"
               "                          0: none)\n"
               "  --no-bloom              no bloom\n"
               "  --shadow-size N         texels per side of each of the 4 cascades (default 2048)\n"
               "  --scene auto|raster|traced\n"
               "                          how the world is drawn: rasterised with cascaded shadow\n"
               "                          maps (penumbrae estimated, PCSS), or one ray a pixel\n"
               "                          with shadow rays (exact; penumbrae from a ray a frame\n"
               "                          over the sun's disk); auto: traced on a GPU, rasterised\n"
               "                          on a CPU device (default)\n"
               "  --hdr                   also write the linear HDR frames, frame_0000.exr, ...\n"
               "  --bench                 time the passes: warm-up frames, then --frames frames,\n"
               "                          each drawn twice, its passes alone (their times)\n"
               "                          and as rendered (the frame's GPU and wall time);\n"
               "                          prints a table and writes OUT_DIR/bench.json\n"
               "  --warmup N              warm-up frames for --bench (default 5)\n"
               "  --device NAME|INDEX     Vulkan device by index or name substring\n"
               "  --validate              enable Vulkan validation; any message fails the run\n"
               "                          (also SKYBAKE_VALIDATE=1)\n"
               "  -q, --quiet             warnings and errors only\n"
               "  -v, --verbose           debug messages\n"
               "\n"
               "a window (GLFW; headless is the default):\n"
               "  --window                show the frames in a window, interactively: W A S D Q E\n"
               "                          fly (Shift faster), drag the mouse to look, arrow keys\n"
               "                          move the sun (with --time-of-day H, the hour), 1 to 8\n"
               "                          switch fog, contact shadows, clouds, Purkinje, local\n"
               "                          tone mapping, scene-linear grading, bloom, the LUT; H\n"
               "                          the timing overlay, P a screenshot into OUT_DIR\n"
               "                          (default .), Esc quits. With --frames N: N frames as\n"
               "                          headless, then close\n"
               "  --screenshot FILE       with --window --frames N: the swapchain's last image as\n"
               "                          PNG\n"
               "  --no-overlay            start without the timing overlay\n"
               "\n"
               "time of day (the sun from a place and a date, or from keys; -z is north):\n"
               "  --time-of-day H | FROM-TO\n"
               "                          the sun at local time H (hours), or a sweep from FROM to\n"
               "                          TO (0 to 48) over --frames frames (default: enough that\n"
               "                          the sun moves at most 0.2 degrees a frame, which keeps\n"
               "                          the fog's and clouds' history), exposure adapting and\n"
               "                          the clouds drifting between frames as in playback;\n"
               "                          writes OUT_DIR/day.mp4 (ffmpeg) or frame_0000.png, ...,\n"
               "                          and OUT_DIR/sequence.json (each frame's hour, sun,\n"
               "                          moon and exposure)\n"
               "  --location LAT,LON      degrees, north and east positive (default 45,0)\n"
               "  --date YYYY-MM-DD       1800 to 2100 (default 2026-06-21, the June solstice)\n"
               "  --utc-offset H          hours are clock time H ahead of UTC (default: the\n"
               "                          longitude's mean solar time, LON / 15)\n"
               "  --sun-keys H:EL:AZ,...  the sun from keys instead (hours, degrees): a monotone\n"
               "                          cubic through them, azimuth the short way round\n"
               "  --fps N                 playback rate: the time between frames for exposure\n"
               "                          and drift, and the video's rate (default 30)\n"
               "  --encoder auto|ffmpeg|png\n"
               "                          a sweep's frames as an H.264 MP4 through ffmpeg, or as\n"
               "                          numbered PNGs; auto: ffmpeg when installed (default)\n"
               "  --contact-sheet STEP    instead of the sweep, OUT_DIR/contact_sheet.png: the day\n"
               "                          at every multiple of STEP hours from FROM to TO, each\n"
               "                          frame settled (8 frames at its hour), labelled with\n"
               "                          its time and sun (--size is a frame's; default 480x270)\n"
               "\n"
               "environment: SKYBAKE_VALIDATE=1 as --validate; SKYBAKE_PIPELINE_STATS=1 logs\n"
               "each compute kernel's registers and memory as the driver reports them (on\n"
               "NVIDIA; not with -q).\n"
               "\n"
               "exit codes: 0 ok, 1 rendering failed, 2 usage, pack or world error,\n"
               "            3 no Vulkan device, 4 validation messages\n");
}

static bool parse_doubles(const char *s, double *out, int min, int max, int *count)
{
    int n = 0;
    while (*s && n < max) {
        char *end;
        errno = 0;
        double v = strtod(s, &end);
        if (end == s || errno || !isfinite(v))
            return false;
        out[n++] = v;
        s = end;
        if (*s == ',')
            s++;
        else if (*s)
            return false;
    }
    *count = n;
    return !*s && n >= min;
}

static bool parse_number(const char *s, double lo, double hi, double *out)
{
    int n;
    return parse_doubles(s, out, 1, 1, &n) && *out >= lo && *out <= hi;
}

struct options {
    const char *pack, *out_dir, *world;
    const char *grade;      /* a .cube file, or NULL */
    struct sb_vk_params vk; /* the environment's, then --device and --validate */
    struct sb_renderer_params params;
    struct sb_view view;
    bool camera_given; /* --camera: else the default, unless it cannot see the world */
    int frames, warmup;
    bool hdr, bench;
    /* Time of day: the sun from sun_path at day_from (one hour), or swept to day_to. */
    bool time_of_day, sweep;
    double day_from, day_to;
    struct sb_sun_path sun_path;
    bool no_moon; /* the path's place has no moon */
    double fps;
    enum { ENCODER_AUTO, ENCODER_FFMPEG, ENCODER_PNG } encoder;
    double sheet_step_h; /* > 0: a contact sheet instead of the sweep */
    bool window, no_overlay;
    const char *screenshot;
    const char *set[16]; /* options given that only go with some others, for the checks after parsing */
    int set_count;
};

static bool given(const struct options *o, const char *name)
{
    for (int i = 0; i < o->set_count; i++)
        if (!strcmp(o->set[i], name))
            return true;
    return false;
}

/* Remember that option `a` was given, for check_combinations (once: set[]
 * has room for every option noted). */
static void note_option(struct options *o, const char *a)
{
    if (!given(o, a) && o->set_count < (int)(sizeof(o->set) / sizeof(o->set[0])))
        o->set[o->set_count++] = a;
}

/* The sweep's frames when --frames is not given: enough that the sun moves
 * less than the renderer's history limit between two (sampled each minute). */
static int sweep_frames(const struct options *o)
{
    double fastest = 0.0, previous[3] = {0.0, 0.0, 0.0};
    for (double h = o->day_from; h <= o->day_to + 1e-9; h += 1.0 / 60.0) {
        double e, a, d[3];
        sb_sun_path_at(&o->sun_path, h, &e, &a);
        sb_direction(a, e, d);
        if (h > o->day_from) {
            double cosine = d[0] * previous[0] + d[1] * previous[1] + d[2] * previous[2];
            fastest = fmax(fastest, acos(fmin(1.0, cosine)) * 60.0); /* radians an hour */
        }
        memcpy(previous, d, sizeof(d));
    }
    double steps = ceil((o->day_to - o->day_from) * fastest / (0.95 * SB_SUN_HISTORY_LIMIT_DEG * DEG));
    return (int)fmin(100000.0, fmax(2.0, steps + 1.0));
}

#define SHEET_MAX_FRAMES 64 /* a contact sheet's */

/* Options that go only with others, and the defaults that depend on them. */
static int check_combinations(struct options *o)
{
    static const char *const need_time[] = {"--location", "--date",    "--utc-offset",   "--sun-keys",
                                            "--fps",      "--encoder", "--contact-sheet"};
    for (size_t i = 0; i < sizeof(need_time) / sizeof(need_time[0]); i++)
        if (!o->time_of_day && given(o, need_time[i])) {
            fprintf(stderr, "skyview: %s goes with --time-of-day\n", need_time[i]);
            return EXIT_USAGE;
        }
    if (given(o, "--moon") && given(o, "--no-moon")) {
        fprintf(stderr, "skyview: --moon and --no-moon: give one\n");
        return EXIT_USAGE;
    }
    if (o->time_of_day) {
        static const char *const fixed_sun[] = {"--sun-elevation", "--sun-azimuth", "--moon"};
        for (int i = 0; i < 3; i++)
            if (given(o, fixed_sun[i])) {
                fprintf(stderr, "skyview: %s and --time-of-day both place the %s: give one\n", fixed_sun[i],
                        i == 2 ? "moon" : "sun");
                return EXIT_USAGE;
            }
        static const char *const place[] = {"--location", "--date", "--utc-offset"};
        for (int i = 0; i < 3; i++)
            if (o->sun_path.key_count && given(o, place[i])) {
                fprintf(stderr, "skyview: %s places the sun by the date, --sun-keys by keys: give one\n", place[i]);
                return EXIT_USAGE;
            }
        if (o->bench) {
            fprintf(stderr, "skyview: --bench times frames of one sun: it does not go with --time-of-day\n");
            return EXIT_USAGE;
        }
        if ((given(o, "--encoder") || given(o, "--contact-sheet")) && !o->sweep) {
            fprintf(stderr, "skyview: %s needs a sweep, --time-of-day FROM-TO\n",
                    given(o, "--encoder") ? "--encoder" : "--contact-sheet");
            return EXIT_USAGE;
        }
        if (o->sheet_step_h > 0.0 && given(o, "--encoder")) {
            fprintf(stderr, "skyview: --contact-sheet writes one PNG: --encoder does not go with it\n");
            return EXIT_USAGE;
        }
        if (o->sheet_step_h > 0.0 && ceil(o->day_from / o->sheet_step_h - 1e-9) * o->sheet_step_h > o->day_to + 1e-9) {
            fprintf(stderr, "skyview: --contact-sheet %g: no multiple of %g hours from %g to %g\n", o->sheet_step_h,
                    o->sheet_step_h, o->day_from, o->day_to);
            return EXIT_USAGE;
        }
        double first = ceil(o->day_from / o->sheet_step_h - 1e-9), last = floor(o->day_to / o->sheet_step_h + 1e-9);
        if (o->sheet_step_h > 0.0 && last - first + 1.0 > SHEET_MAX_FRAMES) {
            fprintf(stderr, "skyview: --contact-sheet %g: %.0f frames from %g to %g h, more than %d\n", o->sheet_step_h,
                    last - first + 1.0, o->day_from, o->day_to, SHEET_MAX_FRAMES);
            return EXIT_USAGE;
        }
        if (o->sheet_step_h > 0.0 && o->frames >= 0) {
            fprintf(stderr, "skyview: --contact-sheet renders one frame an hour it shows: --frames does not go "
                            "with it\n");
            return EXIT_USAGE;
        }
        if (o->sweep && o->frames == 1) {
            fprintf(stderr, "skyview: a sweep, --time-of-day FROM-TO, needs --frames 2 or more\n");
            return EXIT_USAGE;
        }
    }
    static const char *const need_window[] = {"--screenshot", "--no-overlay"};
    for (int i = 0; i < 2; i++)
        if (!o->window && given(o, need_window[i])) {
            fprintf(stderr, "skyview: %s goes with --window\n", need_window[i]);
            return EXIT_USAGE;
        }
    if (o->window && (o->bench || o->sweep || o->hdr)) {
        fprintf(stderr, "skyview: --window shows frames as they come: not with %s\n",
                o->bench   ? "--bench"
                : o->sweep ? "a sweep (--time-of-day FROM-TO)"
                           : "--hdr");
        return EXIT_USAGE;
    }
    if (o->screenshot && o->frames < 0) {
        fprintf(stderr, "skyview: --screenshot is taken after --frames N: give N\n");
        return EXIT_USAGE;
    }
    if (o->window)
        return 0; /* frames < 0: until the window closes */
    if (o->frames < 0)
        o->frames = o->bench ? 30 : o->sweep ? sweep_frames(o) : 1;
    return 0;
}

static int parse_options(int argc, char **argv, struct options *o)
{
    memset(o, 0, sizeof(*o));
    o->world = NULL; /* the built-in test world */
    o->frames = -1;
    o->warmup = 5;
    o->view = (struct sb_view){
        .camera_m = {0.0, 2.0, 0.0},
        .pitch = 3.0 * DEG,
        .fov_y = 50.0 * DEG,
        .sun_azimuth = 150.0 * DEG,
        .sun_elevation = 30.0 * DEG,
    };
    o->vk = sb_vk_params_from_env();
    o->vk.graphics = true;
    o->params.grading = (struct sb_grading){
        .enabled = true,
        .white_balance_k = SB_GRADING_NEUTRAL_K,
        .saturation = 1.0,
        .contrast = 1.0,
    };
    o->params.purkinje = true;
    o->params.local_contrast = 0.7;
    o->sun_path.latitude_deg = 45.0;
    o->fps = 30.0;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        const char *next = i + 1 < argc ? argv[i + 1] : NULL;
        double v, c[6];
        int n;
        bool ok = true;
        if ((!strcmp(a, "-o") || !strcmp(a, "--output")) && next)
            o->out_dir = argv[++i];
        else if (!strcmp(a, "--size") && next) {
            unsigned w, h;
            char extra;
            ok = sscanf(argv[++i], "%ux%u%c", &w, &h, &extra) == 2 && w >= 8 && h >= 8 && w <= 8192 && h <= 8192;
            o->params.width = w;
            o->params.height = h;
        } else if (!strcmp(a, "--frames") && next) {
            ok = parse_number(argv[++i], 1, 100000, &v) && v == floor(v);
            o->frames = (int)v;
        } else if (!strcmp(a, "--relight") && next) {
            ok = parse_number(argv[++i], 1, 64, &v) && v == floor(v);
            o->params.relight_cubes = (uint32_t)v;
        } else if (!strcmp(a, "--relight-always")) {
            o->params.relight_always = true;
        } else if (!strcmp(a, "--warmup") && next) {
            ok = parse_number(argv[++i], 0, 10000, &v) && v == floor(v);
            o->warmup = (int)v;
        } else if (!strcmp(a, "--sun-elevation") && next) {
            ok = parse_number(argv[++i], -90, 90, &v);
            o->view.sun_elevation = v * DEG;
            note_option(o, a);
        } else if (!strcmp(a, "--sun-azimuth") && next) {
            ok = parse_number(argv[++i], -360, 360, &v);
            o->view.sun_azimuth = v * DEG;
            note_option(o, a);
        } else if (!strcmp(a, "--moon") && next) {
            ok = parse_doubles(argv[++i], c, 2, 2, &n) && fabs(c[0]) <= 90.0 && fabs(c[1]) <= 360.0;
            o->view.moon = true;
            o->view.moon_elevation = c[0] * DEG;
            o->view.moon_azimuth = c[1] * DEG;
            note_option(o, a);
        } else if (!strcmp(a, "--no-moon")) {
            o->no_moon = true;
            note_option(o, a);
        } else if (!strcmp(a, "--time-of-day") && next) {
            const char *t = argv[++i];
            char *dash = strchr(t, '-');
            o->time_of_day = true;
            if (dash) {
                char from[64];
                snprintf(from, sizeof(from), "%.*s", (int)(dash - t), t);
                ok = (size_t)(dash - t) < sizeof(from) && parse_number(from, 0, 48, &o->day_from) &&
                     parse_number(dash + 1, 0, 48, &o->day_to) && o->day_to > o->day_from;
                o->sweep = true;
            } else {
                ok = parse_number(t, 0, 48, &o->day_from);
                o->day_to = o->day_from;
            }
        } else if (!strcmp(a, "--location") && next) {
            ok = parse_doubles(argv[++i], c, 2, 2, &n) && fabs(c[0]) <= 90.0 && fabs(c[1]) <= 180.0;
            o->sun_path.latitude_deg = c[0];
            o->sun_path.longitude_deg = c[1];
            note_option(o, a);
        } else if (!strcmp(a, "--date") && next) {
            char why[256];
            struct sb_sun_path *p = &o->sun_path;
            if (!sb_parse_date(argv[++i], &p->year, &p->month, &p->day, why, sizeof(why))) {
                fprintf(stderr, "skyview: --date: %s\n", why);
                return EXIT_USAGE;
            }
            note_option(o, a);
        } else if (!strcmp(a, "--utc-offset") && next) {
            ok = parse_number(argv[++i], -14, 14, &v);
            o->sun_path.has_utc_offset = true;
            o->sun_path.utc_offset_h = v;
            note_option(o, a);
        } else if (!strcmp(a, "--sun-keys") && next) {
            char why[256];
            if (!sb_sun_path_parse_keys(argv[++i], &o->sun_path, why, sizeof(why))) {
                fprintf(stderr, "skyview: --sun-keys: %s\n", why);
                return EXIT_USAGE;
            }
            note_option(o, a);
        } else if (!strcmp(a, "--fps") && next) {
            ok = parse_number(argv[++i], 1, 240, &v);
            o->fps = v;
            note_option(o, a);
        } else if (!strcmp(a, "--encoder") && next) {
            const char *t = argv[++i];
            ok = !strcmp(t, "auto") || !strcmp(t, "ffmpeg") || !strcmp(t, "png");
            o->encoder = !strcmp(t, "ffmpeg") ? ENCODER_FFMPEG : !strcmp(t, "png") ? ENCODER_PNG : ENCODER_AUTO;
            note_option(o, a);
        } else if (!strcmp(a, "--window")) {
            o->window = true;
        } else if (!strcmp(a, "--no-overlay")) {
            o->no_overlay = true;
            note_option(o, a);
        } else if (!strcmp(a, "--screenshot") && next) {
            o->screenshot = argv[++i];
            note_option(o, a);
        } else if (!strcmp(a, "--contact-sheet") && next) {
            ok = parse_number(argv[++i], 1.0 / 60.0, 24, &o->sheet_step_h);
            note_option(o, a);
        } else if (!strcmp(a, "--camera") && next) {
            ok = parse_doubles(argv[++i], c, 3, 6, &n) && fabs(c[0]) <= 1e7 && fabs(c[2]) <= 1e7 &&
                 c[1] >= -SB_CAMERA_LOWEST_M && c[1] <= 1e8;
            if (ok) {
                o->camera_given = true;
                memcpy(o->view.camera_m, c, sizeof(o->view.camera_m));
                if (n >= 5) {
                    o->view.yaw = c[3] * DEG;
                    o->view.pitch = c[4] * DEG;
                    ok = fabs(c[4]) <= 90.0;
                }
                if (n >= 6) {
                    o->view.fov_y = c[5] * DEG;
                    ok = ok && c[5] > 1.0 && c[5] < 170.0;
                }
            }
        } else if (!strcmp(a, "--grade") && next)
            o->grade = argv[++i];
        else if (!strcmp(a, "--grade-space") && next) {
            const char *t = argv[++i];
            ok = !strcmp(t, "srgb") || !strcmp(t, "acescct");
            o->params.grade_log = !strcmp(t, "acescct");
        } else if (!strcmp(a, "--white-balance") && next) {
            ok = parse_doubles(argv[++i], c, 1, 2, &n) && c[0] >= 1000.0 && c[0] <= 15000.0 &&
                 (n < 2 || fabs(c[1]) <= 50.0);
            o->params.grading.white_balance_k = c[0];
            o->params.grading.tint = n == 2 ? c[1] : 0.0;
        } else if (!strcmp(a, "--saturation") && next) {
            ok = parse_number(argv[++i], 0, 4, &v);
            o->params.grading.saturation = v;
        } else if (!strcmp(a, "--contrast") && next) {
            ok = parse_number(argv[++i], 0.25, 4, &v);
            o->params.grading.contrast = v;
        } else if (!strcmp(a, "--local-contrast") && next) {
            ok = parse_number(argv[++i], 0.25, 1, &v);
            o->params.local_contrast = v;
        } else if (!strcmp(a, "--no-purkinje"))
            o->params.purkinje = false;
        else if (!strcmp(a, "--ev-range") && next) {
            ok = parse_doubles(argv[++i], c, 2, 2, &n) && c[0] >= -20.0 && c[1] <= 30.0 && c[0] < c[1];
            o->params.exposure_min_ev100 = c[0];
            o->params.exposure_max_ev100 = c[1];
        } else if (!strcmp(a, "--dim-compensation") && next) {
            ok = parse_number(argv[++i], 0.0, 1.0, &v);
            o->params.dim_compensation = v > 0.0 ? v : -1.0;
        } else if (!strcmp(a, "--sun-lux") && next) {
            ok = parse_number(argv[++i], 1e-3, 1e7, &v);
            o->params.sun_illuminance_lux = v;
        } else if (!strcmp(a, "--world") && next)
            o->world = argv[++i];
        else if (!strcmp(a, "--tonemap") && next) {
            const char *t = argv[++i];
            o->params.tonemap = !strcmp(t, "agx")    ? SB_TONEMAP_AGX
                                : !strcmp(t, "aces") ? SB_TONEMAP_ACES
                                : !strcmp(t, "gt")   ? SB_TONEMAP_GT
                                                     : -1;
            ok = o->params.tonemap >= 0;
        } else if (!strcmp(a, "--scene") && next) {
            const char *t = argv[++i];
            int m = !strcmp(t, "auto")     ? SB_SCENE_AUTO
                    : !strcmp(t, "raster") ? SB_SCENE_RASTER
                    : !strcmp(t, "traced") ? SB_SCENE_TRACED
                                           : -1;
            ok = m >= 0;
            o->params.scene = m >= 0 ? (enum sb_scene_method)m : SB_SCENE_AUTO;
        } else if (!strcmp(a, "--exposure") && next) {
            ok = parse_number(argv[++i], -20, 20, &v);
            o->params.exposure_compensation_ev = v;
        } else if (!strcmp(a, "--no-bloom"))
            o->params.bloom_strength = -1.0;
        else if (!strcmp(a, "--shadow-size") && next) {
            ok = parse_number(argv[++i], 64, 8192, &v) && v == floor(v);
            o->params.shadow_size = (uint32_t)v;
        } else if (!strcmp(a, "--hdr"))
            o->hdr = true;
        else if (!strcmp(a, "--no-probes"))
            o->params.no_probes = true;
        else if (!strcmp(a, "--no-far-shadows"))
            o->params.no_far_shadows = true;
        else if (!strcmp(a, "--no-contact-shadows"))
            o->params.no_contact_shadows = true;
        else if (!strcmp(a, "--no-reflections"))
            o->params.no_reflections = true;
        else if (!strcmp(a, "--baked-reflections"))
            o->params.baked_reflections = true;
        else if (!strcmp(a, "--no-textures"))
            o->params.no_textures = true;
        else if (!strcmp(a, "--no-fog"))
            o->params.no_fog = true;
        else if (!strcmp(a, "--fog-tile") && next) {
            ok = parse_number(argv[++i], 1, 64, &v) && v == floor(v);
            o->params.fog_tile_px = (uint32_t)v;
        } else if (!strcmp(a, "--fog-slices") && next) {
            ok = parse_number(argv[++i], 2, 256, &v) && v == floor(v);
            o->params.fog_slices = (uint32_t)v;
        } else if (!strcmp(a, "--fog-far") && next) {
            ok = parse_number(argv[++i], 1, 1e5, &v);
            o->params.fog_far_m = v;
        } else if (!strcmp(a, "--no-clouds"))
            o->params.no_clouds = true;
        else if (!strcmp(a, "--cloud-scale") && next) {
            ok = parse_number(argv[++i], 1, 4, &v) && (v == 1 || v == 2 || v == 4);
            o->params.cloud_scale = (uint32_t)v;
        } else if (!strcmp(a, "--cloud-steps") && next) {
            ok = parse_number(argv[++i], 8, 1024, &v) && v == floor(v);
            o->params.cloud_steps = (uint32_t)v;
        } else if (!strcmp(a, "--cloud-light-steps") && next) {
            ok = parse_number(argv[++i], 1, SB_CLOUD_MAX_LIGHT_STEPS, &v) && v == floor(v);
            o->params.cloud_light_steps = (uint32_t)v;
        } else if (!strcmp(a, "--cloud-shadow-size") && next) {
            ok = parse_number(argv[++i], 16, 4096, &v) && v == floor(v);
            o->params.cloud_shadow_size = (uint32_t)v;
        } else if (!strcmp(a, "--bench"))
            o->bench = true;
        else if (!strcmp(a, "--device") && next)
            o->vk.device = argv[++i];
        else if (!strcmp(a, "--validate"))
            o->vk.validate = true;
        else if (!strcmp(a, "-q") || !strcmp(a, "--quiet"))
            sb_log_set_level(SB_LOG_WARN);
        else if (!strcmp(a, "-v") || !strcmp(a, "--verbose"))
            sb_log_set_level(SB_LOG_DEBUG);
        else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "skyview: unknown or incomplete option '%s'\n", a);
            usage(stderr);
            return EXIT_USAGE;
        } else if (!o->pack)
            o->pack = a;
        else {
            fprintf(stderr, "skyview: unexpected argument '%s'\n", a);
            return EXIT_USAGE;
        }
        if (!ok) {
            fprintf(stderr, "skyview: %s: bad value '%s'\n", a, argv[i]);
            usage(stderr);
            return EXIT_USAGE;
        }
    }
    if (o->params.grade_log && !o->grade) {
        fprintf(stderr, "skyview: --grade-space acescct applies a LUT: it needs --grade FILE.cube\n");
        return EXIT_USAGE;
    }
    if (o->window && !o->out_dir)
        o->out_dir = "."; /* where P's screenshots go */
    if (!o->pack || !o->out_dir) {
        fprintf(stderr, "skyview: needs a PACK and -o OUT_DIR\n");
        usage(stderr);
        return EXIT_USAGE;
    }
    return check_combinations(o);
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof(double), compare_doubles);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* Write `root` formatted to `path` (then free it); SB_ERR_IO naming the path. */
static enum sb_result write_json(const char *path, cJSON *root)
{
    char *text = cJSON_Print(root);
    cJSON_Delete(root);
    if (!text)
        return SB_ERR_NOMEM;
    size_t n = strlen(text);
    char *with_newline = realloc(text, n + 2);
    if (!with_newline) {
        free(text);
        return SB_ERR_NOMEM;
    }
    with_newline[n] = '\n';
    with_newline[n + 1] = '\0';
    enum sb_result res = sb_write_file(path, with_newline, n + 1, "JSON");
    free(with_newline);
    return res;
}

/* What --bench measures of a frame: each pass alone (a barrier after
 * each, sb_view.isolate_passes), and the frame as it is rendered (the
 * render graph's barriers alone), on the GPU's clock and the host's
 * (recording, submission and the wait: on llvmpipe, whose timestamps can
 * book one pass's work to another, the truer figure). */
struct bench_frame {
    struct sb_frame_timings alone, rendered;
    double wall_ms;
};

/* One row of the table and of bench.json: the median, min and max of the n values. */
static void bench_row(cJSON *array, const char *name, double *v, int n)
{
    double med = median(v, n);
    printf("%-28s %12.3f %12.3f %12.3f\n", name, med, v[0], v[n - 1]);
    cJSON *item = cJSON_CreateObject();
    cJSON_AddStringToObject(item, "pass", name);
    cJSON_AddNumberToObject(item, "median_ms", med);
    cJSON_AddNumberToObject(item, "min_ms", v[0]);
    cJSON_AddNumberToObject(item, "max_ms", v[n - 1]);
    cJSON_AddItemToArray(array, item);
}

/* The bench table on stdout and the same numbers as JSON in OUT_DIR/bench.json. */
static enum sb_result report_bench(const struct options *o, const struct sb_vk *vk, uint32_t w, uint32_t h,
                                   const struct bench_frame *f, int n)
{
    double *v = malloc((size_t)n * sizeof(double));
    if (!v)
        return SB_ERR_NOMEM;
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "skyview", SKYBAKE_VERSION);
    cJSON_AddStringToObject(root, "device", vk->properties.deviceName);
    cJSON_AddStringToObject(root, "driver", vk->driver_name);
    cJSON_AddNumberToObject(root, "width", w);
    cJSON_AddNumberToObject(root, "height", h);
    cJSON_AddNumberToObject(root, "warmup_frames", o->warmup);
    cJSON_AddNumberToObject(root, "frames", n);
    cJSON_AddStringToObject(root, "statistic", "median over the frames");
    cJSON *passes = cJSON_AddArrayToObject(root, "passes");
    printf("skyview bench: %ux%u on %s, median of %d frames after %d warm-up\n", w, h, vk->properties.deviceName, n,
           o->warmup);
    printf("%-28s %12s %12s %12s\n", "pass (each alone)", "median ms", "min ms", "max ms");
    for (int p = 0; p <= SB_PASS_COUNT; p++) {
        for (int i = 0; i < n; i++)
            v[i] = p < SB_PASS_COUNT ? f[i].alone.ms[p] : f[i].alone.total_ms;
        bench_row(passes, p < SB_PASS_COUNT ? sb_pass_name((enum sb_pass)p) : "total", v, n);
    }
    cJSON *frame = cJSON_AddArrayToObject(root, "frame");
    for (int i = 0; i < n; i++)
        v[i] = f[i].rendered.total_ms;
    bench_row(frame, "frame as rendered, GPU", v, n);
    for (int i = 0; i < n; i++)
        v[i] = f[i].wall_ms;
    bench_row(frame, "frame as rendered, wall", v, n);
    free(v);
    char path[4200];
    snprintf(path, sizeof(path), "%s/bench.json", o->out_dir);
    return write_json(path, root);
}

/* The frame's HDR image as OUT_DIR/frame_NNNN.exr. */
static enum sb_result write_hdr(const struct options *o, struct sb_renderer *r, int index)
{
    uint32_t w, h;
    sb_renderer_size(r, &w, &h);
    struct sb_image image = {0};
    enum sb_result res = sb_image_init(&image, w, h, 3);
    if (res)
        return res;
    sb_image_set_channel_names(&image, "R,G,B");
    sb_renderer_hdr(r, image.data);
    char path[4200];
    snprintf(path, sizeof(path), "%s/frame_%04d.exr", o->out_dir, index);
    res = sb_exr_write(path, &image, NULL, 0);
    sb_image_finish(&image);
    return res;
}

/* The frame as OUT_DIR/frame_NNNN.png, or into the video; with --hdr, its EXR too. */
static enum sb_result write_frame(const struct options *o, struct sb_renderer *r, int index, struct sb_video *video)
{
    uint32_t w, h;
    sb_renderer_size(r, &w, &h);
    enum sb_result res;
    if (video)
        res = sb_video_write(video, sb_renderer_ldr(r));
    else {
        char path[4200];
        snprintf(path, sizeof(path), "%s/frame_%04d.png", o->out_dir, index);
        res = sb_png_write(path, w, h, sb_renderer_ldr(r));
    }
    return res || !o->hdr ? res : write_hdr(o, r, index);
}

/* The local time `hour` as HH:MM (the day after from 24). */
static void format_hour(double hour, char *out, size_t size)
{
    long minutes = lround(hour * 60.0);
    snprintf(out, size, "%02ld:%02ld%s", minutes / 60 % 24, minutes % 60, minutes >= 24 * 60 ? " +1d" : "");
}

/*
 * A day: --frames frames from day_from to day_to, the sun on the path, each
 * frame 1/fps after the one before (exposure adapts, clouds and fog drift and
 * keep their history as in playback); the first is a cut. Each frame's hour,
 * sun and exposure go to OUT_DIR/sequence.json.
 */
static enum sb_result render_day(const struct options *o, struct sb_renderer *r, struct sb_video *video)
{
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "skyview", SKYBAKE_VERSION);
    cJSON_AddNumberToObject(root, "from_hour", o->day_from);
    cJSON_AddNumberToObject(root, "to_hour", o->day_to);
    cJSON_AddNumberToObject(root, "fps", o->fps);
    cJSON_AddStringToObject(root, "output", video ? "day.mp4" : "frame_NNNN.png");
    cJSON *frames = cJSON_AddArrayToObject(root, "frames");
    enum sb_result res = SB_OK;
    int largest_step_frame = -1;
    double largest_step = 0.0, previous[3] = {0.0, 0.0, 0.0};
    sb_progress("frames", 0, (unsigned)o->frames);
    for (int i = 0; i < o->frames && !res; i++) {
        double hour = o->day_from + (o->day_to - o->day_from) * i / (o->frames - 1);
        struct sb_view view = o->view;
        sb_view_at_hour(&view, &o->sun_path, hour, !o->no_moon);
        view.snap_exposure = i == 0;
        view.dt_s = 1.0 / o->fps;
        view.time_s = i / o->fps;
        res = sb_renderer_render(r, &view, true, NULL);
        if (!res)
            res = write_frame(o, r, i, video);
        double d[3];
        sb_direction(view.sun_azimuth, view.sun_elevation, d);
        double step = acos(fmin(1.0, d[0] * previous[0] + d[1] * previous[1] + d[2] * previous[2])) / DEG;
        if (i > 0 && step > largest_step) {
            largest_step = step;
            largest_step_frame = i;
        }
        memcpy(previous, d, sizeof(d));
        float exposure[4];
        sb_renderer_exposure(r, exposure);
        cJSON *f = cJSON_CreateObject();
        cJSON_AddNumberToObject(f, "frame", i);
        cJSON_AddNumberToObject(f, "hour", hour);
        cJSON_AddNumberToObject(f, "sun_elevation_deg", view.sun_elevation / DEG);
        cJSON_AddNumberToObject(f, "sun_azimuth_deg", view.sun_azimuth / DEG);
        if (view.moon) {
            cJSON_AddNumberToObject(f, "moon_elevation_deg", view.moon_elevation / DEG);
            cJSON_AddNumberToObject(f, "moon_azimuth_deg", view.moon_azimuth / DEG);
        }
        cJSON_AddNumberToObject(f, "adapted_log2_luminance", exposure[0]);
        cJSON_AddNumberToObject(f, "metered_log2_luminance", exposure[2]);
        cJSON_AddNumberToObject(f, "exposure", exposure[1]);
        cJSON_AddItemToArray(frames, f);
        sb_progress("frames", (unsigned)i + 1, (unsigned)o->frames);
    }
    if (largest_step > SB_SUN_HISTORY_LIMIT_DEG)
        sb_warn("the sun moves up to %.2f degrees a frame (frame %d): the fog's and clouds' history is dropped "
                "past %.1f; --frames %d keeps it",
                largest_step, largest_step_frame, SB_SUN_HISTORY_LIMIT_DEG, sweep_frames(o));
    char path[4200];
    snprintf(path, sizeof(path), "%s/sequence.json", o->out_dir);
    if (res)
        cJSON_Delete(root);
    else
        res = write_json(path, root);
    return res;
}

/* Frames rendered at each hour of a contact sheet: the first a cut, the
 * rest let the clouds' checkerboard and the fog's history fill in. */
#define SHEET_SETTLE_FRAMES 8

/* The day at every multiple of sheet_step_h hours in [day_from, day_to], in
 * one PNG. Each hour's frames start from the same time_s, so every frame
 * shows the same clouds under its own sun. */
static enum sb_result render_contact_sheet(const struct options *o, struct sb_renderer *r)
{
    double hours[SHEET_MAX_FRAMES];
    int n = 0;
    for (double k = ceil(o->day_from / o->sheet_step_h - 1e-9); n < SHEET_MAX_FRAMES; k++) {
        double h = k * o->sheet_step_h;
        if (h > o->day_to + 1e-9)
            break;
        hours[n++] = h;
    }
    uint32_t w, h;
    sb_renderer_size(r, &w, &h);
    struct sb_contact_sheet sheet;
    enum sb_result res = sb_contact_sheet_init(&sheet, w, h, (uint32_t)n);
    sb_progress("frames", 0, (unsigned)n);
    for (int t = 0; t < n && !res; t++) {
        struct sb_view view = o->view;
        sb_view_at_hour(&view, &o->sun_path, hours[t], !o->no_moon);
        view.dt_s = 1.0 / o->fps;
        for (int f = 0; f < SHEET_SETTLE_FRAMES && !res; f++) {
            view.snap_exposure = f == 0;
            view.time_s = f / o->fps;
            res = sb_renderer_render(r, &view, f == SHEET_SETTLE_FRAMES - 1, NULL);
        }
        if (res)
            break;
        char time[32], label[128];
        format_hour(hours[t], time, sizeof(time));
        snprintf(label, sizeof(label), "%s  sun %.1f\xc2\xb0 az %.0f\xc2\xb0", time, view.sun_elevation / DEG,
                 view.sun_azimuth / DEG);
        sb_contact_sheet_put(&sheet, (uint32_t)t, sb_renderer_ldr(r), label);
        sb_progress("frames", (unsigned)t + 1, (unsigned)n);
    }
    if (!res) {
        char path[4200];
        snprintf(path, sizeof(path), "%s/contact_sheet.png", o->out_dir);
        res = sb_png_write(path, sheet.width, sheet.height, sheet.rgba);
        if (!res)
            sb_info("contact sheet: %d frames, %g to %g h every %g h, %ux%u: %s", n, hours[0], hours[n - 1],
                    o->sheet_step_h, sheet.width, sheet.height, path);
    }
    sb_contact_sheet_finish(&sheet);
    return res;
}

/*
 * The world to draw: --world, else the world the pack's probes (or its
 * reflection cubes) were baked against (its scene's world, read from where
 * the baker read it), else the built-in one. Probes and cubes light only
 * the world they were baked for: another world (or the same file changed
 * since) is drawn without them, with a warning.
 */
static enum sb_result load_world(const struct options *o, const struct sb_pack *pack, struct sb_world *world,
                                 struct sb_renderer_params *params)
{
    static const enum sb_product_id baked_against[] = {SB_PRODUCT_SKY_VISIBILITY, SB_PRODUCT_REFLECTION_CUBES};
    char hash[2][64] = {"", ""}, baked_path[1024] = "";
    for (int i = 0; i < 2; i++) {
        const struct sb_artifact *a = &pack->artifacts[baked_against[i]];
        if (!pack->present[baked_against[i]])
            continue;
        snprintf(hash[i], sizeof(hash[i]), "%s", a->world_hash);
        if (!baked_path[0])
            snprintf(baked_path, sizeof(baked_path), "%s", a->world_path);
    }
    enum sb_result res;
    if (o->world || baked_path[0]) {
        /* --world: a mesh file stands on a ground, as a scene's world does by default */
        struct sb_world_params *wp = calloc(1, sizeof(*wp));
        if (!wp)
            return SB_ERR_NOMEM;
        if (o->world) {
            wp->units_m = wp->scale = 1;
            for (int i = 0; i < 3; i++)
                wp->ground.albedo[i] = 0.18;
        } else {
            *wp = pack->scene->world;
        }
        snprintf(wp->file, sizeof(wp->file), "%s", o->world ? o->world : baked_path);
        struct sb_level level;
        res = sb_level_load(wp, "", &level, NULL, 0);
        if (!res)
            res = sb_world_from_level(&level, world);
        sb_level_finish(&level);
        free(wp);
        if (res && !o->world)
            sb_error("%s: the world its probes were baked against cannot be read; name one with --world", o->pack);
    } else {
        res = sb_world_parse(sb_default_world_json, strlen(sb_default_world_json),
                             "the built-in world (data/worlds/test.json)", world);
    }
    if (res)
        return res;
    if (pack->present[SB_PRODUCT_SKY_VISIBILITY] && !params->no_probes && strcmp(hash[0], world->mesh_hash) != 0) {
        sb_warn("%s: its probes were baked against another world (%s, not this one's %s): lit by the sky alone",
                o->pack, hash[0][0] ? hash[0] : "unrecorded", world->mesh_hash);
        params->no_probes = true;
    }
    /* Cubes baked with no world (the sky alone) suit any. */
    if (pack->present[SB_PRODUCT_REFLECTION_CUBES] && !params->no_reflections && hash[1][0] &&
        strcmp(hash[1], world->mesh_hash) != 0) {
        sb_warn("%s: its reflection cubes were captured in another world (%s, not this one's %s): not used", o->pack,
                hash[1], world->mesh_hash);
        params->no_reflections = true;
    }
    return SB_OK;
}

static int run(const struct options *o)
{
    struct sb_pack pack;
    if (sb_pack_open(o->pack, &pack)) {
        sb_error("%s: refused; nothing was rendered", o->pack);
        return EXIT_USAGE;
    }
    if (sb_renderer_check_pack(&pack)) {
        sb_error("%s: refused; nothing was rendered", o->pack);
        sb_pack_close(&pack);
        return EXIT_USAGE;
    }
    struct sb_world world;
    struct sb_renderer_params params = o->params;
    if (o->sheet_step_h > 0.0 && !params.width) {
        params.width = 480;
        params.height = 270;
    }
    bool ffmpeg_found = o->sweep && o->sheet_step_h <= 0.0 && o->encoder != ENCODER_PNG && sb_video_encoder_found();
    if (o->encoder == ENCODER_FFMPEG && !ffmpeg_found) {
        sb_error("--encoder ffmpeg: no ffmpeg on PATH (apt-get install ffmpeg); --encoder png writes numbered PNGs");
        sb_pack_close(&pack);
        return EXIT_USAGE;
    }
    struct sb_lut3d grade = {0};
    if (o->grade && sb_lut3d_load(o->grade, &grade)) {
        sb_error("%s: refused; nothing was rendered", o->grade);
        sb_pack_close(&pack);
        return EXIT_USAGE;
    }
    params.grade = o->grade ? &grade : NULL;
    if (load_world(o, &pack, &world, &params)) {
        sb_lut3d_finish(&grade);
        sb_pack_close(&pack);
        return EXIT_USAGE;
    }
    /* A newcomer's own model is in the first frame: a default camera that
     * cannot see the world, or stands inside a model, is moved to frame it. */
    struct options framed;
    if (!o->camera_given) {
        framed = *o;
        struct sb_view *v = &framed.view;
        double aspect = (double)(params.width ? params.width : 1280) / (params.height ? params.height : 720);
        double surface;
        if (sb_world_lift(&world, 1.7, v->camera_m, &surface)) {
            sb_info("the default camera is under the world's surface (at %.4g m there): lifted onto it, as --camera "
                    "%.4g,%.4g,%.4g,%.4g,%.4g,%.4g",
                    surface, v->camera_m[0], v->camera_m[1], v->camera_m[2], v->yaw / DEG, v->pitch / DEG,
                    (v->fov_y > 0 ? v->fov_y : 50.0 * DEG) / DEG);
            o = &framed;
        }
        if (sb_world_frame(&world, aspect, v->fov_y > 0 ? v->fov_y : 50.0 * DEG, v->camera_m, &v->yaw, &v->pitch)) {
            sb_info("the default camera does not show the world (out of its view, or inside a model): framing it, as "
                    "--camera %.4g,%.4g,%.4g,%.4g,%.4g,%.4g",
                    v->camera_m[0], v->camera_m[1], v->camera_m[2], v->yaw / DEG, v->pitch / DEG,
                    (v->fov_y > 0 ? v->fov_y : 50.0 * DEG) / DEG);
            o = &framed;
        }
    }
    if (mkdir(o->out_dir, 0777) != 0 && errno != EEXIST) {
        sb_error("%s: cannot create the output directory: %s", o->out_dir, strerror(errno));
        sb_lut3d_finish(&grade);
        sb_world_finish(&world);
        sb_pack_close(&pack);
        return EXIT_RENDER_FAILED;
    }

    int code = 0;
    struct sb_vk *vk = NULL;
    struct sb_renderer *r = NULL;
    struct bench_frame *timings = NULL;
    struct sb_video *video = NULL;
    struct sb_vk_params vk_params = o->vk;
    struct sb_window *window = NULL;
    bool window_system = false;
    char video_path[4200];
    snprintf(video_path, sizeof(video_path), "%s/day.mp4", o->out_dir);
    enum sb_result res = SB_OK;
    /* ffmpeg starts before Vulkan does, so it forks a process without the driver's threads. */
    if (ffmpeg_found && (res = sb_video_create(video_path, params.width ? params.width : 1280,
                                               params.height ? params.height : 720, o->fps, &video))) {
        code = EXIT_RENDER_FAILED;
        goto done;
    }
    if (o->sweep && o->sheet_step_h <= 0.0 && !ffmpeg_found && o->encoder == ENCODER_AUTO)
        sb_info("no ffmpeg on PATH: the sweep's frames go to numbered PNGs");
    if (o->window) {
        if ((res = sb_window_system_init(&vk_params))) {
            code = res == SB_ERR_USAGE ? EXIT_USAGE : EXIT_NO_DEVICE;
            goto done;
        }
        window_system = true;
    }
    res = sb_vk_create(&vk_params, &vk);
    if (res) {
        code = res == SB_ERR_NO_DEVICE ? EXIT_NO_DEVICE : EXIT_RENDER_FAILED;
        goto done;
    }
    sb_info("skyview %s: %s on %s (%s)", SKYBAKE_VERSION, o->pack, vk->properties.deviceName, vk->driver_name);
    res = sb_renderer_create(vk, &pack, &world, &params, &r);
    if (res) {
        code = res == SB_ERR_USAGE || res == SB_ERR_VERSION ? EXIT_USAGE : EXIT_RENDER_FAILED;
        goto done;
    }
    if (o->window) {
        uint32_t w, h;
        sb_renderer_size(r, &w, &h);
        char title[256];
        snprintf(title, sizeof(title), "skyview: %s", o->pack);
        struct sb_viewer_params vp = {
            .view = o->view,
            .sun_path = o->time_of_day ? &o->sun_path : NULL,
            .hour = o->day_from,
            .moon = !o->no_moon,
            .frames = o->frames > 0 ? o->frames : 0,
            .screenshot = o->screenshot,
            .out_dir = o->out_dir,
            .overlay = !o->no_overlay,
        };
        if (o->time_of_day)
            sb_view_at_hour(&vp.view, &o->sun_path, o->day_from, !o->no_moon);
        res = sb_window_create(vk, w, h, title, &window);
        if (!res)
            res = sb_viewer_run(r, window, &vp);
        if (res)
            code = res == SB_ERR_NO_DEVICE ? EXIT_NO_DEVICE : EXIT_RENDER_FAILED;
        goto done;
    }
    if (o->sheet_step_h > 0.0 || o->sweep) {
        res = o->sweep && o->sheet_step_h <= 0.0 ? render_day(o, r, video) : render_contact_sheet(o, r);
        if (!res && video)
            res = sb_video_destroy(&video, true);
        if (res)
            code = EXIT_RENDER_FAILED;
        else if (o->sheet_step_h <= 0.0)
            sb_info("wrote %d frames from %g to %g h to %s", o->frames, o->day_from, o->day_to,
                    ffmpeg_found ? video_path : o->out_dir);
        goto done;
    }
    int total = o->frames + (o->bench ? o->warmup : 0);
    timings = calloc((size_t)o->frames, sizeof(*timings));
    if (!timings) {
        code = EXIT_RENDER_FAILED;
        goto done;
    }
    sb_progress("frames", 0, (unsigned)total);
    for (int i = 0; i < total && !res; i++) {
        struct sb_view view = o->view;
        if (o->time_of_day)
            sb_view_at_hour(&view, &o->sun_path, o->day_from, !o->no_moon);
        view.snap_exposure = i == 0;
        view.dt_s = 1.0 / 60.0;
        view.time_s = i * view.dt_s;
        int measured = o->bench ? i - o->warmup : i;
        bool write = !o->bench || i == total - 1;
        /* The GPU's clocks up, as skybake bench keeps them (sb_warm_up). */
        if (o->bench)
            res = sb_warm_up(vk, i == 0 || measured == 0 ? SB_WARM_UP_MS : SB_KEEP_WARM_MS);
        /* Measured, each frame twice: its passes alone, then as rendered. */
        struct bench_frame *f = o->bench && measured >= 0 ? &timings[measured] : NULL;
        view.isolate_passes = f != NULL;
        if (!res && f)
            res = sb_renderer_render(r, &view, false, &f->alone);
        view.isolate_passes = false;
        double start = sb_now_s();
        if (!res)
            res = sb_renderer_render(r, &view, write, f ? &f->rendered : NULL);
        if (f)
            f->wall_ms = (sb_now_s() - start) * 1e3;
        if (!res && write)
            res = write_frame(o, r, o->bench ? 0 : i, NULL);
        sb_progress("frames", (unsigned)i + 1, (unsigned)total);
    }
    if (!res && o->bench) {
        uint32_t w, h;
        sb_renderer_size(r, &w, &h);
        if (!timings[0].alone.valid)
            sb_warn("%s has no timestamps on its queue: the bench measures nothing", vk->properties.deviceName);
        res = report_bench(o, vk, w, h, timings, o->frames);
    }
    if (res)
        code = EXIT_RENDER_FAILED;
    else
        sb_info("wrote %d frame(s) to %s", o->bench ? 1 : o->frames, o->out_dir);

done:
    sb_video_destroy(&video, false);
    sb_window_destroy(&window);
    sb_renderer_destroy(&r);
    unsigned messages = vk ? sb_vk_validation_messages(vk) : 0;
    sb_vk_destroy(&vk);
    if (window_system)
        sb_window_system_finish();
    free(timings);
    sb_world_finish(&world);
    sb_lut3d_finish(&grade);
    sb_pack_close(&pack);
    if (!code && messages) {
        sb_error("%u validation message(s)", messages);
        code = EXIT_VALIDATION;
    }
    return code;
}

int main(int argc, char **argv)
{
    sb_log_set_program("skyview");
    if (argc < 2) {
        usage(stderr);
        return EXIT_USAGE;
    }
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        usage(stdout);
        return 0;
    }
    if (!strcmp(argv[1], "--version")) {
        printf("skyview %s (pack format %d)\n", SKYBAKE_VERSION, SB_PACK_FORMAT_VERSION);
        return 0;
    }
    struct options o;
    int code = parse_options(argc - 1, argv + 1, &o);
    return code ? code : run(&o);
}
