/*
 * skybake: bake the lighting data a scene needs into a versioned pack.
 *
 * Exit codes: 0 success; 1 the bake failed or the pack did not verify; 2 bad
 * command line, bad scene or a pack that cannot be read; 3 no Vulkan device;
 * 4 validation layers reported messages. diff has its own (see usage()).
 */
#include <cJSON.h>
#include <math.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake.h"
#include "bench.h"
#include "context.h"
#include "json.h"
#include "log.h"
#include "pack_tools.h"
#include "parallel.h"
#include "scene.h"
#include "sky_error.h"
#include "skybake_version.h"

enum {
    EXIT_BAKE_FAILED = 1,
    EXIT_USAGE = 2,
    EXIT_NO_DEVICE = 3,
    EXIT_VALIDATION = 4,
    EXIT_DIFF_WITHIN = 1, /* diff: every difference within --tol */
    EXIT_DIFF_DIFFERENT = 5,
    EXIT_DIFF_MISSING = 6,
};

static void usage(FILE *f)
{
    fprintf(f, "usage: skybake bake SCENE -o OUT_DIR [options]\n"
               "       skybake bench [SCENE] [--product NAME]... [--json] [-o DIR] [--repeat N] [--quick]\n"
               "       skybake sky-error [SCENE]... [--paths N] [--spectral-paths N] [--orders] [--orders-grid R,MU,MUS,NU]\n"
               "                 [--seed N] [--sun DEG]... [--json]\n"
               "       skybake info PACK [--json]\n"
               "       skybake verify PACK [--json]\n"
               "       skybake diff A B [--tol REL] [--floor F] [--json]\n"
               "       skybake preview PACK OUT.png [--probes]\n"
               "       skybake --version | --help\n"
               "\n"
               "Bakes what SCENE (JSON, see docs/scene.md) needs into the pack OUT_DIR:\n"
               "manifest.json plus one file per product: EXR for 2D data, OpenVDB for the\n"
               "cloud volumes (baked when the scene lists them, as earth-clouds.json does),\n"
               "probe files for the sky-visibility probes, their bounce and the sun's\n"
               "(sun_bounce, a table over the sun's direction) over the scene's world (a mesh\n"
               "assimp reads, or a skybake world file: ifc-house.json, outdoor.json), and\n"
               "the reflections when listed: the DFG LUT (EXR), the\n"
               "reflection probes' prefiltered cubes (tiled mip-mapped cube EXRs), their\n"
               "records with irradiance SH, and what relights the cubes for any sun\n"
               "(reflection_surfaces; reflections.json; docs/reflections.md).\n"
               "The pack is replaced atomically;\n"
               "a failed bake leaves the previous pack as it was. Baking into a pack\n"
               "reuses every artifact whose bake key (its parameters, settings, kernels\n"
               "and inputs' keys) is unchanged, when that pack verifies and was baked on\n"
               "the same device.\n"
               "\n"
               "options:\n"
               "  -o, --output DIR    the pack to write (required)\n"
               "  --force             bake every product, reusing nothing\n"
               "  --tile X,Z          bake this tile of the probes alone (repeatable; probes.tile_m):\n"
               "                      the pack's other tiles are kept where their keys held, else left\n"
               "                      unbaked (invalid) for another bake into the same pack\n"
               "  --from PACK         also keep the probes' tiles PACK baked under the same keys\n"
               "                      (repeatable, after the pack at -o; this device's): a farm's merge\n"
               "  --device NAME|INDEX Vulkan device by index or name substring\n"
               "                      (default: first discrete GPU, else the first device)\n"
               "  --threads N         CPU threads for the BVH build and the CPU steps\n"
               "                      (default: every core, at most 64); the pack's bytes\n"
               "                      do not depend on it\n"
               "  --validate          enable Vulkan validation; any message fails the bake\n"
               "                      (also SKYBAKE_VALIDATE=1)\n"
               "  --json              print a machine-readable summary on stdout\n"
               "  -q, --quiet         no per-product lines on stderr\n"
               "  -v, --verbose       debug messages\n"
               "\n"
               "bench: speed against error for each product's settings, on the device,\n"
               "against the fp64 reference (docs/accuracy.md). Products: transmittance,\n"
               "transmittance_resolution, multiscattering, irradiance_ground, irradiance_sky,\n"
               "with the published methods as anchor rows (Hillaire 2020's and Bruneton 2017's\n"
               "transmittance, Hillaire 2020's multiple-scattering LUT, Bruneton 2017's ground\n"
               "irradiance);\n"
               "and the cloud noise (cloud_shape, cloud_detail, cloud_curl, weather, at the\n"
               "SCENE's sizes), timed against its CPU reference on one core; and\n"
               "sky_visibility: 4096 probes' rays per second on the device against Embree's\n"
               "on every core, over the IFC house and a terrain of a million triangles,\n"
               "and sky_bounce's GPU time at the same probes (rays / 8 x rays / 32; 64 x 8 with --quick);\n"
               "reflection (or reflection_cubes): the prefilter's GPU time against its error per\n"
               "mip for sample counts and Karis's and Filament's settings, on a 256^2 cube (64^2\n"
               "with --quick, --face N to choose) captured above the terrain\n"
               "(default: all). -o DIR writes bench.csv, bench.json, bench.svg (gnuplot),\n"
               "bench_clouds.csv, bench_probes.csv, bench_reflection.csv.\n"
               "--repeat N bakes each setting N times (default 3) and reports the median;\n"
               "on a GPU each setting is timed after 200 ms of warm-up, so that its clocks\n"
               "are up (docs/accuracy.md, \"GPU clocks\");\n"
               "--quick runs a short sweep (the meson benchmark).\n"
               "\n"
               "sky-error: the sky as the runtime computes it from a default bake, against\n"
               "an fp64 path tracer with every scattering order, per sun elevation (default\n"
               "90 30 10 2 -4, or each --sun DEG) over 16 view directions from the scene's\n"
               "camera altitude (docs/accuracy.md): its radiance error, and its colour's as\n"
               "CIEDE2000 against the same path tracer and against the path tracer at 48\n"
               "wavelengths, 360 to 830 nm, through the CIE 1931 observer; also the sky\n"
               "with the orders product, as its channels and at the spectral products' 12\n"
               "wavelengths (what skyview draws from a pack naming spectral_orders). Any\n"
               "number of scenes. --paths N per direction and channel (default 16384);\n"
               "--spectral-paths N per direction and wavelength (default N / 16); --seed N\n"
               "(default 1). --orders: also the sky with multiple scattering by orders,\n"
               "from its fp64 reference (2 to 3 minutes a scene on 2 cores), --orders-grid\n"
               "R,MU,MUS,NU on a grid of its nodes (default 16,64,24,8).\n"
               "\n"
               "info: what PACK holds (products, sizes, settings and errors, hashes, device,\n"
               "version), after verifying all of it; exit 2 if it is not a valid pack.\n"
               "\n"
               "verify: re-read every artifact, recompute its file and content hashes and\n"
               "check the manifest against the files (names, dimensions, channels, types,\n"
               "no file unlisted); names every problem found. Exit 0 when all holds, else 1.\n"
               "\n"
               "diff: per artifact of packs A and B (both verified first): identical,\n"
               "within tolerance, different, or missing from one, with the largest\n"
               "absolute and relative differences and where. Relative difference:\n"
               "|a - b| / max(|a|, |b|, F x the channel's largest value), F = --floor\n"
               "(default 1e-3); --tol REL (default 0). Exit 0 identical, 1 within\n"
               "tolerance, 5 different, 6 an artifact missing from one pack (the worst\n"
               "artifact decides), 2 usage or a pack that does not verify.\n"
               "\n"
               "preview: a contact sheet of PACK's reflection cubes as a PNG: a block a\n"
               "cube, a row a mip (sharp to rough), the six faces as stored (+x -x +y -y\n"
               "+z -z), one exposure for the sheet. With --probes, or for a pack with\n"
               "sky_visibility and no cubes, the probe layout from above (north, -z, up):\n"
               "grid probes white, detail probes amber over their brick columns (blue),\n"
               "explicit ones green, each as bright as the sky it sees, invalid ones red.\n"
               "Exit 2 if the pack has neither.\n"
               "\n"
               "environment: SKYBAKE_VALIDATE=1 as --validate; SKYBAKE_PIPELINE_STATS=1 logs\n"
               "each compute kernel's registers and memory as the driver reports them (on\n"
               "NVIDIA; not with -q).\n"
               "\n"
               "exit codes: 0 ok, 1 bake failed, 2 usage or scene error, 3 no Vulkan device,\n"
               "            4 validation messages\n");
}

