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

#include "config.h"
#include "context.h"
#include "default_world.h"
#include "exr.h"
#include "log.h"
#include "lut3d.h"
#include "mesh.h"
#include "pack.h"
#include "pngfile.h"
#include "renderer.h"
#include "scene.h"
#include "skybake_version.h"
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
               "       skyview --version | --help\n"
               "\n"
               "Renders the world lit by the atmosphere of PACK (a skybake pack), offscreen,\n"
               "and writes OUT_DIR/frame_0000.png, ... (8-bit sRGB).\n"
               "\n"
               "options:\n"
               "  -o, --output DIR        where the frames go (created if missing)\n"
               "  --size WxH              frame size (default 1280x720)\n"
               "  --frames N              frames to render (default 1; with --bench 30)\n"
               "  --sun-elevation DEG     the sun above the horizon (default 30)\n"
               "  --sun-azimuth DEG       clockwise from north, -z (default 150)\n"
               "  --camera X,Y,Z[,YAW,PITCH[,FOV]]\n"
               "                          metres (y up, origin on the ground) and degrees: yaw\n"
               "                          clockwise from north, pitch above the horizontal,\n"
               "                          vertical field of view (default 0,2,0,0,3,50)\n"
               "  --world FILE            the world: a skybake world file (.json) or a mesh assimp\n"
               "                          reads (default: the world the pack's probes were baked\n"
               "                          against, else the built-in data/worlds/test.json)\n"
               "  --no-probes             light the world with the sky alone, ignoring the pack's\n"
               "                          sky-visibility probes\n"
               "  --no-reflections        the sky model's ambient specular, ignoring the pack's\n"
               "                          reflection probes\n"
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
               "                          (default 128000, the earth's)\n"
               "  --exposure EV           exposure compensation (default 0)\n"
               "  --no-bloom              no bloom\n"
               "  --shadow-size N         texels per side of each of the 4 cascades (default 2048)\n"
               "  --scene auto|raster|traced\n"
               "                          how the world is drawn: rasterised with cascaded shadow\n"
               "                          maps, or one ray a pixel with shadow rays (exact, hard\n"
               "                          shadows); auto: traced on a GPU, rasterised on a CPU\n"
               "                          device (default)\n"
               "  --hdr                   also write the linear HDR frames, frame_0000.exr, ...\n"
               "  --bench                 time the passes: warm-up frames, then --frames frames;\n"
               "                          prints a table and writes OUT_DIR/bench.json\n"
               "  --warmup N              warm-up frames for --bench (default 5)\n"
               "  --device NAME|INDEX     Vulkan device by index or name substring\n"
               "  --validate              enable Vulkan validation; any message fails the run\n"
               "                          (also SKYBAKE_VALIDATE=1)\n"
               "  -q, --quiet             warnings and errors only\n"
               "  -v, --verbose           debug messages\n"
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
    int frames, warmup;
    bool hdr, bench;
};

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
        } else if (!strcmp(a, "--warmup") && next) {
            ok = parse_number(argv[++i], 0, 10000, &v) && v == floor(v);
            o->warmup = (int)v;
        } else if (!strcmp(a, "--sun-elevation") && next) {
            ok = parse_number(argv[++i], -90, 90, &v);
            o->view.sun_elevation = v * DEG;
        } else if (!strcmp(a, "--sun-azimuth") && next) {
            ok = parse_number(argv[++i], -360, 360, &v);
            o->view.sun_azimuth = v * DEG;
        } else if (!strcmp(a, "--camera") && next) {
            ok = parse_doubles(argv[++i], c, 3, 6, &n) && fabs(c[0]) <= 1e7 && fabs(c[2]) <= 1e7 && c[1] > 0.0 &&
                 c[1] <= 1e8;
            if (ok) {
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
        else if (!strcmp(a, "--sun-lux") && next) {
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
        else if (!strcmp(a, "--no-reflections"))
            o->params.no_reflections = true;
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
    if (!o->pack || !o->out_dir) {
        fprintf(stderr, "skyview: needs a PACK and -o OUT_DIR\n");
        usage(stderr);
        return EXIT_USAGE;
    }
    if (o->frames < 0)
        o->frames = o->bench ? 30 : 1;
    return 0;
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

/* The bench table on stdout and the same numbers as JSON in OUT_DIR/bench.json. */
static enum sb_result report_bench(const struct options *o, const struct sb_vk *vk, uint32_t w, uint32_t h,
                                   const struct sb_frame_timings *t, int n)
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
    printf("%-20s %12s %12s %12s\n", "pass", "median ms", "min ms", "max ms");
    for (int p = 0; p <= SB_PASS_COUNT; p++) {
        for (int i = 0; i < n; i++)
            v[i] = p < SB_PASS_COUNT ? t[i].ms[p] : t[i].total_ms;
        double med = median(v, n);
        const char *name = p < SB_PASS_COUNT ? sb_pass_name((enum sb_pass)p) : "total";
        printf("%-20s %12.3f %12.3f %12.3f\n", name, med, v[0], v[n - 1]);
        cJSON *item = cJSON_CreateObject();
        cJSON_AddStringToObject(item, "pass", name);
        cJSON_AddNumberToObject(item, "median_ms", med);
        cJSON_AddNumberToObject(item, "min_ms", v[0]);
        cJSON_AddNumberToObject(item, "max_ms", v[n - 1]);
        cJSON_AddItemToArray(passes, item);
    }
    free(v);
    char path[4200];
    snprintf(path, sizeof(path), "%s/bench.json", o->out_dir);
    char *text = cJSON_Print(root);
    cJSON_Delete(root);
    FILE *f = text ? fopen(path, "w") : NULL;
    enum sb_result res = SB_OK;
    if (!f || fputs(text, f) < 0 || fputc('\n', f) < 0) {
        sb_error("%s: cannot write: %s", path, strerror(errno));
        res = SB_ERR_IO;
    }
    if (f && fclose(f) != 0 && !res) {
        sb_error("%s: cannot write: %s", path, strerror(errno));
        res = SB_ERR_IO;
    }
    free(text);
    return res;
}

static enum sb_result write_frame(const struct options *o, struct sb_renderer *r, int index)
{
    uint32_t w, h;
    sb_renderer_size(r, &w, &h);
    char path[4200];
    snprintf(path, sizeof(path), "%s/frame_%04d.png", o->out_dir, index);
    enum sb_result res = sb_png_write(path, w, h, sb_renderer_ldr(r));
    if (res || !o->hdr)
        return res;
    struct sb_image image = {0};
    if ((res = sb_image_init(&image, w, h, 3)))
        return res;
    sb_image_set_channel_names(&image, "R,G,B");
    sb_renderer_hdr(r, image.data);
    snprintf(path, sizeof(path), "%s/frame_%04d.exr", o->out_dir, index);
    res = sb_exr_write(path, &image, NULL, 0);
    sb_image_finish(&image);
    return res;
}

/* A string member of a JSON object's text; "" when missing. */
static void settings_string(const char *json, const char *key, char *out, size_t size)
{
    out[0] = '\0';
    cJSON *root = cJSON_Parse(json);
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(root, key);
    if (cJSON_IsString(item))
        snprintf(out, size, "%s", item->valuestring);
    cJSON_Delete(root);
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
        settings_string(a->settings_json, "world_hash", hash[i], sizeof(hash[i]));
        if (!baked_path[0])
            settings_string(a->settings_json, "world_path", baked_path, sizeof(baked_path));
    }
    enum sb_result res;
    if (o->world) {
        res = sb_world_load(o->world, NULL, world);
    } else if (baked_path[0]) {
        struct sb_world_params *wp = malloc(sizeof(*wp));
        if (!wp)
            return SB_ERR_NOMEM;
        *wp = pack->scene->world;
        snprintf(wp->file, sizeof(wp->file), "%s", baked_path);
        struct sb_mesh mesh = {0};
        res = sb_mesh_load_world(wp, "", &mesh, NULL, 0);
        if (!res)
            res = sb_world_from_mesh(&mesh, world);
        sb_mesh_finish(&mesh);
        free(wp);
        if (res)
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
    struct sb_world world;
    struct sb_renderer_params params = o->params;
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
    struct sb_frame_timings *timings = NULL;
    enum sb_result res = sb_vk_create(&o->vk, &vk);
    if (res) {
        code = res == SB_ERR_NO_DEVICE ? EXIT_NO_DEVICE : EXIT_RENDER_FAILED;
        goto done;
    }
    sb_info("skyview %s: %s on %s (%s)", SKYBAKE_VERSION, o->pack, vk->properties.deviceName, vk->driver_name);
    res = sb_renderer_create(vk, &pack, &world, &params, &r);
    if (res) {
        code = res == SB_ERR_USAGE ? EXIT_USAGE : EXIT_RENDER_FAILED;
        goto done;
    }
    int total = o->frames + (o->bench ? o->warmup : 0);
    timings = calloc((size_t)o->frames, sizeof(*timings));
    if (!timings) {
        code = EXIT_RENDER_FAILED;
        goto done;
    }
    for (int i = 0; i < total && !res; i++) {
        struct sb_view view = o->view;
        view.snap_exposure = i == 0;
        view.dt_s = 1.0 / 60.0;
        view.time_s = i * view.dt_s;
        int measured = o->bench ? i - o->warmup : i;
        bool write = !o->bench || i == total - 1;
        res = sb_renderer_render(r, &view, write, measured >= 0 ? &timings[measured] : NULL);
        if (!res && write)
            res = write_frame(o, r, o->bench ? 0 : i);
    }
    if (!res && o->bench) {
        uint32_t w, h;
        sb_renderer_size(r, &w, &h);
        if (!timings[0].valid)
            sb_warn("%s has no timestamps on its queue: the bench measures nothing", vk->properties.deviceName);
        res = report_bench(o, vk, w, h, timings, o->frames);
    }
    if (res)
        code = EXIT_RENDER_FAILED;
    else
        sb_info("wrote %d frame(s) to %s", o->bench ? 1 : o->frames, o->out_dir);

done:
    sb_renderer_destroy(&r);
    unsigned messages = vk ? sb_vk_validation_messages(vk) : 0;
    sb_vk_destroy(&vk);
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