static void print_json(const char *out_dir, const struct sb_vk *vk, const struct sb_bake_report *report)
{
    cJSON *root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "pack", out_dir);
    cJSON_AddStringToObject(root, "device", vk->properties.deviceName);
    cJSON *arr = cJSON_AddArrayToObject(root, "artifacts");
    for (int i = 0; i < report->artifact_count; i++) {
        const struct sb_artifact *a = &report->artifacts[i];
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", sb_product_name(a->product));
        cJSON_AddStringToObject(o, "file", a->file);
        cJSON_AddNumberToObject(o, "width", report->shapes[i][0]);
        cJSON_AddNumberToObject(o, "height", report->shapes[i][1]);
        cJSON_AddNumberToObject(o, "depth", report->shapes[i][2]);
        cJSON_AddNumberToObject(o, "channels", report->shapes[i][3]);
        cJSON_AddNumberToObject(o, "gpu_ms", a->gpu_ms);
        cJSON_AddNumberToObject(o, "bake_ms", a->bake_ms);
        cJSON_AddStringToObject(o, "content_hash", a->content_hash);
        cJSON_AddStringToObject(o, "key", a->key);
        cJSON_AddBoolToObject(o, "reused", report->reused[i]);
        cJSON_AddItemToArray(arr, o);
    }
    /* asked for, but left out under the scene's tolerance (the orders where Hillaire's LUT is within it) */
    cJSON *declined = cJSON_AddArrayToObject(root, "declined");
    for (int p = 0; p < SB_PRODUCT_COUNT; p++)
        if (report->declined >> p & 1)
            cJSON_AddItemToArray(declined, cJSON_CreateString(sb_product_name((enum sb_product_id)p)));
    sb_json_emit(stdout, root);
}

/* The options the commands share: 1 when argv[*i] was one (and its value
 * taken), 0 when it is not, -1 when its value is refused (said why). */
static int common_option(int argc, char **argv, int *i, struct sb_vk_params *vk_params, bool *json)
{
    const char *a = argv[*i];
    if (!strcmp(a, "--device") && *i + 1 < argc)
        vk_params->device = argv[++*i];
    else if (!strcmp(a, "--validate"))
        vk_params->validate = true;
    else if (!strcmp(a, "--json"))
        *json = true;
    else if (!strcmp(a, "--threads") && *i + 1 < argc) {
        char *end;
        long n = strtol(argv[++*i], &end, 10);
        if (*end || end == argv[*i] || n < 1 || n > SB_PARALLEL_MAX_THREADS) {
            fprintf(stderr, "skybake: --threads: '%s' is not a count from 1 to %d\n", argv[*i],
                    SB_PARALLEL_MAX_THREADS);
            return -1;
        }
        sb_parallel_set_threads((int)n);
    } else if (!strcmp(a, "-q") || !strcmp(a, "--quiet"))
        sb_log_set_level(SB_LOG_WARN);
    else if (!strcmp(a, "-v") || !strcmp(a, "--verbose"))
        sb_log_set_level(SB_LOG_DEBUG);
    else
        return 0;
    return 1;
}

static int cmd_bake(int argc, char **argv)
{
    const char *scene_path = NULL, *out_dir = NULL;
    struct sb_bake_options options = {0};
    int32_t tiles[SB_PROBES_MAX_ONLY_TILES][2];
    int tile_count = 0;
    struct sb_vk_params params = sb_vk_params_from_env();
    bool json = false;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        int common = common_option(argc, argv, &i, &params, &json);
        if (common < 0)
            return EXIT_USAGE;
        if (common)
            continue;
        if ((!strcmp(a, "-o") || !strcmp(a, "--output")) && i + 1 < argc)
            out_dir = argv[++i];
        else if (!strcmp(a, "--force"))
            options.force = true;
        else if (!strcmp(a, "--from") && i + 1 < argc) {
            if (options.from_count == SB_BAKE_MAX_FROM) {
                fprintf(stderr, "skybake: --from: at most %d packs\n", SB_BAKE_MAX_FROM);
                return EXIT_USAGE;
            }
            options.from[options.from_count++] = argv[++i];
        } else if (!strcmp(a, "--tile") && i + 1 < argc) {
            long x, z;
            char end;
            if (tile_count == SB_PROBES_MAX_ONLY_TILES || sscanf(argv[++i], "%ld,%ld%c", &x, &z, &end) != 2 ||
                labs(x) > 1000000 || labs(z) > 1000000) {
                fprintf(stderr, "skybake: --tile takes X,Z (a tile's integer coordinates, probes.tile_m apart from 0), "
                                "at most %d times\n", SB_PROBES_MAX_ONLY_TILES);
                return EXIT_USAGE;
            }
            tiles[tile_count][0] = (int32_t)x;
            tiles[tile_count++][1] = (int32_t)z;
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "skybake: unknown or incomplete option '%s'\n", a);
            usage(stderr);
            return EXIT_USAGE;
        } else if (!scene_path)
            scene_path = a;
        else {
            fprintf(stderr, "skybake: unexpected argument '%s'\n", a);
            return EXIT_USAGE;
        }
    }
    if (options.force && options.from_count) {
        fprintf(stderr, "skybake: --force reuses nothing: it and --from do not go together\n");
        return EXIT_USAGE;
    }
    if (!scene_path || !out_dir) {
        fprintf(stderr, "skybake: bake needs a SCENE and -o OUT_DIR\n");
        usage(stderr);
        return EXIT_USAGE;
    }

    struct sb_scene scene;
    if (sb_scene_load(scene_path, &scene))
        return EXIT_USAGE;
    if (tile_count && !(scene.probes.tile_m > 0 && (scene.wants[SB_PRODUCT_SKY_VISIBILITY] ||
                                                      scene.wants[SB_PRODUCT_SKY_BOUNCE] ||
                                                      scene.wants[SB_PRODUCT_SUN_BOUNCE]))) {
        fprintf(stderr, "skybake: --tile: %s bakes no probes in tiles (probes.tile_m)\n", scene_path);
        return EXIT_USAGE;
    }
    scene.probes.only_tile_count = tile_count;
    memcpy(scene.probes.only_tiles, tiles, sizeof(tiles[0]) * (size_t)tile_count);

    struct sb_vk *vk = NULL;
    enum sb_result res = sb_vk_create(&params, &vk);
    if (res)
        return res == SB_ERR_NO_DEVICE ? EXIT_NO_DEVICE : EXIT_BAKE_FAILED;
    sb_info("skybake %s: baking %s on %s (%s)", SKYBAKE_VERSION, scene_path, vk->properties.deviceName,
            vk->driver_name);

    struct sb_bake_report report;
    res = sb_bake_scene(vk, &scene, out_dir, &options, &report);
    unsigned messages = sb_vk_validation_messages(vk);
    if (!res && json)
        print_json(out_dir, vk, &report);
    sb_vk_destroy(&vk);
    if (res) {
        sb_error("bake failed (%s); %s was left as it was", sb_result_name(res), out_dir);
        return res == SB_ERR_TOLERANCE ? EXIT_USAGE : EXIT_BAKE_FAILED;
    }
    if (messages) {
        sb_error("%u validation message(s) during the bake", messages);
        return EXIT_VALIDATION;
    }
    sb_info("wrote %s (%d artifacts)", out_dir, report.artifact_count);
    return 0;
}

static int cmd_bench(int argc, char **argv)
{
    const char *scene_path = NULL, *out_dir = NULL;
    struct sb_vk_params vk_params = sb_vk_params_from_env();
    struct sb_bench_params params = {.repeat = 3};
    bool json = false, any = false;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        enum sb_bench_sweep sweep;
        int common = common_option(argc, argv, &i, &vk_params, &json);
        if (common < 0)
            return EXIT_USAGE;
        if (common)
            continue;
        if ((!strcmp(a, "-o") || !strcmp(a, "--output")) && i + 1 < argc) {
            out_dir = argv[++i];
        } else if (!strcmp(a, "--product") && i + 1 < argc) {
            enum sb_product_id id;
            bool known = sb_product_from_name(argv[++i], &id);
            if (known && sb_product_format(id)->family == SB_FAMILY_CLOUDS) {
                params.clouds[id] = any = true;
                continue;
            }
            if (known && id == SB_PRODUCT_SKY_VISIBILITY) {
                params.probes = any = true;
                continue;
            }
            if (!strcmp(argv[i], "reflection") || (known && id == SB_PRODUCT_REFLECTION_CUBES)) {
                params.reflection = any = true;
                continue;
            }
            if (!sb_bench_sweep_from_name(argv[i], &sweep)) {
                fprintf(stderr, "skybake: bench: unknown product '%s'\n", argv[i]);
                return EXIT_USAGE;
            }
            params.sweeps[sweep] = any = true;
        } else if (!strcmp(a, "--repeat") && i + 1 < argc) {
            char *end;
            long n = strtol(argv[++i], &end, 10);
            if (*end || n < 1 || n > 1000) {
                fprintf(stderr, "skybake: bench: --repeat takes 1 to 1000\n");
                return EXIT_USAGE;
            }
            params.repeat = (int)n;
        } else if (!strcmp(a, "--quick")) {
            params.quick = true;
        } else if (!strcmp(a, "--face") && i + 1 < argc) {
            char *end;
            long n = strtol(argv[++i], &end, 10);
            if (*end || n < 16 || n > 1024 || (n & (n - 1))) {
                fprintf(stderr, "skybake: bench: --face takes a power of two in [16, 1024]\n");
                return EXIT_USAGE;
            }
            params.reflection_face = (uint32_t)n;
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "skybake: unknown or incomplete option '%s'\n", a);
            usage(stderr);
            return EXIT_USAGE;
        } else if (!scene_path) {
            scene_path = a;
        } else {
            fprintf(stderr, "skybake: unexpected argument '%s'\n", a);
            return EXIT_USAGE;
        }
    }
    if (!any) {
        for (int w = 0; w < SB_BENCH_SWEEP_COUNT; w++)
            params.sweeps[w] = true;
        for (int p = 0; p < SB_PRODUCT_COUNT; p++)
            params.clouds[p] = sb_product_format((enum sb_product_id)p)->family == SB_FAMILY_CLOUDS;
        params.probes = true;
        params.reflection = true;
    }
    struct sb_scene scene = {0};
    if (scene_path && sb_scene_load(scene_path, &scene))
        return EXIT_USAGE;
    if (!scene_path) {
        sb_atmosphere_preset_earth(&scene.atmosphere);
        sb_cloud_params_default(&scene.clouds);
    }
    params.cloud_params = scene.clouds;

    struct sb_vk *vk = NULL;
    enum sb_result res = sb_vk_create(&vk_params, &vk);
    if (res)
        return res == SB_ERR_NO_DEVICE ? EXIT_NO_DEVICE : EXIT_BAKE_FAILED;
    sb_info("skybake %s: bench of %s on %s (%s)", SKYBAKE_VERSION, scene_path ? scene_path : "the earth preset",
            vk->properties.deviceName, vk->driver_name);
    struct sb_bench_report report;
    res = sb_bench_run(vk, &scene.atmosphere, &params, &report);
    if (!res) {
        sb_bench_print(&report, vk, json);
        if (out_dir)
            res = sb_bench_write(&report, vk, out_dir);
    }
    unsigned messages = sb_vk_validation_messages(vk);
    sb_bench_report_finish(&report);
    sb_vk_destroy(&vk);
    if (res)
        return EXIT_BAKE_FAILED;
    if (messages) {
        sb_error("%u validation message(s) during the bench", messages);
        return EXIT_VALIDATION;
    }
    return 0;
}

static bool parse_number(const char *text, double lo, double hi, double *out)
{
    char *end;
    double v = strtod(text, &end);
    if (end == text || *end || !(v >= lo && v <= hi))
        return false;
    *out = v;
    return true;
}

static int cmd_sky_error(int argc, char **argv)
{
    /* the scenes' paths, gathered at the front of argv (each at or before
     * its own slot): any number of them */
    int scene_count = 0;
    struct sb_vk_params vk_params = sb_vk_params_from_env();
    struct sb_sky_error_params params = {.seed = 1};
    bool json = false;
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        double v;
        int common = common_option(argc, argv, &i, &vk_params, &json);
        if (common < 0)
            return EXIT_USAGE;
        if (common)
            continue;
        if (!strcmp(a, "--paths") && i + 1 < argc) {
            if (!parse_number(argv[++i], 32, 1e8, &v) || v != floor(v)) {
                fprintf(stderr, "skybake: sky-error: --paths takes an integer from 32 to 1e8\n");
                return EXIT_USAGE;
            }
            params.paths = (int)v;
        } else if (!strcmp(a, "--spectral-paths") && i + 1 < argc) {
            if (!parse_number(argv[++i], 32, 1e8, &v) || v != floor(v)) {
                fprintf(stderr, "skybake: sky-error: --spectral-paths takes an integer from 32 to 1e8\n");
                return EXIT_USAGE;
            }
            params.spectral_paths = (int)v;
        } else if (!strcmp(a, "--orders")) {
            params.orders = true;
        } else if (!strcmp(a, "--orders-grid") && i + 1 < argc) {
            struct sb_orders_settings *g = &params.orders_grid;
            char tail;
            if (sscanf(argv[++i], "%d,%d,%d,%d%c", &g->r, &g->mu, &g->mu_s, &g->nu, &tail) != 4 || g->r < 2 ||
                g->r > 64 || g->mu < 4 || g->mu > 1024 || g->mu % 2 || g->mu_s < 4 || g->mu_s > 256 || g->nu < 2 ||
                g->nu > 64) {
                fprintf(stderr, "skybake: sky-error: --orders-grid takes R,MU,MUS,NU: nodes in altitude (2 to 64), view "
                                "cosine (even, 4 to 1024), sun cosine (4 to 256) and azimuth (2 to 64)\n");
                return EXIT_USAGE;
            }
            params.orders = true;
        } else if (!strcmp(a, "--seed") && i + 1 < argc) {
            if (!parse_number(argv[++i], 0, 9007199254740992.0, &v) || v != floor(v)) {
                fprintf(stderr, "skybake: sky-error: --seed takes an integer from 0 to 2^53\n");
                return EXIT_USAGE;
            }
            params.seed = (uint64_t)v;
        } else if (!strcmp(a, "--sun") && i + 1 < argc) {
            if (!parse_number(argv[++i], -90, 90, &v) || params.sun_count == SB_SKY_ERROR_MAX_SUNS) {
                fprintf(stderr, "skybake: sky-error: --sun takes an elevation in [-90, 90] degrees, at most %d times\n",
                        SB_SKY_ERROR_MAX_SUNS);
                return EXIT_USAGE;
            }
            params.sun_elevation_deg[params.sun_count++] = v;
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "skybake: unknown or incomplete option '%s'\n", a);
            usage(stderr);
            return EXIT_USAGE;
        } else {
            argv[scene_count++] = argv[i];
        }
    }
    const char *preset = "the earth preset";
    const char *const *scenes = scene_count ? (const char *const *)argv : &preset;
    struct sb_scene *loaded = calloc((size_t)(scene_count ? scene_count : 1), sizeof(*loaded));
    struct sb_sky_error_report *reports = calloc((size_t)(scene_count ? scene_count : 1), sizeof(*reports));
    int rc = EXIT_USAGE;
    if (!loaded || !reports)
        goto done;
    for (int i = 0; i < scene_count; i++)
        if (sb_scene_load(scenes[i], &loaded[i]))
            goto done;
    if (!scene_count) {
        sb_atmosphere_preset_earth(&loaded[0].atmosphere);
        loaded[0].view = (struct sb_scene_view){0.002, 30, 150};
        scene_count = 1;
    }

    struct sb_vk *vk = NULL;
    enum sb_result res = sb_vk_create(&vk_params, &vk);
    if (res) {
        rc = res == SB_ERR_NO_DEVICE ? EXIT_NO_DEVICE : EXIT_BAKE_FAILED;
        goto done;
    }
    for (int i = 0; i < scene_count && !res; i++)
        res = sb_sky_error_run(vk, scenes[i], &loaded[i], &params, &reports[i]);
    unsigned messages = sb_vk_validation_messages(vk);
    sb_vk_destroy(&vk);
    if (res) {
        rc = EXIT_BAKE_FAILED;
        goto done;
    }
    sb_sky_error_print(reports, scene_count, json);
    rc = 0;
    if (messages) {
        sb_error("%u validation message(s) during sky-error", messages);
        rc = EXIT_VALIDATION;
    }
done:
    free(loaded);
    free(reports);
    return rc;
}

/* The arguments of info, verify and diff: `count` packs and --json; diff's
 * --tol and --floor when `tolerance` is not NULL. */
static bool pack_args(int argc, char **argv, const char *command, const char **dirs, int count, bool *json,
                      double *tolerance, double *floor)
{
    int n = 0;
    struct sb_vk_params unused = {0};
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        int common = common_option(argc, argv, &i, &unused, json);
        if (common < 0)
            return false;
        if (common)
            continue;
        if (tolerance && (!strcmp(a, "--tol") || !strcmp(a, "--floor")) && i + 1 < argc) {
            double *out = !strcmp(a, "--tol") ? tolerance : floor;
            if (!parse_number(argv[++i], 0, 1e30, out)) {
                fprintf(stderr, "skybake: %s: %s takes a number >= 0, got '%s'\n", command, a, argv[i]);
                return false;
            }
        } else if (a[0] == '-' && a[1]) {
            fprintf(stderr, "skybake: unknown or incomplete option '%s'\n", a);
            usage(stderr);
            return false;
        } else if (n < count) {
            dirs[n++] = a;
        } else {
            fprintf(stderr, "skybake: unexpected argument '%s'\n", a);
            return false;
        }
    }
    if (n < count) {
        fprintf(stderr, "skybake: %s needs %s\n", command,
                count == 1                 ? "a PACK"
                : !strcmp(command, "diff") ? "two packs, A and B"
                                           : "a PACK and an OUT.png");
        return false;
    }
    return true;
}

static int cmd_info(int argc, char **argv)
{
    const char *dir;
    bool json = false;
    if (!pack_args(argc, argv, "info", &dir, 1, &json, NULL, NULL))
        return EXIT_USAGE;
    struct sb_pack pack;
    enum sb_result res = sb_pack_open(dir, &pack);
    if (res) {
        sb_error("%s: not a valid pack (%s)", dir, sb_result_name(res));
        return EXIT_USAGE;
    }
    sb_pack_info_print(&pack, dir, json);
    sb_pack_close(&pack);
    return 0;
}

static int cmd_verify(int argc, char **argv)
{
    const char *dir;
    bool json = false;
    if (!pack_args(argc, argv, "verify", &dir, 1, &json, NULL, NULL))
        return EXIT_USAGE;
    return sb_pack_verify_print(dir, json) ? EXIT_BAKE_FAILED : 0;
}

static int cmd_preview(int argc, char **argv)
{
    const char *args[2];
    bool json = false, probes = false;
    int kept = 0;
    for (int i = 0; i < argc; i++) /* preview's own option, then the common ones */
        if (!strcmp(argv[i], "--probes"))
            probes = true;
        else
            argv[kept++] = argv[i];
    if (!pack_args(kept, argv, "preview", args, 2, &json, NULL, NULL))
        return EXIT_USAGE;
    struct sb_pack pack;
    enum sb_result res = sb_pack_open(args[0], &pack);
    if (res) {
        sb_error("%s: not a valid pack (%s)", args[0], sb_result_name(res));
        return EXIT_USAGE;
    }
    /* the probe map when asked for, or when the pack has no cubes */
    if (probes || (!pack.present[SB_PRODUCT_REFLECTION_CUBES] && pack.present[SB_PRODUCT_SKY_VISIBILITY]))
        res = sb_pack_probe_map(&pack, args[1]);
    else
        res = sb_pack_contact_sheet(&pack, args[1]);
    sb_pack_close(&pack);
    if (res)
        return res == SB_ERR_USAGE ? EXIT_USAGE : EXIT_BAKE_FAILED;
    if (!json)
        printf("wrote %s\n", args[1]);
    return 0;
}

static int cmd_diff(int argc, char **argv)
{
    const char *dirs[2];
    bool json = false;
    double tolerance = 0, floor = 1e-3;
    if (!pack_args(argc, argv, "diff", dirs, 2, &json, &tolerance, &floor))
        return EXIT_USAGE;
    struct sb_pack *packs = calloc(2, sizeof(*packs));
    struct sb_artifact_diff diffs[SB_PRODUCT_COUNT];
    if (!packs)
        return EXIT_BAKE_FAILED;
    int rc = EXIT_USAGE;
    for (int i = 0; i < 2; i++)
        if (sb_pack_open(dirs[i], &packs[i])) {
            sb_error("%s: not a valid pack; run skybake verify %s for every problem", dirs[i], dirs[i]);
            goto done;
        }
    static const int codes[] = {[SB_DIFF_IDENTICAL] = 0,
                                [SB_DIFF_WITHIN] = EXIT_DIFF_WITHIN,
                                [SB_DIFF_DIFFERENT] = EXIT_DIFF_DIFFERENT,
                                [SB_DIFF_MISSING] = EXIT_DIFF_MISSING};
    enum sb_diff_outcome worst = sb_pack_diff(&packs[0], &packs[1], tolerance, floor, diffs);
    sb_pack_diff_print(&packs[0], dirs[0], &packs[1], dirs[1], tolerance, floor, diffs, json);
    rc = codes[worst];
done:
    sb_pack_close(&packs[0]);
    sb_pack_close(&packs[1]);
    free(packs);
    return rc;
}

/* SIGINT, SIGTERM, SIGHUP: remove the pack's temporary files, then end as the signal would. */
static void on_stop_signal(int sig)
{
    sb_pack_writers_remove_temporaries();
    signal(sig, SIG_DFL);
    raise(sig);
}

static void install_signal_handlers(void)
{
    struct sigaction sa = {.sa_handler = on_stop_signal};
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGHUP, &sa, NULL);
    /* A file size limit (ulimit -f) then fails the write with EFBIG, which
     * is reported and cleaned up, instead of killing the process. */
    signal(SIGXFSZ, SIG_IGN);
}

int main(int argc, char **argv)
{
    install_signal_handlers();
    if (argc < 2) {
        usage(stderr);
        return EXIT_USAGE;
    }
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")) {
        usage(stdout);
        return 0;
    }
    if (!strcmp(argv[1], "--version")) {
        printf("skybake %s (pack format %d)\n", SKYBAKE_VERSION, SB_PACK_FORMAT_VERSION);
        return 0;
    }
    if (!strcmp(argv[1], "bake"))
        return cmd_bake(argc - 2, argv + 2);
    if (!strcmp(argv[1], "bench"))
        return cmd_bench(argc - 2, argv + 2);
    if (!strcmp(argv[1], "info"))
        return cmd_info(argc - 2, argv + 2);
    if (!strcmp(argv[1], "verify"))
        return cmd_verify(argc - 2, argv + 2);
    if (!strcmp(argv[1], "diff"))
        return cmd_diff(argc - 2, argv + 2);
    if (!strcmp(argv[1], "preview"))
        return cmd_preview(argc - 2, argv + 2);
    if (!strcmp(argv[1], "sky-error"))
        return cmd_sky_error(argc - 2, argv + 2);
    fprintf(stderr, "skybake: unknown command '%s'\n", argv[1]);
    usage(stderr);
    return EXIT_USAGE;
}
