/* formats/: EXR round trips, content hashes, scene parsing and validation,
 * packs written and read back, and packs that must be refused. */
#include <cJSON.h>
#include <fcntl.h>
#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include <xxhash.h>

#include "exr.h"
#include "harness.h"
#include "image.h"
#include "log.h"
#include "lut3d.h"
#include "pack.h"
#include "parallel.h"
#include "probes.h"
#include "sandbox.h"
#include "scene.h"
#include "synthetic_pack.h"
#include "vdb.h"

static void quiet(void *user, enum sb_log_level level, const char *msg)
{
    (void)user;
    (void)level;
    (void)msg;
}

/* How many prefixes of the file at `path` (every length below `fine`, then
 * every `step`th) `read` accepts; the file is left as the longest prefix
 * tried, for the caller to remove. */
static int truncations_accepted(const char *path, long fine, long step, bool (*read)(const char *path))
{
    FILE *f = fopen(path, "rb");
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    rewind(f);
    unsigned char *bytes = malloc(size);
    CHECK(fread(bytes, 1, size, f) == (size_t)size, "read %s back", path);
    fclose(f);
    int accepted = 0;
    for (long cut = 0; cut < size; cut += cut < fine ? 1 : step) {
        f = fopen(path, "wb");
        fwrite(bytes, 1, cut, f);
        fclose(f);
        accepted += read(path);
    }
    free(bytes);
    return accepted;
}

static bool read_rgb(const char *path)
{
    struct sb_image t;
    bool ok = sb_exr_read(path, "r,g,b", 0, &t, NULL, NULL) == SB_OK;
    if (ok)
        sb_image_finish(&t);
    return ok;
}

/* As a pack reads test_exr_cube's file: 3 cubes of 32 a face. */
static bool read_cube(const char *path)
{
    struct sb_image t;
    bool ok = sb_exr_cube_read(path, "R,G,B", 32, 3, &t) == SB_OK;
    if (ok)
        sb_image_finish(&t);
    return ok;
}

static bool read_volume(const char *path)
{
    struct sb_image t;
    bool ok = sb_vdb_read(path, "perlin_worley,worley.0,worley.1,worley.2", 13 * 9 * 20, &t, NULL, NULL) == SB_OK;
    if (ok)
        sb_image_finish(&t);
    return ok;
}

static void test_exr_round_trip(void)
{
    struct sb_image img, back;
    CHECK(sb_image_init(&img, 37, 11, 3) == SB_OK, "init");
    sb_image_set_channel_names(&img, "r,g,b");
    for (uint64_t i = 0; i < sb_image_float_count(&img); i++) /* awkward values: denormals, tiny, huge, negative */
        img.data[i] = (i % 7 == 0) ? 1e-40f : (float)((double)i * 1.2345e-3 - 0.2) * (i % 5 == 0 ? 1e20f : 1.0f);
    char path[] = "/tmp/skybake-test-XXXXXX.exr";
    int fd = mkstemps(path, 4);
    close(fd);
    struct sb_attribute attrs[2] = {{"skybake.product", "transmittance"}, {"skybake.content_hash", "abc"}};
    CHECK(sb_exr_write(path, &img, attrs, 2) == SB_OK, "write");
    struct sb_attribute got[SB_FILE_MAX_ATTRIBUTES];
    int ngot = 0;
    CHECK(sb_exr_read(path, "r,g,b", 0, &back, got, &ngot) == SB_OK, "read");
    CHECK(back.width == 37 && back.height == 11 && back.channel_count == 3, "shape %ux%ux%u", back.width, back.height,
          back.channel_count);
    CHECK(back.data && memcmp(back.data, img.data, sb_image_float_count(&img) * 4) == 0, "data differs");
    CHECK(ngot == 2 && !strcmp(got[0].value, "transmittance"), "attributes: %d", ngot);
    char h1[SB_HASH_HEX_SIZE], h2[SB_HASH_HEX_SIZE];
    sb_image_content_hash(&img, h1);
    sb_image_content_hash(&back, h2);
    CHECK(!strcmp(h1, h2), "hash changed by the round trip");
    /* Channels come back in any requested order. */
    struct sb_image reordered;
    CHECK(sb_exr_read(path, "b,r,g", 0, &reordered, NULL, NULL) == SB_OK, "reorder");
    CHECK(reordered.data && reordered.data[0] == img.data[2] && reordered.data[1] == img.data[0], "order");
    sb_image_finish(&reordered);
    CHECK(sb_exr_read(path, "r,g", 0, &reordered, NULL, NULL) == SB_ERR_BAD_IMAGE, "channel count mismatch");
    CHECK(sb_exr_read(path, NULL, 10, &reordered, NULL, NULL) == SB_ERR_BAD_IMAGE, "size cap");
    /* Every truncated prefix is refused cleanly. */
    int accepted = truncations_accepted(path, 512, 97, read_rgb);
    CHECK(accepted == 0, "%d truncated files were accepted", accepted);
    unlink(path);
    /* The hash sees every value and the shape. */
    img.data[5] = nextafterf(img.data[5], INFINITY);
    sb_image_content_hash(&img, h2);
    CHECK(strcmp(h1, h2) != 0, "one ulp must change the hash");
    sb_image_finish(&img);
    sb_image_finish(&back);
    sb_image_finish(&reordered);
}

/* Cube arrays with their mip chains: bit-exact round trip, the shape
 * exrheader sees, every hostile variant refused before allocation. */
static void test_exr_cube(void)
{
    struct sb_image img, back;
    const uint32_t n = 32, cubes = 3;
    CHECK(sb_cube_levels(32) == 6 && sb_cube_levels(1) == 1 && sb_cube_levels(1024) == 11, "levels");
    CHECK(sb_image_init_levels(&img, n, 6 * n, cubes, 3, sb_cube_levels(n)) == SB_OK, "init");
    sb_image_set_channel_names(&img, "R,G,B");
    CHECK(sb_image_float_count(&img) == (uint64_t)3 * cubes * 6 * (1024 + 256 + 64 + 16 + 4 + 1), "count %llu",
          (unsigned long long)sb_image_float_count(&img));
    for (uint64_t i = 0; i < sb_image_float_count(&img); i++)
        img.data[i] = (float)((double)i * 0.37 - 1e3) * (i % 11 == 0 ? 1e-30f : 1.0f);
    char path[] = "/tmp/skybake-cube-XXXXXX.exr";
    int fd = mkstemps(path, 4);
    close(fd);
    struct sb_attribute attrs[1] = {{"skybake.product", "reflection_cubes"}};
    CHECK(sb_exr_cube_write(path, &img, attrs, 1) == SB_OK, "write");
    CHECK(sb_exr_cube_read(path, "R,G,B", n, cubes, &back) == SB_OK, "read");
    CHECK(back.levels == img.levels && back.depth == cubes && back.height == 6 * n, "shape");
    uint64_t first = 0;
    while (back.data && first < sb_image_float_count(&img) && back.data[first] == img.data[first])
        first++;
    CHECK(back.data && first == sb_image_float_count(&img), "data differs from float %llu (%g, not %g)",
          (unsigned long long)first, back.data ? back.data[first] : 0.0, img.data[first]);
    char h1[SB_HASH_HEX_SIZE], h2[SB_HASH_HEX_SIZE];
    sb_image_content_hash(&img, h1);
    sb_image_content_hash(&back, h2);
    CHECK(!strcmp(h1, h2), "hash changed by the round trip");
    /* A mip-less image of the same top level hashes otherwise. */
    struct sb_image flat = img;
    flat.levels = 1;
    sb_image_content_hash(&flat, h2);
    CHECK(strcmp(h1, h2) != 0, "levels must be hashed");
    sb_image_finish(&back);
    /* What the caller does not expect is refused. */
    CHECK(sb_exr_cube_read(path, "R,G,B", 16, cubes, &back) == SB_ERR_BAD_IMAGE, "other size");
    CHECK(sb_exr_cube_read(path, "R,G,B", n, 2, &back) == SB_ERR_BAD_IMAGE, "other count");
    CHECK(sb_exr_cube_read(path, "R,G", n, cubes, &back) == SB_ERR_BAD_IMAGE, "other channels");
    CHECK(sb_exr_cube_read(path, "R,G,B", 0, cubes, &back) == SB_ERR_BAD_IMAGE, "size 0");
    CHECK(sb_exr_cube_read(path, "R,G,B", 65536, cubes, &back) == SB_ERR_BAD_IMAGE, "size 65536");
    CHECK(sb_exr_cube_read(path, "R,G,B", 24, cubes, &back) == SB_ERR_BAD_IMAGE, "not a power of two");
    /* A scanline EXR is not a cube. */
    struct sb_image plain;
    CHECK(sb_image_init(&plain, n, 6 * n, 3) == SB_OK, "plain");
    sb_image_set_channel_names(&plain, "R,G,B");
    char path2[] = "/tmp/skybake-plain-XXXXXX.exr";
    close(mkstemps(path2, 4));
    CHECK(sb_exr_write(path2, &plain, NULL, 0) == SB_OK, "plain write");
    CHECK(sb_exr_cube_read(path2, "R,G,B", n, 1, &back) == SB_ERR_BAD_IMAGE, "scanline refused");
    unlink(path2);
    sb_image_finish(&plain);
    /* Every truncated prefix is refused cleanly (a byte at a time through
     * the header, then every 331st). */
    int accepted = truncations_accepted(path, 1024, 331, read_cube);
    CHECK(accepted == 0, "%d truncated cube files were accepted", accepted);
    unlink(path);
    sb_image_finish(&img);
}

static bool files_equal(const char *a, const char *b)
{
    char cmd[600];
    snprintf(cmd, sizeof(cmd), "cmp -s '%s' '%s'", a, b);
    return system(cmd) == 0;
}

/* An image's file written at `threads` threads (sb_exr_write_chunks). */
static enum sb_result write_at(int threads, const char *path, const struct sb_image *img, bool cube)
{
    sb_parallel_set_threads(threads);
    enum sb_result res = cube ? sb_exr_cube_write(path, img, NULL, 0) : sb_exr_write(path, img, NULL, 0);
    sb_parallel_set_threads(0);
    return res;
}

/* The writers compress chunks on several threads and write them in order:
 * the same bytes at one thread and at five, and a write that fails half
 * way (a file size limit) fails cleanly, never waiting for ever. */
static void test_exr_threads(void)
{
    struct sb_image img, cube, back;
    CHECK(sb_image_init(&img, 53, 300, 3) == SB_OK, "init"); /* 19 chunks of 16 lines */
    sb_image_set_channel_names(&img, "r,g,b");
    uint64_t x = 0x9e3779b97f4a7c15ull;
    for (uint64_t i = 0; i < sb_image_float_count(&img); i++) { /* random bits: ZIP keeps most chunks large */
        x ^= x << 13, x ^= x >> 7, x ^= x << 17;
        img.data[i] = i % 3 ? (float)(x >> 40) * 0x1p-24f : (float)i;
    }
    CHECK(sb_image_init_levels(&cube, 128, 6 * 128, 2, 3, sb_cube_levels(128)) == SB_OK, "cube init");
    sb_image_set_channel_names(&cube, "R,G,B");
    for (uint64_t i = 0; i < sb_image_float_count(&cube); i++)
        cube.data[i] = (float)(i % 1013) * 0.25f;
    char one[] = "/tmp/skybake-threads-XXXXXX.exr", five[] = "/tmp/skybake-threads-XXXXXX.exr";
    close(mkstemps(one, 4));
    close(mkstemps(five, 4));
    for (int c = 0; c < 2; c++) {
        const struct sb_image *im = c ? &cube : &img;
        CHECK(write_at(1, one, im, c) == SB_OK && write_at(5, five, im, c) == SB_OK, "%s: write",
              c ? "cube" : "scanlines");
        CHECK(files_equal(one, five), "%s: the file at 5 threads differs from the one at 1", c ? "cube" : "scanlines");
        enum sb_result r =
            c ? sb_exr_cube_read(five, "R,G,B", 128, 2, &back) : sb_exr_read(five, "r,g,b", 0, &back, NULL, NULL);
        CHECK(r == SB_OK && memcmp(back.data, im->data, sb_image_float_count(im) * sizeof(float)) == 0,
              "%s: the file at 5 threads reads back", c ? "cube" : "scanlines");
        sb_image_finish(&back);
    }
    /* A file size limit stops the writes half way through the chunks. */
    struct rlimit was;
    getrlimit(RLIMIT_FSIZE, &was);
    void (*handler)(int) = signal(SIGXFSZ, SIG_IGN);
    struct rlimit small = {64 << 10, was.rlim_max};
    CHECK(setrlimit(RLIMIT_FSIZE, &small) == 0, "set a file size limit");
    enum sb_result scan = write_at(5, five, &img, false), cubed = write_at(5, five, &cube, true);
    setrlimit(RLIMIT_FSIZE, &was);
    signal(SIGXFSZ, handler);
    CHECK(scan == SB_ERR_IO && cubed == SB_ERR_IO, "past the limit: %s and %s, not io", sb_result_name(scan),
          sb_result_name(cubed));
    unlink(one);
    unlink(five);
    sb_image_finish(&img);
    sb_image_finish(&cube);
}

struct scene_case {
    const char *json;
    enum sb_result expect;
};

#define EARTH "{\"atmosphere\":{\"preset\":\"earth\"},"

static void test_scenes(void)
{
    static const struct scene_case cases[] = {
        {"{\"atmosphere\":{\"preset\":\"earth\"}}", SB_OK},
        {"{\"atmosphere\":{\"preset\":\"earth\",\"mie_g\":0.5,\"ground_albedo\":[0.1,0.2,0.3]}}", SB_OK},
        {"{\"atmosphere\":{\"preset\":\"earth\"},\"products\":[\"multiscattering\"]}", SB_OK},
        {"", SB_ERR_JSON_SYNTAX},
        {"{", SB_ERR_JSON_SYNTAX},
        {"{\"atmosphere\":{\"preset\":\"earth\"}} x", SB_ERR_JSON_SYNTAX},
        {"[]", SB_ERR_WRONG_TYPE},
        {"{}", SB_ERR_MISSING_FIELD},
        {"{\"atmosphere\":{}}", SB_ERR_MISSING_FIELD},
        {"{\"atmosphere\":{\"preset\":\"venus\"}}", SB_ERR_UNKNOWN_PRESET},
        {"{\"atmosphere\":{\"preset\":\"earth\",\"mie_gg\":0.5}}", SB_ERR_UNKNOWN_KEY},
        {"{\"atmosphere\":{\"preset\":\"earth\"},\"extra\":1}", SB_ERR_UNKNOWN_KEY},
        {"{\"atmosphere\":{\"preset\":\"earth\",\"mie_g\":1.0}}", SB_ERR_OUT_OF_RANGE},
        {"{\"atmosphere\":{\"preset\":\"earth\",\"mie_g\":-1.0}}", SB_ERR_OUT_OF_RANGE},
        {"{\"atmosphere\":{\"preset\":\"earth\",\"mie_g\":\"0.8\"}}", SB_ERR_WRONG_TYPE},
        {"{\"atmosphere\":{\"preset\":\"earth\",\"top_radius_km\":6360}}", SB_ERR_OUT_OF_RANGE},
        {"{\"atmosphere\":{\"preset\":\"earth\",\"top_radius_km\":6000}}", SB_ERR_OUT_OF_RANGE},
        {"{\"atmosphere\":{\"preset\":\"earth\",\"rayleigh_scattering_per_km\":[1,-1,1]}}", SB_ERR_OUT_OF_RANGE},
        {"{\"atmosphere\":{\"preset\":\"earth\",\"rayleigh_scattering_per_km\":[1,1]}}", SB_ERR_WRONG_TYPE},
        {"{\"atmosphere\":{\"preset\":\"earth\",\"mie_scale_height_km\":0}}", SB_ERR_OUT_OF_RANGE},
        {"{\"atmosphere\":{\"preset\":\"earth\",\"ground_albedo\":1.5}}", SB_ERR_OUT_OF_RANGE},
        {"{\"atmosphere\":{\"preset\":\"earth\",\"ground_radius_km\":1e999}}", SB_ERR_OUT_OF_RANGE},
        {"{\"atmosphere\":{\"preset\":\"earth\",\"mie_g\":0.1,\"mie_g\":0.2}}", SB_ERR_DUPLICATE_KEY},
        {"{\"atmosphere\":{\"preset\":\"earth\"},\"products\":[\"clouds\"]}", SB_ERR_UNKNOWN_PRODUCT},
        {"{\"atmosphere\":{\"preset\":\"earth\"},\"products\":[]}", SB_ERR_OUT_OF_RANGE},
        {"{\"atmosphere\":{\"preset\":\"earth\"},\"version\":2}", SB_ERR_OUT_OF_RANGE},
        {"{\"atmosphere\":{\"preset\":\"earth\",\"mie_g\":NaN}}", SB_ERR_JSON_SYNTAX},
        {"{\"atmosphere\":{\"preset\":\"earth\",\"mie_g\":Infinity}}", SB_ERR_JSON_SYNTAX},
        {"{\"atmosphere\":{\"preset\":\"earth\",\"top_radius_km\":1e308}}", SB_ERR_OUT_OF_RANGE},
        {"{\"atmosphere\":{\"preset\":\"earth\",\"mie_scale_height_km\":1e-320}}", SB_ERR_OUT_OF_RANGE},
        {"{\"atmosphere\":\"earth\"}", SB_ERR_WRONG_TYPE},
        {"{\"atmosphere\":{\"preset\":\"earth\",\"ground_albedo\":[0.1,[0.2],0.3]}}", SB_ERR_WRONG_TYPE},
        {"{\"atmosphere\":{\"preset\":\"earth\"},\"products\":[\"transmittance\",\"transmittance\"]}",
         SB_ERR_DUPLICATE_KEY},
        {"\x89PNG\r\n\x1a\n\xff\xfe{[", SB_ERR_JSON_SYNTAX},
        {"{\"atmosphere\":{\"preset\":\"earth}}", SB_ERR_JSON_SYNTAX},
        /* Cloud noise. */
        {"{\"atmosphere\":{\"preset\":\"earth\"},\"products\":[\"cloud_shape\",\"weather\"]}", SB_OK},
        {EARTH "\"clouds\":{\"seed\":4294967295,\"cloud_shape\":{\"size\":96,\"worley_cells\":[3,6,24]},"
               "\"weather\":{\"size\":1024,\"coverage_period\":64,\"coverage_octaves\":5}}}",
         SB_OK},
        {EARTH "\"clouds\":{\"seed\":4294967296}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"clouds\":{\"seed\":-1}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"clouds\":{\"seed\":1.5}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"clouds\":{\"seed\":\"7\"}}", SB_ERR_WRONG_TYPE},
        {EARTH "\"clouds\":[]}", SB_ERR_WRONG_TYPE},
        {EARTH "\"clouds\":{\"cloud_shape\":7}}", SB_ERR_WRONG_TYPE},
        {EARTH "\"clouds\":{\"cloud_shape\":{\"size\":512}}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"clouds\":{\"cloud_shape\":{\"size\":4}}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"clouds\":{\"weather\":{\"size\":2048}}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"clouds\":{\"cloud_shape\":{\"perlin_octaves\":0}}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"clouds\":{\"cloud_shape\":{\"perlin_octaves\":9}}}", SB_ERR_OUT_OF_RANGE},
        /* finer than a texel: 16 cells x 2^3 over 64 texels; 32 cells x 4 over 128 */
        {EARTH "\"clouds\":{\"cloud_shape\":{\"size\":64,\"perlin_period\":16}}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"clouds\":{\"cloud_shape\":{\"worley_cells\":[4,8,33]}}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"clouds\":{\"cloud_detail\":{\"size\":16}}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"clouds\":{\"cloud_shape\":{\"worley_cells\":[4,8]}}}", SB_ERR_WRONG_TYPE},
        {EARTH "\"clouds\":{\"cloud_shape\":{\"worley_cells\":[4,8,0]}}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"clouds\":{\"cloud_shape\":{\"worley_cells\":[4,\"8\",16]}}}", SB_ERR_WRONG_TYPE},
        {EARTH "\"clouds\":{\"cloud_shape\":{\"cells\":[4,8,16]}}}", SB_ERR_UNKNOWN_KEY},
        {EARTH "\"clouds\":{\"size\":128}}", SB_ERR_UNKNOWN_KEY},
        {EARTH "\"clouds\":{\"shape\":{}}}", SB_ERR_UNKNOWN_KEY},
        {EARTH "\"clouds\":{\"weather\":{\"size\":8,\"size\":16}}}", SB_ERR_DUPLICATE_KEY},
        {EARTH "\"clouds\":{\"cloud_curl\":{\"period\":0}}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"tolerance\":{\"cloud_shape\":1e-3}}", SB_ERR_OUT_OF_RANGE},
        /* Reflections. */
        {EARTH "\"products\":[\"reflection_cubes\"]}", SB_OK},
        {EARTH "\"reflections\":{\"face_size\":64,\"samples\":256,\"probes\":[{\"position_m\":[0,1,0],"
               "\"box_m\":[[-5,0,-5],[5,3,5]]}]}}",
         SB_OK},
        {EARTH "\"reflections\":{\"probes\":[]}}", SB_OK},
        {EARTH "\"reflections\":{\"face_size\":0}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"reflections\":{\"face_size\":1}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"reflections\":{\"face_size\":65536}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"reflections\":{\"face_size\":96}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"reflections\":{\"samples\":100}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"reflections\":{\"ambient_rays\":0}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"reflections\":{\"size\":64}}", SB_ERR_UNKNOWN_KEY},
        {EARTH "\"reflections\":{\"probes\":[{\"position_m\":[0,1,0]}]}}", SB_ERR_MISSING_FIELD},
        {EARTH "\"reflections\":{\"probes\":[{\"position_m\":[0,1,0],\"box_m\":[[0,0,0],[0,3,5]]}]}}",
         SB_ERR_OUT_OF_RANGE},
        {EARTH "\"reflections\":{\"probes\":[{\"position_m\":[0,1,0],\"box_m\":[[5,0,5],[-5,3,-5]]}]}}",
         SB_ERR_OUT_OF_RANGE},
        {EARTH "\"reflections\":{\"probes\":[{\"position_m\":[0,9,0],\"box_m\":[[-5,0,-5],[5,3,5]]}]}}",
         SB_ERR_OUT_OF_RANGE},
        {EARTH "\"reflections\":{\"probes\":[{\"position_m\":[0,1,0],\"box_m\":[[-5,0],[5,3,5]]}]}}",
         SB_ERR_WRONG_TYPE},
        {EARTH "\"reflections\":{\"probes\":{}}}", SB_ERR_WRONG_TYPE},
        {EARTH "\"tolerance\":{\"reflection_cubes\":1e-2}}", SB_ERR_OUT_OF_RANGE},
        /* Fog. */
        {EARTH "\"fog\":{}}", SB_OK},
        {EARTH "\"fog\":{\"extinction_per_m\":0.02,\"base_altitude_m\":-5,\"falloff_height_m\":30,"
               "\"albedo\":[0.9,0.8,0.7],\"anisotropy\":-0.3,\"noise\":{\"amount\":1,\"scale_m\":20,"
               "\"wind_m_s\":[1,0,-2]},\"volumes\":[{\"box_m\":[[-5,0,-5],[5,3,5]],\"extinction_per_m\":0.5}]}}",
         SB_OK},
        {EARTH "\"fog\":{\"extinction_per_m\":-0.01}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"fog\":{\"extinction_per_m\":11}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"fog\":{\"extinction_per_m\":NaN}}", SB_ERR_JSON_SYNTAX},
        {EARTH "\"fog\":{\"extinction_per_m\":\"thick\"}}", SB_ERR_WRONG_TYPE},
        {EARTH "\"fog\":{\"falloff_height_m\":0}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"fog\":{\"albedo\":[0.9,1.2,0.9]}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"fog\":{\"anisotropy\":1}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"fog\":{\"noise\":{\"amount\":1.5}}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"fog\":{\"noise\":{\"scale_m\":0}}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"fog\":{\"noise\":{\"speed\":1}}}", SB_ERR_UNKNOWN_KEY},
        {EARTH "\"fog\":{\"density\":1}}", SB_ERR_UNKNOWN_KEY},
        {EARTH "\"fog\":{\"volumes\":[{\"box_m\":[[-5,0,-5],[5,3,5]]}]}}", SB_ERR_MISSING_FIELD},
        {EARTH "\"fog\":{\"volumes\":[{\"box_m\":[[5,0,5],[-5,3,-5]],\"extinction_per_m\":1}]}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"fog\":{\"volumes\":[{\"box_m\":[[-5,0,-5],[5,3,5]],\"extinction_per_m\":-1}]}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"fog\":{\"volumes\":{}}}", SB_ERR_WRONG_TYPE},
        /* The cloud layer. */
        {EARTH "\"cloud_layer\":{}}", SB_OK},
        {EARTH "\"cloud_layer\":{\"base_altitude_m\":800,\"top_altitude_m\":2500,\"coverage\":1,"
               "\"extinction_per_m\":0.1,\"albedo\":[1,1,1],\"weather_scale_m\":2e4,\"shape_scale_m\":5e3,"
               "\"detail_scale_m\":500,\"erosion\":0.5,\"curl_scale_m\":3e3,\"curl_m\":100,"
               "\"wind_m_s\":[5,0,-3],\"phase\":{\"forward_g\":0.85,\"backward_g\":-0.2,\"forward_weight\":0.6},"
               "\"scattering_octaves\":8}}",
         SB_OK},
        {EARTH "\"cloud_layer\":{\"extinction_per_m\":-0.01}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"cloud_layer\":{\"extinction_per_m\":NaN}}", SB_ERR_JSON_SYNTAX},
        {EARTH "\"cloud_layer\":{\"coverage\":1.01}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"cloud_layer\":{\"coverage\":-0.1}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"cloud_layer\":{\"base_altitude_m\":3000,\"top_altitude_m\":2000}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"cloud_layer\":{\"base_altitude_m\":2000,\"top_altitude_m\":2050}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"cloud_layer\":{\"base_altitude_m\":-1}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"cloud_layer\":{\"top_altitude_m\":1e6}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"cloud_layer\":{\"albedo\":[0.9,1.2,0.9]}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"cloud_layer\":{\"weather_scale_m\":0}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"cloud_layer\":{\"erosion\":2}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"cloud_layer\":{\"wind_m_s\":[1,2]}}", SB_ERR_WRONG_TYPE},
        {EARTH "\"cloud_layer\":{\"phase\":{\"forward_g\":1}}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"cloud_layer\":{\"phase\":{\"g\":0.5}}}", SB_ERR_UNKNOWN_KEY},
        {EARTH "\"cloud_layer\":{\"scattering_octaves\":2.5}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"cloud_layer\":{\"scattering_octaves\":0}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"cloud_layer\":{\"density\":1}}", SB_ERR_UNKNOWN_KEY},
        {EARTH "\"cloud_layer\":[]}", SB_ERR_WRONG_TYPE},
        {EARTH "\"view\":{\"sun_azimuth_deg\":400}}", SB_ERR_OUT_OF_RANGE},
        {EARTH "\"view\":{\"sun_azimuth_deg\":40}}", SB_OK},
        /* Text that is not UTF-8 (it would reach the manifest as it is), and
         * an escaped NUL (cJSON would end the string there, silently) */
        {EARTH "\"name\":\"caf\xe9\"}", SB_ERR_JSON_SYNTAX},
        {EARTH "\"name\":\"\xc0\xaf\"}", SB_ERR_JSON_SYNTAX},         /* overlong '/' */
        {EARTH "\"name\":\"\xed\xa0\x80\"}", SB_ERR_JSON_SYNTAX},     /* a surrogate */
        {EARTH "\"name\":\"\xf4\x90\x80\x80\"}", SB_ERR_JSON_SYNTAX}, /* past U+10FFFF */
        {EARTH "\"name\":\"caf\xc3\xa9 \xf0\x9f\x8c\x85\"}", SB_OK},
        {EARTH "\"name\":\"a\\u0000b\"}", SB_ERR_JSON_SYNTAX},
        {EARTH "\"name\":\"a\\\\u0000b\"}", SB_OK}, /* a backslash, then the text u0000 */
        {EARTH "\"name\":\"a\\u00e9\"}", SB_OK},
    };
    for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
        struct sb_scene scene;
        enum sb_result got = sb_scene_parse(cases[i].json, strlen(cases[i].json), "case", &scene);
        CHECK(got == cases[i].expect, "case %zu (%s): got %s, expected %s", i, cases[i].json, sb_result_name(got),
              sb_result_name(cases[i].expect));
    }
    /* Deep nesting (cJSON stops at 1000 levels) and a NUL inside the text. */
    size_t depth = 100000;
    char *deep = malloc(2 * depth + 1);
    for (size_t i = 0; i < depth; i++) {
        deep[i] = '[';
        deep[2 * depth - 1 - i] = ']';
    }
    deep[2 * depth] = '\0';
    struct sb_scene nested;
    enum sb_result got = sb_scene_parse(deep, 2 * depth, "deep", &nested);
    CHECK(got == SB_ERR_JSON_SYNTAX, "100000 nested arrays: got %s", sb_result_name(got));
    free(deep);
    static const char with_nul[] = "{\"atmosphere\":{\"preset\":\"earth\"}}\0{}";
    got = sb_scene_parse(with_nul, sizeof(with_nul) - 1, "nul", &nested);
    CHECK(got == SB_ERR_JSON_SYNTAX, "a NUL byte in the text: got %s", sb_result_name(got));

    /* 40,000 keys with the last given twice: refused, naming it (the check
     * sorts the keys; it was quadratic) */
    size_t keys = 40000;
    char *wide = malloc(keys * 16 + 64), *w = wide;
    w += sprintf(w, "{\"atmosphere\":{\"preset\":\"earth\"},");
    for (size_t k = 0; k < keys; k++)
        w += sprintf(w, "\"k%zu\":0,", k);
    w += sprintf(w, "\"k0\":1}");
    got = sb_scene_parse(wide, (size_t)(w - wide), "wide", &nested);
    CHECK(got == SB_ERR_DUPLICATE_KEY, "40000 keys, one twice: got %s", sb_result_name(got));
    free(wide);

    /* A million reflection probes: refused by their count, naming the field;
     * 64, the cap, accepted. */
    static const int counts[] = {64, 65, 1000000};
    for (size_t c = 0; c < sizeof(counts) / sizeof(counts[0]); c++) {
        int count = counts[c];
        const char probe[] = "{\"position_m\":[0,1,0],\"box_m\":[[-1,0,-1],[1,2,1]]},";
        size_t cap = 200 + (size_t)count * (sizeof(probe) - 1);
        char *json = malloc(cap);
        size_t len = (size_t)snprintf(json, cap, EARTH "\"reflections\":{\"probes\":[");
        for (int i = 0; i < count; i++) {
            memcpy(json + len, probe, sizeof(probe) - 1);
            len += sizeof(probe) - 1;
        }
        len += (size_t)snprintf(json + len - 1, cap - len + 1, "]}}") - 1;
        struct sb_scene many;
        got = sb_scene_parse(json, len, "many", &many);
        CHECK(got == (count == 64 ? SB_OK : SB_ERR_OUT_OF_RANGE), "%d reflection probes: got %s", count,
              sb_result_name(got));
        free(json);
    }

    /* Overrides apply and normalisation is stable. */
    struct sb_scene a, b;
    const char *ja = "{\"atmosphere\":{\"preset\":\"earth\",\"mie_g\":0.76}}";
    const char *jb = "{ \"atmosphere\" : { \"mie_g\" : 0.76, \"preset\" : \"earth\" } }";
    CHECK(sb_scene_parse(ja, strlen(ja), "a", &a) == SB_OK && a.atmosphere.mie_g == 0.76, "override");
    CHECK(sb_scene_parse(jb, strlen(jb), "b", &b) == SB_OK, "parse b");
    char *na = sb_scene_normalized_json(&a), *nb = sb_scene_normalized_json(&b);
    CHECK(na && nb && !strcmp(na, nb), "normalised forms differ:\n%s\n%s", na, nb);
    free(na);
    free(nb);
    CHECK(sb_scene_load("/nonexistent/scene.json", &a) == SB_ERR_IO, "missing file");

    /* Without clouds asked for or given, the normalised scene has no
     * "clouds" (its hash is what format version 1 gave) and the atmosphere's
     * products skyview reads are wanted, irradiance_sky not (it is baked
     * only when named); the cloud parameters are the defaults, resolved in
     * full when asked for, and read back to the same form. */
    CHECK(sb_scene_parse(ja, strlen(ja), "a", &a) == SB_OK, "parse");
    na = sb_scene_normalized_json(&a);
    CHECK(na && !strstr(na, "clouds") && a.wants[SB_PRODUCT_TRANSMITTANCE] && a.wants[SB_PRODUCT_MULTISCATTERING] &&
              a.wants[SB_PRODUCT_IRRADIANCE_GROUND] && a.wants[SB_PRODUCT_ORDERS] &&
              !a.wants[SB_PRODUCT_IRRADIANCE_SKY] && !a.wants[SB_PRODUCT_CLOUD_SHAPE] && !a.wants[SB_PRODUCT_WEATHER],
          "an atmosphere scene: %s", na);
    free(na);
    const char *jc = EARTH "\"products\":[\"cloud_detail\"],\"clouds\":{\"cloud_detail\":{\"size\":48}}}";
    CHECK(sb_scene_parse(jc, strlen(jc), "c", &a) == SB_OK && a.clouds.detail_size == 48 &&
              a.clouds.shape_size == 128 && a.clouds.detail_worley_cells[2] == 8 && a.clouds.cloud_type.octaves == 3,
          "cloud parameters: given ones and defaults");
    na = sb_scene_normalized_json(&a);
    CHECK(na && sb_scene_parse(na, strlen(na), "normalised", &b) == SB_OK, "the normalised cloud scene parses");
    nb = sb_scene_normalized_json(&b);
    CHECK(na && nb && !strcmp(na, nb) && strstr(na, "\"type_octaves\":3"), "cloud scene normalisation is stable: %s",
          nb);
    free(na);
    free(nb);
}

/* binary16 against an independent reference: every half widens and narrows
 * back to itself; between each two neighbouring finite halves, the float
 * just below their midpoint (computed exactly in double) rounds down, just
 * above rounds up, and the midpoint itself to the even one; overflow. */
static void test_half(void)
{
    unsigned identity = 0, rounding = 0;
    for (uint32_t h = 0; h < 0x10000u; h++) {
        float f = sb_half_to_float((uint16_t)h);
        bool nan = (h & 0x7c00u) == 0x7c00u && (h & 0x3ffu);
        identity += nan ? !(isnan(f) && (sb_half_from_float(f) & 0x7e00u) == 0x7e00u) : sb_half_from_float(f) != h;
    }
    for (uint32_t h = 0; h < 0x7bffu; h++) {
        for (int sign = 0; sign < 2; sign++) {
            uint16_t lo = (uint16_t)(h | (sign << 15)), hi = (uint16_t)((h + 1) | (sign << 15));
            double mid = ((double)sb_half_to_float(lo) + (double)sb_half_to_float(hi)) / 2;
            float m = (float)mid; /* exact: 12 significant bits */
            uint16_t even = (h & 1) ? hi : lo;
            rounding += (double)m != mid;
            rounding += sb_half_from_float(m) != even;
            rounding += sb_half_from_float(nextafterf(m, 0.0f)) != lo;
            rounding += sb_half_from_float(nextafterf(m, sign ? -INFINITY : INFINITY)) != hi;
        }
    }
    CHECK(identity == 0, "%u halves do not survive a round trip through fp32", identity);
    CHECK(rounding == 0, "%u roundings to the nearest half differ from the midpoint reference", rounding);
    CHECK(sb_half_from_float(65504.0f) == 0x7bffu && sb_half_from_float(65519.99f) == 0x7bffu &&
              sb_half_from_float(65520.0f) == 0x7c00u && sb_half_from_float(-1e9f) == 0xfc00u &&
              sb_half_from_float(0x1p-25f) == 0 && sb_half_from_float(nextafterf(0x1p-25f, 1.0f)) == 1 &&
              sb_half_from_float(-0.0f) == 0x8000u,
          "overflow, the smallest subnormal's half and the sign of zero");
    struct sb_image big;
    sb_image_init(&big, 2, 1, 1);
    big.data[0] = 0.5f;
    big.data[1] = 70000.0f;
    int64_t bad = -1;
    CHECK(sb_image_round_to_half(&big, &bad) == SB_ERR_NUMERIC && bad == 1 && big.data[0] == 0.5f,
          "a value beyond binary16 is refused and nothing is changed");
    sb_image_finish(&big);
}

/* VDB volumes: exact at half precision, deterministic bytes, and refusals. */
static void test_vdb(void)
{
    struct sb_image v, back;
    CHECK(sb_image_init_volume(&v, 13, 9, 20, 4) == SB_OK, "init"); /* not multiples of the 8^3 leaves */
    sb_image_set_channel_names(&v, "perlin_worley,worley.0,worley.1,worley.2");
    uint32_t state = 12345;
    for (uint64_t i = 0; i < sb_image_float_count(&v); i++) {
        state = state * 1664525u + 1013904223u;
        v.data[i] = (float)(state >> 8) * 0x1p-24f; /* [0, 1) */
    }
    v.data[0] = 0.0f;
    v.data[1] = 1.0f;
    v.data[2] = 3e-7f; /* subnormal in binary16 */
    v.data[3] = 6.1e-5f;
    char path[] = "/tmp/skybake-test-XXXXXX.vdb", again[] = "/tmp/skybake-test-XXXXXX.vdb";
    close(mkstemps(path, 4));
    close(mkstemps(again, 4));
    struct sb_attribute attrs[2] = {{"skybake.product", "cloud_shape"}, {"skybake.content_hash", "abc"}};
    CHECK(sb_vdb_write(path, &v, attrs, 2) == SB_ERR_NUMERIC, "a value that is not a binary16 one is refused");
    CHECK(sb_image_round_to_half(&v, NULL) == SB_OK, "round");
    CHECK(sb_vdb_write(path, &v, attrs, 2) == SB_OK, "write");
    CHECK(sb_vdb_write(again, &v, attrs, 2) == SB_OK && files_equal(path, again),
          "the same volume gives the same bytes (OpenVDB's random UUID replaced)");
    struct sb_attribute got[SB_FILE_MAX_ATTRIBUTES];
    int ngot = 0;
    CHECK(sb_vdb_read(path, "perlin_worley,worley.0,worley.1,worley.2", 0, &back, got, &ngot) == SB_OK, "read");
    CHECK(back.width == 13 && back.height == 9 && back.depth == 20 && back.channel_count == 4, "shape %ux%ux%u x%u",
          back.width, back.height, back.depth, back.channel_count);
    CHECK(back.data && !memcmp(back.data, v.data, sb_image_float_count(&v) * sizeof(float)),
          "every value reads back bit for bit");
    char ha[SB_HASH_HEX_SIZE], hb[SB_HASH_HEX_SIZE];
    sb_image_content_hash(&v, ha);
    sb_image_content_hash(&back, hb);
    CHECK(!strcmp(ha, hb), "content hashes agree");
    bool found = false;
    for (int i = 0; i < ngot; i++)
        found |= !strcmp(got[i].name, "skybake.product") && !strcmp(got[i].value, "cloud_shape");
    CHECK(ngot == 2 && found, "attributes read back (%d)", ngot);
    sb_image_finish(&back);

    /* Refusals, each before or instead of a guess. */
    CHECK(sb_vdb_read(path, "worley.0,worley.1,worley.2", 0, &back, NULL, NULL) == SB_ERR_BAD_IMAGE, "other channels");
    CHECK(sb_vdb_read(path, "perlin_worley,worley.0,worley.1,worley.x", 0, &back, NULL, NULL) == SB_ERR_BAD_IMAGE,
          "a channel it does not hold");
    CHECK(sb_vdb_read(path, "perlin_worley,worley.0,worley.1,worley.2", 13 * 9 * 20 - 1, &back, NULL, NULL) ==
              SB_ERR_BAD_IMAGE,
          "more voxels than allowed, refused from the metadata");
    CHECK(!back.data, "a refused volume is left empty");
    CHECK(sb_vdb_read("/nonexistent.vdb", "a", 0, &back, NULL, NULL) == SB_ERR_IO, "no file");
    CHECK(sb_vdb_read("/tmp", "a", 0, &back, NULL, NULL) == SB_ERR_IO, "a directory");
    FILE *f = fopen(again, "wb");
    fputs("not a vdb file at all, just some text", f);
    fclose(f);
    CHECK(sb_vdb_read(again, "a", 0, &back, NULL, NULL) == SB_ERR_VDB, "bad magic");
    f = fopen(again, "wb");
    fclose(f);
    CHECK(sb_vdb_read(again, "a", 0, &back, NULL, NULL) == SB_ERR_VDB, "empty file");
    /* Crafted files: OpenVDB trusts the lengths in a file (a cut one made it
     * allocate 20 GB, others abort under ASan). Every prefix is refused,
     * most by the structure check before OpenVDB sees them; bytes changed
     * inside a grid, where only OpenVDB looks, cost the parent nothing. */
    CHECK(sb_vdb_write(again, &v, attrs, 2) == SB_OK, "write");
    CHECK(truncations_accepted(again, 300, 97, read_volume) == 0, "a cut VDB file is refused");
    CHECK(sb_vdb_write(again, &v, attrs, 2) == SB_OK, "write");
    f = fopen(again, "rb");
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    fclose(f);
    int accepted = 0, refused = 0;
    for (long at = 200; at + 8 < size; at += size / 24) {
        CHECK(sb_vdb_write(again, &v, attrs, 2) == SB_OK, "write");
        int fd = open(again, O_WRONLY);
        static const unsigned char junk[8] = {0xff, 0xff, 0xff, 0x7f, 0xff, 0xff, 0xff, 0x7f};
        CHECK(fd >= 0 && pwrite(fd, junk, sizeof(junk), at) == (ssize_t)sizeof(junk), "corrupt at %ld", at);
        close(fd);
        struct sb_image t;
        enum sb_result res =
            sb_vdb_read(again, "perlin_worley,worley.0,worley.1,worley.2", 13 * 9 * 20, &t, NULL, NULL);
        CHECK(res == SB_OK || res == SB_ERR_VDB || res == SB_ERR_BAD_IMAGE, "corrupt at %ld: %s", at,
              sb_result_name(res));
        if (res == SB_OK)
            sb_image_finish(&t);
        accepted += res == SB_OK;
        refused += res != SB_OK;
    }
    CHECK(refused > 0, "bytes changed inside the grids: %d refused, %d read (values changed)", refused, accepted);
    CHECK(sb_vdb_write("/nonexistent/dir/x.vdb", &v, NULL, 0) == SB_ERR_IO, "unwritable path");
    struct sb_image flat;
    sb_image_init(&flat, 4, 4, 1);
    sb_image_set_channel_names(&flat, "a");
    CHECK(sb_exr_write(again, &v, NULL, 0) == SB_ERR_BAD_IMAGE, "EXR refuses a volume");
    sb_image_finish(&flat);
    unlink(path);
    unlink(again);
    sb_image_finish(&v);
}

/* ---- packs ---------------------------------------------------------------------- */

static char pack_root[200];

#define FLIP_BYTE                                                                                                      \
    "printf '\\x55' | dd of=multiscattering.exr bs=1 seek=$(( $(stat -c %s multiscattering.exr) - 40 )) "              \
    "conv=notrunc 2>/dev/null"

static void run(const char *command)
{
    CHECK(system(command) == 0, "%s", command);
}

/* Let `edit` change the manifest of the pack in `dir`. */
static void edit_manifest(const char *dir, void (*edit)(cJSON *root))
{
    char path[512];
    snprintf(path, sizeof(path), "%s/manifest.json", dir);
    FILE *f = fopen(path, "rb");
    char *text = calloc(1, 1 << 20);
    size_t n = f ? fread(text, 1, (1 << 20) - 1, f) : 0;
    if (f)
        fclose(f);
    cJSON *root = cJSON_ParseWithLength(text, n);
    free(text);
    CHECK(root != NULL, "manifest parses");
    if (!root)
        return;
    edit(root);
    char *out = cJSON_Print(root);
    cJSON_Delete(root);
    f = fopen(path, "wb");
    fputs(out, f);
    fclose(f);
    free(out);
}

/* A hostile manifest that vouches for the files as they are now: each
 * artifact's file_hash recomputed, so that what is inside the files is
 * what gets checked. */
static const char *restamp_dir;
static void edit_restamp(cJSON *r)
{
    int fd = open(restamp_dir, O_RDONLY | O_DIRECTORY);
    const cJSON *a;
    cJSON_ArrayForEach(a, cJSON_GetObjectItem(r, "artifacts"))
    {
        char hash[SB_HASH_HEX_SIZE];
        const cJSON *file = cJSON_GetObjectItem(a, "file");
        if (cJSON_IsString(file) && sb_hash_file(fd, file->valuestring, hash) == SB_OK)
            cJSON_ReplaceItemInObject((cJSON *)a, "file_hash", cJSON_CreateString(hash));
    }
    close(fd);
}

/* Copy the good pack to `bad`, let `edit` change its manifest (may be NULL),
 * run `shell` in it (may be NULL), restamp the file hashes if asked, and
 * return the code opening it gives. */
static enum sb_result open_edited(const char *good, const char *bad, void (*edit)(cJSON *root), const char *shell,
                                  bool restamp)
{
    char cmd[1024];
    snprintf(cmd, sizeof(cmd), "rm -rf '%s' && cp -r '%s' '%s'", bad, good, bad);
    run(cmd);
    if (edit)
        edit_manifest(bad, edit);
    if (shell) {
        snprintf(cmd, sizeof(cmd), "cd '%s' && %s", bad, shell);
        run(cmd);
    }
    if (restamp) {
        restamp_dir = bad;
        edit_manifest(bad, edit_restamp);
    }
    struct sb_pack *pack = calloc(1, sizeof(*pack));
    enum sb_result res = sb_pack_open(bad, pack);
    sb_pack_close(pack);
    free(pack);
    return res;
}

static cJSON *artifact(cJSON *root, int i)
{
    return cJSON_GetArrayItem(cJSON_GetObjectItem(root, "artifacts"), i);
}

static void set_string(cJSON *object, const char *key, const char *value)
{
    cJSON_ReplaceItemInObject(object, key, cJSON_CreateString(value));
}

static void edit_version(cJSON *r)
{
    cJSON_ReplaceItemInObject(r, "format_version", cJSON_CreateNumber(SB_PACK_FORMAT_VERSION + 1));
}
static void edit_version_1(cJSON *r)
{
    cJSON_ReplaceItemInObject(r, "format_version", cJSON_CreateNumber(1));
}
/* The scene_hash of the manifest's scene as it now is: an edit the hash
 * does not give away. */
static void rehash_scene(cJSON *r)
{
    char *text = cJSON_PrintUnformatted(cJSON_GetObjectItem(r, "scene"));
    struct sb_scene parsed;
    CHECK(sb_scene_parse(text, strlen(text), "edit", &parsed) == SB_OK, "the edited scene parses");
    char *normal = sb_scene_normalized_json(&parsed), hash[SB_HASH_HEX_SIZE];
    sb_hash_bytes(normal, strlen(normal), hash);
    set_string(r, "scene_hash", hash);
    free(normal);
    free(text);
}
static void edit_version_2(cJSON *r)
{
    cJSON_ReplaceItemInObject(r, "format_version", cJSON_CreateNumber(2));
}
static void edit_version_3(cJSON *r)
{
    cJSON_ReplaceItemInObject(r, "format_version", cJSON_CreateNumber(3));
}
/* The bounce's pixel_type as packs before format version 10 record it. */
static void edit_bounce_fp32(cJSON *r)
{
    cJSON *artifacts = cJSON_GetObjectItem(r, "artifacts"), *a;
    cJSON_ArrayForEach(a, artifacts)
    {
        if (!strcmp(cJSON_GetStringValue(cJSON_GetObjectItem(a, "name")), "sky_bounce"))
            cJSON_ReplaceItemInObject(a, "pixel_type", cJSON_CreateString("float32"));
    }
}
static void edit_version_4(cJSON *r)
{
    cJSON_ReplaceItemInObject(r, "format_version", cJSON_CreateNumber(4));
    edit_bounce_fp32(r);
}
/* Version 5 with the DFG alone of the reflections: what version 5 wrote. */
static void edit_version_5(cJSON *r)
{
    cJSON_ReplaceItemInObject(r, "format_version", cJSON_CreateNumber(5));
    edit_bounce_fp32(r);
}
static void edit_version_11(cJSON *r)
{
    cJSON_ReplaceItemInObject(r, "format_version", cJSON_CreateNumber(11));
}
static void edit_version_12(cJSON *r)
{
    cJSON_ReplaceItemInObject(r, "format_version", cJSON_CreateNumber(12));
}
static void edit_version_13(cJSON *r)
{
    cJSON_ReplaceItemInObject(r, "format_version", cJSON_CreateNumber(13));
}
/* Version 14 with every product but the spectral ones: it opens. */
static void edit_version_14(cJSON *r)
{
    cJSON_ReplaceItemInObject(r, "format_version", cJSON_CreateNumber(14));
    cJSON *artifacts = cJSON_GetObjectItem(r, "artifacts");
    for (int i = cJSON_GetArraySize(artifacts) - 1; i >= 0; i--)
        if (!strncmp(cJSON_GetObjectItem(cJSON_GetArrayItem(artifacts, i), "name")->valuestring, "spectral_", 9))
            cJSON_DeleteItemFromArray(artifacts, i);
}
static void edit_version_14_listing(cJSON *r)
{
    cJSON_ReplaceItemInObject(r, "format_version", cJSON_CreateNumber(14));
}
/* What version 1 wrote: no cloud products (in the scene or the pack), no
 * file_hash; the scene's hash recomputed for the scene without clouds. */
static void edit_make_version_1(cJSON *r)
{
    edit_version_1(r);
    cJSON *artifacts = cJSON_GetObjectItem(r, "artifacts");
    for (int i = cJSON_GetArraySize(artifacts) - 1; i >= 0; i--) {
        cJSON *a = cJSON_GetArrayItem(artifacts, i);
        enum sb_product_id id;
        if (sb_product_from_name(cJSON_GetObjectItem(a, "name")->valuestring, &id) &&
            sb_product_format(id)->since_version > 1)
            cJSON_DeleteItemFromArray(artifacts, i);
        else
            cJSON_DeleteItemFromObject(a, "file_hash");
    }
    cJSON *scene = cJSON_GetObjectItem(r, "scene");
    cJSON_DeleteItemFromObject(scene, "clouds");
    cJSON_DeleteItemFromObject(scene, "probes");
    cJSON_DeleteItemFromObject(scene, "world");
    cJSON_DeleteItemFromObject(scene, "reflections");
    cJSON *products = cJSON_GetObjectItem(scene, "products");
    while (cJSON_GetArraySize(products) > SB_ATMOSPHERE_PRODUCT_COUNT)
        cJSON_DeleteItemFromArray(products, SB_ATMOSPHERE_PRODUCT_COUNT);
    rehash_scene(r);
}
static void edit_no_file_hash(cJSON *r)
{
    cJSON_DeleteItemFromObject(artifact(r, 4), "file_hash");
}
static void edit_empty_file_hash(cJSON *r)
{
    set_string(artifact(r, 1), "file_hash", "");
}
static void edit_volume_depth(cJSON *r)
{
    cJSON_ReplaceItemInObject(artifact(r, 4), "depth", cJSON_CreateNumber(8));
}
static void edit_volume_pixel_type(cJSON *r)
{
    set_string(artifact(r, 4), "pixel_type", "float32");
}
static void edit_cloud_size(cJSON *r)
{
    cJSON *clouds = cJSON_GetObjectItem(cJSON_GetObjectItem(r, "scene"), "clouds");
    cJSON_ReplaceItemInObject(cJSON_GetObjectItem(clouds, "cloud_detail"), "size", cJSON_CreateNumber(16));
    rehash_scene(r);
}
static void edit_no_version(cJSON *r)
{
    cJSON_DeleteItemFromObject(r, "format_version");
}
static void edit_parent_path(cJSON *r)
{
    set_string(artifact(r, 0), "file", "../transmittance.exr");
}
static void edit_absolute_path(cJSON *r)
{
    set_string(artifact(r, 0), "file", "/etc/passwd");
}
static void edit_hidden_path(cJSON *r)
{
    set_string(artifact(r, 0), "file", ".hidden.exr");
}
static void edit_hash(cJSON *r)
{
    set_string(artifact(r, 1), "content_hash", "00000000000000000000000000000000");
}
static void edit_width(cJSON *r)
{
    cJSON_ReplaceItemInObject(artifact(r, 0), "width", cJSON_CreateNumber(255));
}
/* a pack baked before the transmittance's mapping changed (docs/pack.md) */
static void edit_old_mapping(cJSON *r)
{
    set_string(artifact(r, 0), "parameterization", "transmittance-hillaire2020-v1");
}
static void edit_huge(cJSON *r)
{
    cJSON_ReplaceItemInObject(artifact(r, 0), "height", cJSON_CreateNumber(1e12));
}
static void edit_channels(cJSON *r)
{
    cJSON_ReplaceItemInObject(artifact(r, 0), "channels", cJSON_CreateString("r,g,b"));
}
static void edit_unknown(cJSON *r)
{
    set_string(artifact(r, 2), "name", "clouds");
}
static void edit_duplicate(cJSON *r)
{
    cJSON_AddItemToArray(cJSON_GetObjectItem(r, "artifacts"), cJSON_Duplicate(artifact(r, 0), true));
}
static void edit_pixel_type(cJSON *r)
{
    set_string(artifact(r, 0), "pixel_type", "float16");
}
static void edit_device(cJSON *r)
{
    cJSON_DeleteItemFromObject(cJSON_GetObjectItem(r, "device"), "name");
}

static void edit_scene_value(cJSON *r)
{
    cJSON *atm = cJSON_GetObjectItem(cJSON_GetObjectItem(r, "scene"), "atmosphere");
    cJSON_ReplaceItemInObject(atm, "mie_g", cJSON_CreateNumber(0.7));
}
static void edit_scene_invalid(cJSON *r)
{
    cJSON *atm = cJSON_GetObjectItem(cJSON_GetObjectItem(r, "scene"), "atmosphere");
    cJSON_ReplaceItemInObject(atm, "mie_g", cJSON_CreateNumber(1.5));
}
static void edit_no_scene(cJSON *r)
{
    cJSON_DeleteItemFromObject(r, "scene");
}
static void edit_format(cJSON *r)
{
    set_string(r, "format", "other-pack");
}
static void edit_artifacts_type(cJSON *r)
{
    cJSON_ReplaceItemInObject(r, "artifacts", cJSON_CreateObject());
}
/* The probes' world as packs before the typed fields held it: in settings. */
static int probes_entry(cJSON *r)
{
    for (int i = 0; i < cJSON_GetArraySize(cJSON_GetObjectItem(r, "artifacts")); i++)
        if (!strcmp(cJSON_GetStringValue(cJSON_GetObjectItem(artifact(r, i), "name")), "sky_visibility"))
            return i;
    return 0;
}

static void edit_world_in_settings(cJSON *r)
{
    cJSON *a = artifact(r, probes_entry(r)), *settings = cJSON_GetObjectItem(a, "settings");
    cJSON_AddItemToObject(settings, "world_hash", cJSON_DetachItemFromObject(a, "world_hash"));
    cJSON_AddItemToObject(settings, "world_path", cJSON_DetachItemFromObject(a, "world_path"));
}

static void edit_world_hash(cJSON *r)
{
    set_string(artifact(r, probes_entry(r)), "world_hash", "not a hash");
}

static void edit_world_path(cJSON *r)
{
    cJSON_ReplaceItemInObject(artifact(r, probes_entry(r)), "world_path", cJSON_CreateNumber(1));
}

static void edit_artifact_number(cJSON *r)
{
    cJSON_ReplaceItemInArray(cJSON_GetObjectItem(r, "artifacts"), 1, cJSON_CreateNumber(1));
}

static void test_pack_reader(void)
{
    CHECK(test_temp_dir("skybake-pack-test", pack_root, sizeof(pack_root)), "temporary directory");
    char good[256], bad[256];
    snprintf(good, sizeof(good), "%s/good", pack_root);
    snprintf(bad, sizeof(bad), "%s/bad", pack_root);
    struct sb_image images[SB_PRODUCT_COUNT] = {0};
    CHECK(write_synthetic_pack(good, "test", images) == SB_OK, "a synthetic pack");
    struct sb_image nan_image;
    char nan_path[300];
    snprintf(nan_path, sizeof(nan_path), "%s/nan.exr", pack_root);
    sb_image_init(&nan_image, images[SB_PRODUCT_MULTISCATTERING].width, images[SB_PRODUCT_MULTISCATTERING].height, 3);
    sb_image_set_channel_names(&nan_image, "r,g,b");
    nan_image.data[100] = NAN;
    CHECK(sb_exr_write(nan_path, &nan_image, NULL, 0) == SB_OK, "write an EXR holding NaN");
    sb_image_finish(&nan_image);
    /* the orders' table with an infinite node, and with a negative one */
    for (int k = 0; k < 2; k++) {
        snprintf(nan_path, sizeof(nan_path), "%s/%s.exr", pack_root, k ? "orders_negative" : "orders_inf");
        sb_image_init(&nan_image, images[SB_PRODUCT_ORDERS].width, images[SB_PRODUCT_ORDERS].height, 3);
        sb_image_set_channel_names(&nan_image, "r,g,b");
        nan_image.data[3 * 777 + 1] = k ? -1.0f : INFINITY;
        CHECK(sb_exr_write(nan_path, &nan_image, NULL, 0) == SB_OK, "write an orders table holding %s",
              k ? "a negative value" : "Inf");
        sb_image_finish(&nan_image);
        /* the same at 12 wavelengths, the value in the last band */
        const struct sb_image *spectral = &images[SB_PRODUCT_SPECTRAL_ORDERS];
        snprintf(nan_path, sizeof(nan_path), "%s/%s.exr", pack_root, k ? "spectral_negative" : "spectral_inf");
        sb_image_init(&nan_image, spectral->width, spectral->height, spectral->channel_count);
        sb_image_set_channel_names(&nan_image, sb_product_format(SB_PRODUCT_SPECTRAL_ORDERS)->channel_names);
        nan_image.data[spectral->channel_count * 777 + 10] = k ? -1.0f : INFINITY;
        CHECK(sb_exr_write(nan_path, &nan_image, NULL, 0) == SB_OK, "write a spectral orders table holding %s",
              k ? "a negative value" : "Inf");
        sb_image_finish(&nan_image);
    }

    struct sb_pack *pack = calloc(1, sizeof(*pack));
    CHECK(sb_pack_open(good, pack) == SB_OK, "a pack just written opens");
    for (int p = 0; p < SB_PRODUCT_COUNT; p++) {
        CHECK(pack->present[p], "%s present", sb_product_name((enum sb_product_id)p));
        CHECK(pack->images[p].data &&
                  !memcmp(pack->images[p].data, images[p].data, sb_image_float_count(&images[p]) * sizeof(float)),
              "%s reads back bit for bit", sb_product_name((enum sb_product_id)p));
        sb_image_finish(&images[p]);
    }
    CHECK(pack->format_version == SB_PACK_FORMAT_VERSION && !strcmp(pack->device.name, "test device"), "header");
    const struct sb_artifact *probes = &pack->artifacts[SB_PRODUCT_SKY_VISIBILITY];
    CHECK(!strcmp(probes->world_hash, SYNTHETIC_WORLD_HASH) && !strcmp(probes->world_path, SYNTHETIC_WORLD_PATH),
          "the world the probes were baked against reads back: %s %s", probes->world_hash, probes->world_path);
    CHECK(!pack->artifacts[SB_PRODUCT_TRANSMITTANCE].world_hash[0], "the atmosphere has no world");
    CHECK(pack->scene && !strcmp(pack->scene->name, "test") && pack->scene->atmosphere.mie_g == 0.8,
          "the scene reads back");
    sb_pack_close(pack);
    free(pack);

    static const struct {
        const char *what;
        void (*edit)(cJSON *root);
        const char *shell;
        enum sb_result expect;
        bool restamp;
    } cases[] = {
        {"unchanged copy", NULL, NULL, SB_OK, false},
        {"unknown format version", edit_version, NULL, SB_ERR_VERSION, false},
        {"no format version", edit_no_version, NULL, SB_ERR_MISSING_FIELD, false},
        {"file in the parent directory", edit_parent_path, NULL, SB_ERR_UNSAFE_PATH, false},
        {"absolute file", edit_absolute_path, NULL, SB_ERR_UNSAFE_PATH, false},
        {"hidden file", edit_hidden_path, NULL, SB_ERR_UNSAFE_PATH, false},
        {"artifact that is a symbolic link", NULL, "mv transmittance.exr t.exr && ln -s t.exr transmittance.exr",
         SB_ERR_UNSAFE_PATH, false},
        {"manifest that is a symbolic link", NULL, "mv manifest.json m && ln -s m manifest.json", SB_ERR_UNSAFE_PATH,
         false},
        {"missing artifact", NULL, "rm multiscattering.exr", SB_ERR_IO, false},
        {"recorded hash differs", edit_hash, NULL, SB_ERR_HASH_MISMATCH, false},
        {"artifact replaced by another product's file", NULL, "cp irradiance_sky.exr irradiance_ground.exr",
         SB_ERR_HASH_MISMATCH, false},
        {"artifact replaced by another product's file, vouched for", NULL,
         "cp irradiance_sky.exr irradiance_ground.exr", SB_ERR_BAD_IMAGE, true},
        {"truncated artifact", NULL, "head -c 3000 transmittance.exr > t && mv t transmittance.exr",
         SB_ERR_HASH_MISMATCH, false},
        {"truncated artifact, vouched for", NULL, "head -c 3000 transmittance.exr > t && mv t transmittance.exr",
         SB_ERR_EXR, true},
        {"one flipped byte in the compressed pixels", NULL, FLIP_BYTE, SB_ERR_HASH_MISMATCH, false},
        {"one flipped byte in the compressed pixels, vouched for", NULL, FLIP_BYTE, SB_ERR_EXR, true},
        {"format version 1, as version 1 wrote it", edit_make_version_1,
         "rm cloud_shape.vdb cloud_detail.vdb cloud_curl.exr weather.exr sky_visibility.sbprobes sky_bounce.sbprobes "
         "dfg.exr reflection_cubes.exr reflection_probes.sbprobes sun_bounce.sbprobes reflection_surfaces.exr "
         "orders.exr spectral_transmittance.exr spectral_irradiance_ground.exr spectral_orders.exr",
         SB_OK, false},
        {"format version 2 listing sky_visibility", edit_version_2, NULL, SB_ERR_UNKNOWN_PRODUCT, false},
        {"format version 3 listing sky_bounce", edit_version_3, NULL, SB_ERR_UNKNOWN_PRODUCT, false},
        {"format version 4 listing dfg", edit_version_4, NULL, SB_ERR_UNKNOWN_PRODUCT, false},
        {"format version 5 listing reflection_cubes", edit_version_5, NULL, SB_ERR_UNKNOWN_PRODUCT, false},
        {"format version 11 listing sun_bounce", edit_version_11, NULL, SB_ERR_UNKNOWN_PRODUCT, false},
        {"format version 12 listing reflection_surfaces", edit_version_12, NULL, SB_ERR_UNKNOWN_PRODUCT, false},
        {"format version 13 listing orders", edit_version_13, NULL, SB_ERR_UNKNOWN_PRODUCT, false},
        {"orders truncated, vouched for", NULL, "head -c 3000 orders.exr > t && mv t orders.exr", SB_ERR_EXR, true},
        {"orders replaced by the transmittance's file, vouched for", NULL, "cp transmittance.exr orders.exr",
         SB_ERR_BAD_IMAGE, true},
        {"orders holding Inf, vouched for", NULL, "cp ../orders_inf.exr orders.exr", SB_ERR_NUMERIC, true},
        {"orders holding a negative radiance, vouched for", NULL, "cp ../orders_negative.exr orders.exr",
         SB_ERR_NUMERIC, true},
        {"format version 14 listing the spectral products", edit_version_14_listing, NULL, SB_ERR_UNKNOWN_PRODUCT,
         false},
        {"format version 14 without them", edit_version_14,
         "rm spectral_transmittance.exr spectral_irradiance_ground.exr spectral_orders.exr", SB_OK, false},
        {"spectral orders truncated, vouched for", NULL,
         "head -c 5000 spectral_orders.exr > t && mv t spectral_orders.exr", SB_ERR_EXR, true},
        {"spectral orders replaced by the orders' file (3 wavelengths), vouched for", NULL,
         "cp orders.exr spectral_orders.exr", SB_ERR_BAD_IMAGE, true},
        {"spectral transmittance replaced by the transmittance's file, vouched for", NULL,
         "cp transmittance.exr spectral_transmittance.exr", SB_ERR_BAD_IMAGE, true},
        {"spectral orders holding Inf, vouched for", NULL, "cp ../spectral_inf.exr spectral_orders.exr", SB_ERR_NUMERIC,
         true},
        {"spectral orders holding a negative radiance, vouched for", NULL,
         "cp ../spectral_negative.exr spectral_orders.exr", SB_ERR_NUMERIC, true},
        {"surfaces file truncated, vouched for", NULL,
         "head -c 4000 reflection_surfaces.exr > t && mv t reflection_surfaces.exr", SB_ERR_EXR, true},
        {"surfaces replaced by the cubes' file, vouched for", NULL, "cp reflection_cubes.exr reflection_surfaces.exr",
         SB_ERR_BAD_IMAGE, true},
        {"truncated sun bounce file, vouched for", NULL,
         "head -c 300 sun_bounce.sbprobes > t && mv t sun_bounce.sbprobes", SB_ERR_BAD_IMAGE, true},
        {"cube file truncated, vouched for", NULL, "head -c 4000 reflection_cubes.exr > t && mv t reflection_cubes.exr",
         SB_ERR_EXR, true},
        {"cube file replaced by the DFG's EXR, vouched for", NULL, "cp dfg.exr reflection_cubes.exr", SB_ERR_BAD_IMAGE,
         true},
        {"reflection probes truncated, vouched for", NULL,
         "head -c 200 reflection_probes.sbprobes > t && mv t reflection_probes.sbprobes", SB_ERR_BAD_IMAGE, true},
        {"truncated bounce file, vouched for", NULL, "head -c 300 sky_bounce.sbprobes > t && mv t sky_bounce.sbprobes",
         SB_ERR_BAD_IMAGE, true},
        {"truncated probe file", NULL, "head -c 200 sky_visibility.sbprobes > t && mv t sky_visibility.sbprobes",
         SB_ERR_HASH_MISMATCH, false},
        {"truncated probe file, vouched for", NULL,
         "head -c 200 sky_visibility.sbprobes > t && mv t sky_visibility.sbprobes", SB_ERR_BAD_IMAGE, true},
        {"format version 1 listing cloud products", edit_version_1, NULL, SB_ERR_UNKNOWN_PRODUCT, false},
        {"truncated volume", NULL, "head -c 3000 cloud_shape.vdb > t && mv t cloud_shape.vdb", SB_ERR_HASH_MISMATCH,
         false},
        {"volume without a file hash", edit_no_file_hash, NULL, SB_ERR_MISSING_FIELD, false},
        {"an empty file hash", edit_empty_file_hash, NULL, SB_ERR_OUT_OF_RANGE, false},
        {"volume replaced by the other volume, vouched for", NULL, "cp cloud_detail.vdb cloud_shape.vdb",
         SB_ERR_BAD_IMAGE, true},
        {"volume replaced by an EXR, vouched for", NULL, "cp weather.exr cloud_detail.vdb", SB_ERR_VDB, true},
        {"volume's depth differs from the scene's", edit_volume_depth, NULL, SB_ERR_BAD_IMAGE, false},
        {"volume's pixel type", edit_volume_pixel_type, NULL, SB_ERR_BAD_IMAGE, false},
        {"scene's cloud size edited", edit_cloud_size, NULL, SB_ERR_BAD_IMAGE, false},
        {"width differs from the product's", edit_width, NULL, SB_ERR_BAD_IMAGE, false},
        {"the transmittance's mapping before v2", edit_old_mapping, NULL, SB_ERR_BAD_IMAGE, false},
        {"absurd height", edit_huge, NULL, SB_ERR_BAD_IMAGE, false},
        {"channels of the wrong type", edit_channels, NULL, SB_ERR_WRONG_TYPE, false},
        {"pixel type", edit_pixel_type, NULL, SB_ERR_BAD_IMAGE, false},
        {"device without a name", edit_device, NULL, SB_ERR_MISSING_FIELD, false},
        {"scene edited", edit_scene_value, NULL, SB_ERR_HASH_MISMATCH, false},
        {"scene out of range", edit_scene_invalid, NULL, SB_ERR_OUT_OF_RANGE, false},
        {"no scene", edit_no_scene, NULL, SB_ERR_MISSING_FIELD, false},
        {"unknown product", edit_unknown, NULL, SB_ERR_UNKNOWN_PRODUCT, false},
        {"product listed twice", edit_duplicate, NULL, SB_ERR_DUPLICATE_KEY, false},
        {"manifest is binary garbage", NULL, "printf '\\211PNG\\r\\n\\032\\n\\000\\377{[' > manifest.json",
         SB_ERR_JSON_SYNTAX, false},
        {"manifest is a truncated object", NULL, "head -c 200 manifest.json > m && mv m manifest.json",
         SB_ERR_JSON_SYNTAX, false},
        {"manifest is empty", NULL, ": > manifest.json", SB_ERR_JSON_SYNTAX, false},
        {"manifest over 1 MiB", NULL, "head -c 1100000 /dev/zero | tr '\\\\0' ' ' >> manifest.json",
         SB_ERR_OUT_OF_RANGE, false},
        {"no manifest", NULL, "rm manifest.json", SB_ERR_IO, false},
        {"file the manifest does not list", NULL, "echo x > notes.txt", SB_ERR_UNLISTED_FILE, false},
        {"directory the manifest does not list", NULL, "mkdir sub", SB_ERR_UNLISTED_FILE, false},
        {"another format", edit_format, NULL, SB_ERR_VERSION, false},
        {"artifacts not an array", edit_artifacts_type, NULL, SB_ERR_WRONG_TYPE, false},
        {"artifact entry not an object", edit_artifact_number, NULL, SB_ERR_WRONG_TYPE, false},
        {"the world in settings, as earlier builds wrote it", edit_world_in_settings, NULL, SB_OK, false},
        {"a world hash that is not one", edit_world_hash, NULL, SB_ERR_OUT_OF_RANGE, false},
        {"a world path that is not a string", edit_world_path, NULL, SB_ERR_WRONG_TYPE, false},
        {"key given twice in the manifest", NULL,
         "sed -i '0,/\"skybake_version\"/s//\"skybake_version\": \"x\", \"skybake_version\"/' manifest.json",
         SB_ERR_DUPLICATE_KEY, false},
        {"artifact holding NaN", NULL, "cp ../nan.exr multiscattering.exr", SB_ERR_HASH_MISMATCH, false},
        {"artifact holding NaN, vouched for", NULL, "cp ../nan.exr multiscattering.exr", SB_ERR_NUMERIC, true},
        {"pack directory replaced by a file", NULL, "cd .. && rm -rf bad && echo x > bad", SB_ERR_IO, false},
    };
    for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
        enum sb_result got = open_edited(good, bad, cases[i].edit, cases[i].shell, cases[i].restamp);
        CHECK(got == cases[i].expect, "pack with %s: got %s, expected %s", cases[i].what, sb_result_name(got),
              sb_result_name(cases[i].expect));
    }
    /* A pack of an earlier build, its world in the probes' settings: read from there. */
    open_edited(good, bad, edit_world_in_settings, NULL, false);
    struct sb_pack *older = calloc(1, sizeof(*older));
    CHECK(sb_pack_open(bad, older) == SB_OK &&
              !strcmp(older->artifacts[SB_PRODUCT_SKY_VISIBILITY].world_hash, SYNTHETIC_WORLD_HASH) &&
              !strcmp(older->artifacts[SB_PRODUCT_SKY_VISIBILITY].world_path, SYNTHETIC_WORLD_PATH),
          "the world read from an earlier build's settings");
    sb_pack_close(older);
    free(older);
    /* The writer refuses settings that are not a JSON object, and records a
     * world path that is not UTF-8 as unknown. */
    struct sb_pack_writer *writer = NULL;
    char scratch[300];
    snprintf(scratch, sizeof(scratch), "%s/scratch", pack_root);
    CHECK(sb_pack_writer_create(scratch, &writer) == SB_OK, "a writer");
    struct sb_image tiny;
    sb_image_init(&tiny, 2, 2, 2);
    sb_image_set_channel_names(&tiny, "dfg.x,dfg.y");
    struct sb_artifact bad_settings = {.product = SB_PRODUCT_DFG, .file = "dfg.exr", .settings_json = "{\"a\":"};
    CHECK(sb_pack_writer_add_image(writer, &bad_settings, &tiny) == SB_ERR_JSON_SYNTAX, "settings that do not parse");
    struct sb_artifact odd_path = {.product = SB_PRODUCT_SKY_VISIBILITY};
    sb_artifact_set_world(&odd_path, SYNTHETIC_WORLD_HASH, "/worlds/caf\xe9.obj");
    CHECK(!strcmp(odd_path.world_hash, SYNTHETIC_WORLD_HASH) && !odd_path.world_path[0],
          "a world path that is not UTF-8 is not recorded");
    sb_image_finish(&tiny);
    sb_pack_writer_destroy(&writer);

    /* verify goes on past each problem: three of them, each counted. */
    open_edited(good, bad, edit_hash, "rm irradiance_ground.exr && echo x > notes.txt", false);
    unsigned problems = 0;
    enum sb_result got_code = sb_pack_verify(bad, &problems);
    CHECK(got_code == SB_ERR_HASH_MISMATCH && problems == 3, "verify of a pack with three problems: %s, %u problems",
          sb_result_name(got_code), problems);
    got_code = sb_pack_verify(good, &problems);
    CHECK(got_code == SB_OK && problems == 0, "verify of a good pack: %s, %u problems", sb_result_name(got_code),
          problems);

    /* A well-formed EXR whose pixels differ from what the manifest recorded. */
    open_edited(good, bad, NULL, NULL, false);
    char path[512];
    snprintf(path, sizeof(path), "%s/transmittance.exr", bad);
    struct sb_image t;
    CHECK(sb_exr_read(path, "r,g,b", 0, &t, NULL, NULL) == SB_OK, "read");
    t.data[7] = nextafterf(t.data[7], 2.0f);
    CHECK(sb_exr_write(path, &t, NULL, 0) == SB_OK, "rewrite");
    sb_image_finish(&t);
    restamp_dir = bad;
    edit_manifest(bad, edit_restamp);
    pack = calloc(1, sizeof(*pack));
    enum sb_result got = sb_pack_open(bad, pack);
    CHECK(got == SB_ERR_HASH_MISMATCH, "one ulp changed in a pixel: got %s", sb_result_name(got));
    CHECK(!pack->present[0] && !pack->images[0].data, "a refused pack is left empty");

    /* A well-formed VDB whose values differ by one half-ulp, vouched for. */
    open_edited(good, bad, NULL, NULL, false);
    snprintf(path, sizeof(path), "%s/cloud_shape.vdb", bad);
    const char *shape_channels = sb_product_format(SB_PRODUCT_CLOUD_SHAPE)->channel_names;
    CHECK(sb_vdb_read(path, shape_channels, 0, &t, NULL, NULL) == SB_OK, "read the volume");
    t.data[100] = sb_half_to_float((uint16_t)(sb_half_from_float(t.data[100]) + 1));
    CHECK(sb_vdb_write(path, &t, NULL, 0) == SB_OK, "rewrite the volume");
    sb_image_finish(&t);
    edit_manifest(bad, edit_restamp);
    got = sb_pack_open(bad, pack);
    CHECK(got == SB_ERR_HASH_MISMATCH, "one half-ulp changed in a voxel: got %s", sb_result_name(got));

    /* Every truncated prefix of a volume is refused by its file hash before
     * OpenVDB sees a byte (its reader is not hardened against such files). */
    open_edited(good, bad, NULL, NULL, false);
    struct stat st;
    CHECK(stat(path, &st) == 0, "the volume's size");
    unsigned refused = 0, prefixes = 0;
    for (off_t n = 0; n < st.st_size; n += st.st_size / 97 + 1, prefixes++) {
        char cmd[2048];
        snprintf(cmd, sizeof(cmd), "cp '%s/cloud_shape.vdb' '%s/t' && truncate -s %lld '%s/t' && mv '%s/t' '%s'", good,
                 bad, (long long)n, bad, bad, path);
        run(cmd);
        refused += sb_pack_open(bad, pack) == SB_ERR_HASH_MISMATCH;
    }
    CHECK(refused == prefixes, "%u of %u truncated volumes refused with hash-mismatch", refused, prefixes);
    free(pack);

    CHECK(test_remove_dir(pack_root), "clean up %s", pack_root);
}

/* The codes are a closed set: each has its own name and a description. */
static void test_result_codes(void)
{
    for (int i = 0; i < SB_RESULT_COUNT; i++) {
        const char *name = sb_result_name((enum sb_result)i);
        CHECK(strcmp(name, "unknown") != 0 && strlen(sb_result_description((enum sb_result)i)) > 4,
              "code %d has a name and a description", i);
        for (int j = 0; j < i; j++)
            CHECK(strcmp(name, sb_result_name((enum sb_result)j)) != 0, "codes %d and %d share the name %s", j, i,
                  name);
    }
    CHECK(!strcmp(sb_result_name(SB_RESULT_COUNT), "unknown") &&
              !strcmp(sb_result_name((enum sb_result) - 1), "unknown"),
          "outside the set: unknown");
}

/* Probe files: a round trip, and every truncated prefix, every bit flipped
 * in every byte, trailing bytes, a newer version and hostile fields
 * (re-checksummed, so that the field's own check is what refuses them). */
static void restamp(uint8_t *b, size_t size)
{
    uint64_t h = XXH3_64bits(b, size - 8);
    for (int i = 0; i < 8; i++)
        b[size - 8 + i] = (uint8_t)(h >> (8 * i));
}

/* Every truncated prefix and every bit flip of a probe file's bytes is
 * refused (`what` names the file in the messages). */
static void check_probes_damage(uint8_t *bytes, size_t size, const char *what)
{
    struct sb_probe_layout got;
    struct sb_image back;
    int refused = 0, tried = 0;
    for (size_t cut = 0; cut < size; cut++, tried++)
        refused += sb_probes_parse(bytes, cut, "cut", SB_SKY_VISIBILITY_CHANNELS, 1000, &got, &back) != SB_OK;
    CHECK(refused == tried, "%s: every truncated prefix is refused (%d of %d)", what, refused, tried);
    refused = tried = 0;
    for (size_t i = 0; i < size; i++)
        for (int bit = 0; bit < 8; bit++, tried++) {
            bytes[i] ^= (uint8_t)(1u << bit);
            enum sb_result res = sb_probes_parse(bytes, size, "flip", SB_SKY_VISIBILITY_CHANNELS, 1000, &got, &back);
            refused += res != SB_OK;
            if (res == SB_OK)
                sb_image_finish(&back);
            bytes[i] ^= (uint8_t)(1u << bit);
        }
    CHECK(refused == tried, "%s: every bit flip is refused (%d of %d)", what, refused, tried);
}

/* A probe file's bytes as written, into bytes[cap]; their size. */
static size_t read_back(const char *path, uint8_t *bytes, size_t cap)
{
    FILE *f = fopen(path, "rb");
    size_t size = f ? fread(bytes, 1, cap, f) : 0;
    if (f)
        fclose(f);
    return size;
}

/* A field of a probe file set to a value, its checksum restamped: what the
 * parser makes of it (anything it returns freed). */
struct field_edit {
    size_t offset;
    uint32_t value;
    const char *what;
};

static enum sb_result parse_edited(const uint8_t *bytes, size_t size, const struct field_edit *e)
{
    uint8_t edited[4096];
    memcpy(edited, bytes, size);
    for (int k = 0; k < 4; k++)
        edited[e->offset + k] = (uint8_t)(e->value >> (8 * k));
    restamp(edited, size);
    struct sb_probe_layout got;
    struct sb_image back;
    enum sb_result res = sb_probes_parse(edited, size, "edited", SB_SKY_VISIBILITY_CHANNELS, 1000, &got, &back);
    if (res == SB_OK) {
        sb_image_finish(&back);
        sb_probe_layout_finish(&got);
    }
    return res;
}

/* Every edit refused with `want` (SB_OK: with anything but SB_OK). */
static void check_edits(const uint8_t *bytes, size_t size, const struct field_edit *edits, size_t n,
                        enum sb_result want)
{
    for (size_t i = 0; i < n; i++) {
        enum sb_result res = parse_edited(bytes, size, &edits[i]);
        CHECK(want == SB_OK ? res != SB_OK : res == want, "%s: %s", edits[i].what, sb_result_name(res));
    }
}

static void test_probes(void)
{
    /* The channel indices C code uses are the names' positions. */
    static const struct {
        int index;
        const char *name;
    } channels[] = {
        {SB_SKY_VISIBILITY_POSITION, "position.x"},
        {SB_SKY_VISIBILITY_OFFSET, "offset.x"},
        {SB_SKY_VISIBILITY_VALID, "valid"},
        {SB_SKY_VISIBILITY_BACK_FRACTION, "back_fraction"},
        {SB_SKY_VISIBILITY_HIT_FRACTION, "hit_fraction"},
        {SB_SKY_VISIBILITY_MEAN_DISTANCE, "mean_distance_m"},
        {SB_SKY_VISIBILITY_DERING_WINDOW, "dering_window"},
        {SB_SKY_VISIBILITY_SH, "sh.0"},
        {SB_SKY_VISIBILITY_SH + 8, "sh.8"},
    };
    struct sb_image names = {0};
    sb_image_set_channel_names(&names, SB_SKY_VISIBILITY_CHANNELS);
    for (size_t i = 0; i < sizeof(channels) / sizeof(channels[0]); i++)
        CHECK(!strcmp(names.channel_names[channels[i].index], channels[i].name), "channel %d is %s, not %s",
              channels[i].index, names.channel_names[channels[i].index], channels[i].name);

    char dir[256], path[300];
    CHECK(test_temp_dir("skybake-probes", dir, sizeof(dir)), "temporary directory");
    snprintf(path, sizeof(path), "%s/p.sbprobes", dir);
    struct sb_image img = {0}, back;
    const uint32_t n = 2 * 1 * 2 + 1, ch = SB_SKY_VISIBILITY_CHANNEL_COUNT;
    CHECK(sb_image_init(&img, n, 1, ch) == SB_OK, "image");
    sb_image_set_channel_names(&img, SB_SKY_VISIBILITY_CHANNELS);
    for (uint32_t i = 0; i < n * ch; i++) {
        uint32_t c = i % ch;
        img.data[i] = c == 6 ? 1.0f : c >= 7 && c <= 8 ? 0.25f : c == 10 ? 0.5f : (float)(i % 7) * 0.125f - 0.3f;
        if (c == 9)
            img.data[i] = 3.5f;
    }
    struct sb_probe_layout layout = {.grid = {2, 1, 2},
                                     .explicit_count = 1,
                                     .origin_m = {-1, 0.5f, 2},
                                     .spacing_m = {1.5f, 1, 2},
                                     .ray_count = 2048,
                                     .key = "0123456789abcdef0123456789abcdef"},
                           got;
    CHECK(sb_probes_write(path, &layout, &img, false) == SB_OK, "write");
    CHECK(sb_probes_read(path, SB_SKY_VISIBILITY_CHANNELS, 1000, &got, &back) == SB_OK, "read back");
    CHECK(back.width == n && back.channel_count == ch && !memcmp(back.data, img.data, sizeof(float) * n * ch) &&
              !memcmp(got.grid, layout.grid, sizeof(got.grid)) && got.explicit_count == layout.explicit_count &&
              !memcmp(got.origin_m, layout.origin_m, sizeof(got.origin_m)) &&
              !memcmp(got.spacing_m, layout.spacing_m, sizeof(got.spacing_m)) && got.ray_count == layout.ray_count &&
              !strcmp(got.key, layout.key),
          "the round trip is exact");
    sb_image_finish(&back);
    uint8_t bytes[4096];
    size_t size = read_back(path, bytes, sizeof(bytes));
    CHECK(size == SB_PROBES_HEADER_BYTES_V1 + (size_t)n * ch * 4 + 8, "a grid without layers is version 1: size %zu",
          size);
    check_probes_damage(bytes, size, "a grid");
    uint8_t longer[4200];
    memcpy(longer, bytes, size);
    longer[size] = 0;
    CHECK(sb_probes_parse(longer, size + 1, "trailing", SB_SKY_VISIBILITY_CHANNELS, 1000, &got, &back) ==
              SB_ERR_BAD_IMAGE,
          "a trailing byte");
    CHECK(sb_probes_parse(bytes, size, "channels", "a,b,c", 1000, &got, &back) == SB_ERR_BAD_IMAGE, "other channels");
    CHECK(sb_probes_parse(bytes, size, "cap", SB_SKY_VISIBILITY_CHANNELS, 4, &got, &back) == SB_ERR_PROBES,
          "more probes than the cap");
    struct {
        size_t offset;
        uint32_t value;
        enum sb_result want;
        const char *what;
    } fields[] = {
        {8, 7, SB_ERR_VERSION, "a newer version"},
        {8, 6, SB_ERR_PROBES, "version 6 with version 1's header"},
        {8, 5, SB_ERR_PROBES, "version 5 with version 1's header"},
        {8, 4, SB_ERR_PROBES, "version 4 with version 1's header"},
        {8, 3, SB_ERR_PROBES, "version 3 with version 1's header"},
        {8, 2, SB_ERR_PROBES, "version 2 with version 1's header"},
        {8, 0, SB_ERR_VERSION, "version 0"},
        {12, 0x04030201, SB_ERR_PROBES, "big endian"},
        {16, 116, SB_ERR_PROBES, "another header size"},
        {24, 0xffffffff, SB_ERR_PROBES, "a huge count"},
        {28, 0, SB_ERR_PROBES, "a grid with a zero axis"},
        {36, 5000, SB_ERR_PROBES, "a grid past its cap"},
        {40, 2, SB_ERR_PROBES, "counts that do not add up"},
        {56, 0xbf800000, SB_ERR_PROBES, "a negative spacing"},
        {48, 0x7fc00000, SB_ERR_PROBES, "a NaN origin"},
        {72, 0x41414141, SB_ERR_PROBES, "a key that is not hex"},
        {108, 1, SB_ERR_PROBES, "a reserved byte"},
        {SB_PROBES_HEADER_BYTES_V1 + 6 * 4, 0x3f000000, SB_ERR_NUMERIC, "valid = 0.5"},
        {SB_PROBES_HEADER_BYTES_V1 + 7 * 4, 0x40000000, SB_ERR_NUMERIC, "a fraction of 2"},
        {SB_PROBES_HEADER_BYTES_V1 + 9 * 4, 0xbf800000, SB_ERR_NUMERIC, "a negative distance"},
        {SB_PROBES_HEADER_BYTES_V1 + 12 * 4, 0x41200000, SB_ERR_NUMERIC, "an SH coefficient of 10"},
        {SB_PROBES_HEADER_BYTES_V1 + 0 * 4, 0x7f800000, SB_ERR_NUMERIC, "an infinite position"},
    };
    for (size_t i = 0; i < sizeof(fields) / sizeof(fields[0]); i++) {
        enum sb_result res =
            parse_edited(bytes, size, &(struct field_edit){fields[i].offset, fields[i].value, fields[i].what});
        CHECK(res == fields[i].want, "%s: %s, expected %s", fields[i].what, sb_result_name(res),
              sb_result_name(fields[i].want));
    }
    CHECK(sb_probes_read(dir, SB_SKY_VISIBILITY_CHANNELS, 1000, &got, &back) == SB_ERR_IO, "a directory");

    /* A grid of layers that follow the surface: version 2, its heights
     * round-trip, every prefix and bit flip is refused, and so are layers
     * that do not match the grid or do not rise. */
    struct sb_image layered = {0};
    const uint32_t nl = 2 * 2 * 2;
    CHECK(sb_image_init(&layered, nl, 1, ch) == SB_OK, "image");
    sb_image_set_channel_names(&layered, SB_SKY_VISIBILITY_CHANNELS);
    memcpy(layered.data, img.data, sizeof(float) * (n < nl ? n : nl) * ch);
    for (uint32_t i = n; i < nl; i++)
        memcpy(&layered.data[i * ch], img.data, sizeof(float) * ch);
    struct sb_probe_layout terrain = {.grid = {2, 2, 2},
                                      .origin_m = {-1, 0, 2},
                                      .spacing_m = {12.5f, 20, 12.5f},
                                      .ray_count = 512,
                                      .layer_count = 2,
                                      .layers_m = {1.5f, 10}};
    CHECK(sb_probes_write(path, &terrain, &layered, false) == SB_OK, "write layers");
    CHECK(sb_probes_read(path, SB_SKY_VISIBILITY_CHANNELS, 1000, &got, &back) == SB_OK, "read layers back");
    CHECK(got.layer_count == 2 && got.layers_m[0] == 1.5f && got.layers_m[1] == 10 && got.grid[1] == 2 &&
              got.spacing_m[1] == 20 && back.width == nl && !memcmp(back.data, layered.data, sizeof(float) * nl * ch),
          "the layers' round trip is exact");
    sb_image_finish(&back);
    size = read_back(path, bytes, sizeof(bytes));
    CHECK(size == SB_PROBES_HEADER_BYTES_V2 + (size_t)nl * ch * 4 + 8 && bytes[8] == 2, "version 2: size %zu", size);
    check_probes_damage(bytes, size, "a grid in layers");
    struct {
        size_t offset;
        uint32_t value;
        const char *what;
    } layer_fields[] = {
        {104, 3, "more layers than the grid is high"},
        {104, 0, "no layers in version 2"},
        {104, 9, "more layers than the cap"},
        {112, 0x3f800000, "a layer below the one before it"},
        {108, 0x7fc00000, "a NaN height"},
        {108, 0xbf800000, "a negative height"},
        {116, 0x40000000, "a height past the layers"},
        {148, 1, "a reserved byte"},
    };
    for (size_t i = 0; i < sizeof(layer_fields) / sizeof(layer_fields[0]); i++) {
        uint8_t edited[4096];
        memcpy(edited, bytes, size);
        for (int k = 0; k < 4; k++)
            edited[layer_fields[i].offset + k] = (uint8_t)(layer_fields[i].value >> (8 * k));
        restamp(edited, size);
        enum sb_result res = sb_probes_parse(edited, size, "edited", SB_SKY_VISIBILITY_CHANNELS, 1000, &got, &back);
        CHECK(res == SB_ERR_PROBES, "%s: %s", layer_fields[i].what, sb_result_name(res));
        if (res == SB_OK)
            sb_image_finish(&back);
    }

    /* Detail: version 3, its brick columns round-trip, every prefix and
     * bit flip is refused, and so are columns out of order, out of the
     * lattice, or not holding the probes the header says. */
    struct sb_image detailed = {0};
    const uint32_t nd = nl + 16;
    CHECK(sb_image_init(&detailed, nd, 1, ch) == SB_OK, "image");
    sb_image_set_channel_names(&detailed, SB_SKY_VISIBILITY_CHANNELS);
    for (uint32_t i = 0; i < nd; i++)
        memcpy(&detailed.data[i * ch], &layered.data[(i % nl) * ch], sizeof(float) * ch);
    struct sb_probe_column column = {.x = 3, .z = 1, .y0 = 7, .rows = 1};
    struct sb_probe_layout bricks = terrain;
    bricks.detail_spacing_m = 0.5f;
    bricks.detail_origin_m[0] = -4;
    bricks.detail_origin_m[1] = -2;
    bricks.detail_origin_m[2] = 8;
    bricks.detail_count = 16;
    bricks.column_count = 1;
    bricks.columns = &column;
    CHECK(sb_probes_write(path, &bricks, &detailed, false) == SB_OK, "write detail");
    CHECK(sb_probes_read(path, SB_SKY_VISIBILITY_CHANNELS, 1000, &got, &back) == SB_OK, "read detail back");
    CHECK(got.column_count == 1 && got.detail_count == 16 && got.detail_spacing_m == 0.5f &&
              got.detail_origin_m[2] == 8 && got.columns[0].x == 3 && got.columns[0].z == 1 && got.columns[0].y0 == 7 &&
              got.columns[0].rows == 1 && got.layer_count == 2 && back.width == nd &&
              !memcmp(back.data, detailed.data, sizeof(float) * nd * ch),
          "the detail's round trip is exact");
    /* lattice probe (4 * 3 + 1, 7, 4 * 1 + 2): after the grid's, row 0, z 2, x 1 */
    CHECK(sb_probe_detail_index(&got, nl, 13, 7, 6) == nl + 2 * 4 + 1, "a lattice probe's index");
    CHECK(sb_probe_detail_index(&got, nl, 13, 8, 6) == -1 && sb_probe_detail_index(&got, nl, 11, 7, 6) == -1 &&
              sb_probe_detail_index(&got, nl, 13, 7, 3) == -1,
          "lattice probes no column holds");
    struct sb_probe_layout copy;
    CHECK(sb_probe_layout_copy(&copy, &got) == SB_OK && copy.columns != got.columns && copy.columns[0].y0 == 7,
          "a layout's copy owns its columns");
    sb_probe_layout_finish(&copy);
    sb_probe_layout_finish(&got);
    CHECK(!got.columns && !got.column_count, "finished");
    sb_image_finish(&back);
    size = read_back(path, bytes, sizeof(bytes));
    CHECK(size == SB_PROBES_HEADER_BYTES + SB_PROBES_COLUMN_BYTES + (size_t)nd * ch * 4 + 8 && bytes[8] == 3,
          "version 3: size %zu", size);
    check_probes_damage(bytes, size, "detail");
    static const struct field_edit detail_fields[] = {
        {140, 0, "a zero spacing"},
        {140, 0x7fc00000, "a NaN spacing"},
        {144, 0x7f800000, "an infinite origin"},
        {156, 0, "no brick columns in version 3"},
        {160, 32, "more detail probes than the columns hold"},
        {164, 1, "a reserved byte"},
        {SB_PROBES_HEADER_BYTES, 0xffffffff, "a column left of the lattice"},
        {SB_PROBES_HEADER_BYTES + 4, 1u << 14, "a column past the lattice"},
        {SB_PROBES_HEADER_BYTES + 8, 65536, "rows past the lattice"},
        {SB_PROBES_HEADER_BYTES + 12, 0, "a column of no rows"},
        {SB_PROBES_HEADER_BYTES + 12, 2, "a column holding more than the header says"},
    };
    check_edits(bytes, size, detail_fields, sizeof(detail_fields) / sizeof(detail_fields[0]), SB_ERR_PROBES);
    /* two columns, the second before the first */
    struct sb_probe_column two[2] = {{.x = 2, .z = 1, .y0 = 0, .rows = 1}, {.x = 1, .z = 1, .y0 = 0, .rows = 1}};
    struct sb_image wide = {0};
    CHECK(sb_image_init(&wide, nl + 32, 1, ch) == SB_OK, "image");
    sb_image_set_channel_names(&wide, SB_SKY_VISIBILITY_CHANNELS);
    for (uint32_t i = 0; i < nl + 32; i++)
        memcpy(&wide.data[i * ch], &layered.data[(i % nl) * ch], sizeof(float) * ch);
    bricks.columns = two;
    bricks.column_count = 2;
    bricks.detail_count = 32;
    CHECK(sb_probes_write(path, &bricks, &wide, false) == SB_OK, "write two columns");
    enum sb_result unordered = sb_probes_read(path, SB_SKY_VISIBILITY_CHANNELS, 1000, &got, &back);
    CHECK(unordered == SB_ERR_PROBES, "columns out of order: %s", sb_result_name(unordered));
    two[0].x = 1;
    two[1].x = 2;
    CHECK(sb_probes_write(path, &bricks, &wide, false) == SB_OK &&
              sb_probes_read(path, SB_SKY_VISIBILITY_CHANNELS, 1000, &got, &back) == SB_OK &&
              sb_probe_detail_index(&got, nl, 8, 0, 4) == nl + 16,
          "columns in order: the second's first probe follows the first's");
    sb_probe_layout_finish(&got);
    sb_image_finish(&back);
    sb_image_finish(&wide);

    /* Detail with its sight masks: version 4, the masks round-trip and
     * count in the content hash (a layout without hashes as its records
     * alone), every prefix and bit flip is refused, and so are another
     * mask size and a reserved byte. */
    uint32_t sight[16 * SB_PROBES_SIGHT_WORDS];
    for (uint32_t i = 0; i < 16 * SB_PROBES_SIGHT_WORDS; i++)
        sight[i] = 0x9E3779B9u * (i + 1);
    bricks.columns = &column;
    bricks.column_count = 1;
    bricks.detail_count = 16;
    bricks.sight = sight;
    CHECK(sb_probes_write(path, &bricks, &detailed, false) == SB_OK, "write detail with sight masks");
    CHECK(sb_probes_read(path, SB_SKY_VISIBILITY_CHANNELS, 1000, &got, &back) == SB_OK && got.sight &&
              !memcmp(got.sight, sight, sizeof(sight)) && got.column_count == 1 &&
              !memcmp(back.data, detailed.data, sizeof(float) * nd * ch),
          "the sight masks' round trip is exact");
    char with_sight[SB_HASH_HEX_SIZE], without_sight[SB_HASH_HEX_SIZE], records[SB_HASH_HEX_SIZE],
        flipped[SB_HASH_HEX_SIZE];
    sb_probes_content_hash(&back, &got, with_sight);
    got.sight[37] ^= 1u << 9;
    sb_probes_content_hash(&back, &got, flipped);
    sb_image_content_hash(&back, records);
    CHECK(sb_probe_layout_copy(&copy, &got) == SB_OK && copy.sight != got.sight && copy.sight[37] == got.sight[37],
          "a layout's copy owns its sight masks");
    sb_probe_layout_finish(&copy);
    sb_probe_layout_finish(&got);
    CHECK(!got.sight, "finished");
    sb_probes_content_hash(&back, &got, without_sight);
    CHECK(strcmp(with_sight, flipped) != 0 && strcmp(with_sight, records) != 0 && !strcmp(without_sight, records),
          "the content hash covers the sight masks, and is the records' without them");
    sb_image_finish(&back);
    size = read_back(path, bytes, sizeof(bytes));
    CHECK(size == SB_PROBES_HEADER_BYTES + SB_PROBES_COLUMN_BYTES + sizeof(sight) + (size_t)nd * ch * 4 + 8 &&
              bytes[8] == 4,
          "version 4: size %zu", size);
    check_probes_damage(bytes, size, "sight masks");
    static const struct field_edit sight_fields[] = {
        {164, 4, "masks of 4 samples an axis"}, {164, 0, "no mask size"}, {168, 1, "a reserved byte"}};
    check_edits(bytes, size, sight_fields, sizeof(sight_fields) / sizeof(sight_fields[0]), SB_ERR_PROBES);

    /* Values as binary16: version 5, with detail and masks or without
     * any; values binary16 does not hold exactly are refused on writing;
     * the round trip is exact; every prefix and bit flip is refused, and
     * so are other value sizes, masks without detail and detail fields
     * without columns. */
    int64_t not_half;
    CHECK(sb_probes_write(path, &bricks, &detailed, true) == SB_ERR_NUMERIC, "values binary16 does not hold");
    CHECK(sb_image_round_to_half(&detailed, &not_half) == SB_OK, "round to binary16");
    CHECK(sb_probes_write(path, &bricks, &detailed, true) == SB_OK &&
              sb_probes_read(path, SB_SKY_VISIBILITY_CHANNELS, 1000, &got, &back) == SB_OK && got.half && got.sight &&
              !memcmp(got.sight, sight, sizeof(sight)) && !memcmp(back.data, detailed.data, sizeof(float) * nd * ch),
          "binary16 with detail: the round trip is exact");
    sb_probe_layout_finish(&got);
    sb_image_finish(&back);
    size = read_back(path, bytes, sizeof(bytes));
    CHECK(size == SB_PROBES_HEADER_BYTES + SB_PROBES_COLUMN_BYTES + sizeof(sight) + (size_t)nd * ch * 2 + 8 &&
              bytes[8] == 5,
          "version 5: size %zu", size);
    check_probes_damage(bytes, size, "binary16 with detail");
    static const struct field_edit half_fields[] = {{168, 4, "values of 4 bytes in version 5"},
                                                    {168, 0, "no value size"},
                                                    {172, 1, "a reserved byte"},
                                                    {156, 0, "detail fields without columns"}};
    check_edits(bytes, size, half_fields, sizeof(half_fields) / sizeof(half_fields[0]), SB_OK);
    struct sb_probe_layout plain = terrain; /* layers, no detail */
    CHECK(sb_image_round_to_half(&layered, &not_half) == SB_OK &&
              sb_probes_write(path, &plain, &layered, true) == SB_OK &&
              sb_probes_read(path, SB_SKY_VISIBILITY_CHANNELS, 1000, &got, &back) == SB_OK && got.half &&
              !got.column_count && !got.sight && got.layer_count == terrain.layer_count &&
              !memcmp(back.data, layered.data, sizeof(float) * nl * ch),
          "binary16 without detail: the round trip is exact");
    sb_probe_layout_finish(&got);
    sb_image_finish(&back);
    size = read_back(path, bytes, sizeof(bytes));
    CHECK(size == SB_PROBES_HEADER_BYTES + (size_t)nl * ch * 2 + 8 && bytes[8] == 5, "version 5 without detail: %zu",
          size);
    check_probes_damage(bytes, size, "binary16 without detail");
    CHECK(parse_edited(bytes, size, &(struct field_edit){164, 8, "sight masks without detail"}) == SB_ERR_PROBES,
          "sight masks without detail");

    /* Tiles: version 6, the tiles the probes fall in (sb_probe_tiles_assign:
     * the grid's columns and the detail's brick column, 10 m squares from
     * 0), their keys and contents round-trip, a tile left unbaked holds
     * zeros; every prefix and bit flip is refused, and so are tiles that
     * do not match the probes, a content that does not hash, an unbaked
     * tile with a key or with values, and hostile sides and reaches. */
    struct sb_probe_layout tiled;
    uint32_t tile_of[nd];
    CHECK(sb_probe_layout_copy(&tiled, &bricks) == SB_OK, "copy");
    CHECK(sb_probe_tiles_assign(&tiled, 10.0f, tile_of) == SB_OK && tiled.tile_count == 5 && tiled.tile_m == 10.0f,
          "the probes fall in 5 tiles of 10 m (%u)", tiled.tile_count);
    /* the grid's x -1 and 11.5, z 2 and 14.5: tiles x -1 and 1, z 0 and 1;
     * the detail's brick column starts at x 2, z 10: tile 0, 1 */
    CHECK(tiled.tiles[0].x == -1 && tiled.tiles[0].z == 0 && tiled.tiles[0].probes == 2 && tiled.tiles[3].x == 0 &&
              tiled.tiles[3].z == 1 && tiled.tiles[3].probes == 16 && tile_of[nl] == 3 && tile_of[1] == 1,
          "tiles in increasing z then x, each probe's");
    tiled.reach_m = 32;
    for (uint32_t i = 0; i < nd; i++) /* the last tile (x 1, z 1) left unbaked */
        if (tile_of[i] == 4)
            memset(&detailed.data[i * ch], 0, sizeof(float) * ch);
    for (uint32_t t = 0; t < tiled.tile_count; t++) {
        if (t == 4)
            continue;
        tiled.tiles[t].flags = SB_PROBES_TILE_BAKED;
        snprintf(tiled.tiles[t].key, sizeof(tiled.tiles[t].key), "%032x", 0xabc0u + t);
        uint32_t mine[nd], n_mine = 0;
        for (uint32_t i = 0; i < nd; i++)
            if (tile_of[i] == t)
                mine[n_mine++] = i;
        tiled.tiles[t].content = sb_probe_tile_content(&tiled, &detailed, false, mine, n_mine);
    }
    CHECK(sb_probes_write(path, &tiled, &detailed, false) == SB_OK &&
              sb_probes_read(path, SB_SKY_VISIBILITY_CHANNELS, 1000, &got, &back) == SB_OK && got.tile_count == 5 &&
              !memcmp(got.tiles, tiled.tiles, 5 * sizeof(*got.tiles)) && got.reach_m == 32 && !got.half &&
              !memcmp(back.data, detailed.data, sizeof(float) * nd * ch) && !memcmp(got.sight, sight, sizeof(sight)),
          "tiles: the round trip is exact");
    CHECK(sb_probe_layout_copy(&copy, &got) == SB_OK && copy.tiles != got.tiles && copy.tiles[3].probes == 16,
          "a layout's copy owns its tiles");
    sb_probe_layout_finish(&copy);
    sb_probe_layout_finish(&got);
    CHECK(!got.tiles && !got.tile_count, "finished");
    sb_image_finish(&back);
    size = read_back(path, bytes, sizeof(bytes));
    size_t tiles_at = SB_PROBES_HEADER_BYTES + SB_PROBES_COLUMN_BYTES;
    CHECK(size == tiles_at + 5 * SB_PROBES_TILE_BYTES + sizeof(sight) + (size_t)nd * ch * 4 + 8 && bytes[8] == 6,
          "version 6: size %zu", size);
    check_probes_damage(bytes, size, "tiles");
    size_t values_at = tiles_at + 5 * SB_PROBES_TILE_BYTES + sizeof(sight);
    const struct field_edit tile_fields[] = {
        {172, 0, "tiles of 0 m"},
        {172, 0x7fc00000, "tiles of NaN m"},
        {176, 0, "rays reaching 0 m"},
        {180, 0, "no tiles"},
        {180, 4, "fewer tiles than the probes fall in"},
        {184, 1, "a reserved byte"},
        {40, 1, "an explicit probe"},
        {tiles_at, 5, "a tile elsewhere"},
        {tiles_at + 8, 3, "a tile holding other probes"},
        {tiles_at + 12, 2, "an undefined flag"},
        {tiles_at + 32, 7, "a content that does not hash"},
        {tiles_at + 4 * SB_PROBES_TILE_BYTES + 16, 1, "an unbaked tile with a key"},
        {tiles_at + 4 * SB_PROBES_TILE_BYTES + 32, 1, "an unbaked tile with a content"},
        {values_at + (size_t)1 * ch * 4 + 11 * 4, 0x3e123457, "a value in a baked tile, its content not rehashed"},
        {values_at + (size_t)(nl - 1) * ch * 4 + 6 * 4, 0x3f800000, "a value in an unbaked tile"},
    };
    check_edits(bytes, size, tile_fields, sizeof(tile_fields) / sizeof(tile_fields[0]), SB_OK);
    CHECK(parse_edited(bytes, size, &(struct field_edit){168, 2, "values of 2 bytes with 4 stored"}) != SB_OK &&
              parse_edited(bytes, size, &(struct field_edit){168, 3, "values of 3 bytes"}) != SB_OK,
          "value sizes");
    struct sb_probe_layout explicit_too = terrain;
    explicit_too.explicit_count = 1;
    CHECK(sb_probe_tiles_assign(&explicit_too, 10.0f, NULL) == SB_ERR_PROBES, "explicit probes have no tile");
    struct sb_probe_layout far = terrain; /* a grid reaching past any tile index: clamped, never a bad cast */
    far.spacing_m[0] = 3e38f;
    far.tiles = NULL;
    CHECK(sb_probe_tiles_assign(&far, 1.0f, NULL) == SB_OK && far.tile_count == 4 && far.tiles[1].x == 1000000000 &&
              sb_probe_tiles_assign(&far, NAN, NULL) == SB_ERR_PROBES,
          "a grid past any tile, a side that is not a number");
    sb_probe_layout_finish(&far);
    sb_probe_layout_finish(&tiled);
    sb_image_finish(&detailed);
    sb_image_finish(&layered);
    unlink(path);
    rmdir(dir);
    sb_image_finish(&img);
}

/* The last error logged, for checking what a refusal says. */
static char last_error[512];

static void keep_error(void *user, enum sb_log_level level, const char *msg)
{
    (void)user;
    if (level == SB_LOG_ERROR)
        snprintf(last_error, sizeof(last_error), "%s", msg);
}

/* .cube files: a small one with every keyword, read entry by entry; an
 * identity of the usual 33^3 exact; every prefix of a file refused (but
 * the whole); hostile files refused with the line and the reason. */
static void test_lut3d(void)
{
    static const char small[] = "# a comment\r\nTITLE \"two by two\"\r\n\r\nDOMAIN_MIN 0 0 0\r\nDOMAIN_MAX 1 2 4\r\n"
                                "LUT_3D_SIZE 2\r\n"
                                "0 0 0\r\n1 0 0\r\n0 1 0\r\n1 1 0\r\n0 0 1\r\n1 0 1\r\n0 1 1\r\n  1 1 1  \r\n";
    struct sb_lut3d lut;
    enum sb_result res = sb_lut3d_parse(small, strlen(small), "small.cube", &lut);
    CHECK(res == SB_OK, "small.cube: %s", sb_result_name(res));
    if (!res) {
        CHECK(lut.size == 2 && !strcmp(lut.title, "two by two"), "size %u title '%s'", lut.size, lut.title);
        CHECK(lut.domain_max[1] == 2.0f && lut.domain_max[2] == 4.0f, "domain");
        bool order = true; /* red fastest */
        for (int b = 0; b < 2; b++)
            for (int g = 0; g < 2; g++)
                for (int r = 0; r < 2; r++) {
                    const float *e = lut.rgb + ((b * 2 + g) * 2 + r) * 3;
                    order = order && e[0] == (float)r && e[1] == (float)g && e[2] == (float)b;
                }
        CHECK(order, "entries in red-fastest order");
        sb_lut3d_finish(&lut);
    }
    size_t last = strlen(small) - 5; /* the last entry's final digit */
    int accepted = 0;
    for (size_t n = 0; n < last; n++)
        if (sb_lut3d_parse(small, n, "prefix.cube", &lut) == SB_OK) {
            accepted++;
            sb_lut3d_finish(&lut);
        }
    CHECK(accepted == 0, "%d prefixes of a .cube accepted", accepted);

    char *text = malloc(33 * 33 * 33 * 40 + 64);
    size_t len = (size_t)sprintf(text, "LUT_3D_SIZE 33\n");
    for (int i = 0; i < 33 * 33 * 33; i++)
        len +=
            (size_t)sprintf(text + len, "%.9g %.9g %.9g\n", (i % 33) / 32.0, (i / 33 % 33) / 32.0, (i / 1089) / 32.0);
    res = sb_lut3d_parse(text, len, "identity.cube", &lut);
    CHECK(res == SB_OK && lut.size == 33, "identity.cube: %s", sb_result_name(res));
    bool exact = !res;
    for (int i = 0; exact && i < 33 * 33 * 33; i++)
        exact = lut.rgb[3 * i] == (i % 33) / 32.0f && lut.rgb[3 * i + 2] == (i / 1089) / 32.0f;
    CHECK(exact, "identity.cube's entries exact");
    sb_lut3d_finish(&lut);
    free(text);

    static const struct {
        const char *text, *says;
        enum sb_result result;
    } bad[] = {
        {"", "no LUT_3D_SIZE", SB_ERR_MISSING_FIELD},
        {"0 0 0\n", ":1: an entry before LUT_3D_SIZE", SB_ERR_MISSING_FIELD},
        {"LUT_3D_SIZE 1\n0 0 0\n", ":1: LUT_3D_SIZE must be", SB_ERR_OUT_OF_RANGE},
        {"LUT_3D_SIZE 2.5\n", ":1: LUT_3D_SIZE must be", SB_ERR_OUT_OF_RANGE},
        {"LUT_3D_SIZE 4096\n", ":1: LUT_3D_SIZE must be", SB_ERR_TOO_LARGE},
        {"LUT_3D_SIZE 2\nLUT_3D_SIZE 2\n", ":2: LUT_3D_SIZE given twice", SB_ERR_DUPLICATE_KEY},
        {"LUT_1D_SIZE 1024\n", ":1: a 1D LUT", SB_ERR_BAD_IMAGE},
        {"LUT_3D_SIZE 2\nGAMMA 2.2\n", ":2: unknown keyword 'GAMMA'", SB_ERR_UNKNOWN_KEY},
        {"TITLE unquoted\nLUT_3D_SIZE 2\n", ":1: TITLE needs one quoted string", SB_ERR_OUT_OF_RANGE},
        {"DOMAIN_MIN 0 0\nLUT_3D_SIZE 2\n", ":1: DOMAIN_MIN needs three numbers", SB_ERR_OUT_OF_RANGE},
        {"DOMAIN_MIN 1 0 0\nDOMAIN_MAX 1 1 1\nLUT_3D_SIZE 2\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n",
         "not below its maximum", SB_ERR_OUT_OF_RANGE},
        {"DOMAIN_MIN 0 0 0\nLUT_3D_INPUT_RANGE 0 1\n", ":2: LUT_3D_INPUT_RANGE with", SB_ERR_DUPLICATE_KEY},
        {"LUT_3D_SIZE 2\n", "0 entries; LUT_3D_SIZE 2 needs 8", SB_ERR_OUT_OF_RANGE},
        {"LUT_3D_SIZE 2\n0 0 0\n", "1 entries; LUT_3D_SIZE 2 needs 8", SB_ERR_OUT_OF_RANGE},
        {"LUT_3D_SIZE 2\n0 0 nan\n", ":2: an entry must be three numbers within", SB_ERR_OUT_OF_RANGE},
        {"LUT_3D_SIZE 2\n0 0 1e999\n", ":2: an entry must be three numbers within", SB_ERR_OUT_OF_RANGE},
        {"LUT_3D_SIZE 2\n0 0 6e80\n", ":2: an entry must be three numbers within", SB_ERR_OUT_OF_RANGE},
        {"LUT_3D_SIZE 2\n0 0 0 0\n", ":2: an entry must be three numbers within", SB_ERR_OUT_OF_RANGE},
        {"LUT_3D_SIZE 2\n0 0\n0\n", ":2: an entry must be three numbers within", SB_ERR_OUT_OF_RANGE},
        {"LUT_3D_SIZE 2\n0 0 0x\n", ":2: an entry must be three numbers within", SB_ERR_OUT_OF_RANGE},
        {"LUT_3D_SIZE 2\n0 0 0\ninf 0 0\n", ":3: an entry must be three numbers within", SB_ERR_OUT_OF_RANGE},
        {"LUT_3D_SIZE 2\nnan 0 0\n", ":2: an entry must be three numbers within", SB_ERR_OUT_OF_RANGE},
        {"LUT_3D_SIZE 2\n0 0 0\nTITLE \"late\"\n", ":3: a keyword after the table's first entry", SB_ERR_OUT_OF_RANGE},
    };
    sb_log_set_sink(keep_error, NULL);
    for (size_t i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
        last_error[0] = '\0';
        res = sb_lut3d_parse(bad[i].text, strlen(bad[i].text), "bad.cube", &lut);
        CHECK(res == bad[i].result && strstr(last_error, "bad.cube") && strstr(last_error, bad[i].says) && !lut.rgb &&
                  !lut.size,
              "bad .cube %zu: %s, '%s' (wanted %s, '%s')", i, sb_result_name(res), last_error,
              sb_result_name(bad[i].result), bad[i].says);
    }
    /* A NUL byte, a line past the cap, more entries than the size makes */
    static const char nul[] = "LUT_3D_SIZE 2\n\0";
    res = sb_lut3d_parse(nul, sizeof(nul) - 1, "bad.cube", &lut);
    CHECK(res == SB_ERR_BAD_IMAGE && strstr(last_error, "NUL"), "a NUL byte: %s", sb_result_name(res));
    char longline[400] = "LUT_3D_SIZE 2\n0 0 ";
    memset(longline + strlen(longline), '0', 300);
    res = sb_lut3d_parse(longline, strlen(longline), "bad.cube", &lut);
    CHECK(res == SB_ERR_OUT_OF_RANGE && strstr(last_error, ":2: a line of"), "a long line: %s", sb_result_name(res));
    char more[256] = "LUT_3D_SIZE 2\n";
    for (int i = 0; i < 9; i++)
        strcat(more, "0.5 0.5 0.5\n");
    res = sb_lut3d_parse(more, strlen(more), "bad.cube", &lut);
    CHECK(res == SB_ERR_OUT_OF_RANGE && strstr(last_error, ":10: more than the 8 entries"), "nine entries: %s",
          sb_result_name(res));
    CHECK(sb_lut3d_load("/nonexistent/x.cube", &lut) == SB_ERR_IO && strstr(last_error, "/nonexistent/x.cube"),
          "a missing file");
    if (!getenv("SKYBAKE_TEST_VERBOSE"))
        sb_log_set_sink(quiet, NULL);
    else
        sb_log_set_sink(NULL, NULL);
}

/* ---- the parsing child (formats/sandbox.h) ---------------------------------------------- */

static double seconds_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* ---- the sandbox: this program is its own helper (main) -------------------------------- */

static pthread_mutex_t held_by_the_caller = PTHREAD_MUTEX_INITIALIZER;

static int answer(int fd)
{
    uint32_t answer[2] = {7, 11};
    return write(fd, answer, sizeof(answer)) == (ssize_t)sizeof(answer) ? 0 : 1;
}

/* A grandchild that keeps the pipe's write end (and nothing else the test
 * runner waits on: its output goes to /dev/null) for 10 s. */
static void hold_pipe_a_while(void)
{
    int null = open("/dev/null", O_RDWR);
    dup2(null, 0);
    dup2(null, 1);
    dup2(null, 2);
    sleep(10);
    _exit(0);
}

/* The helper's tasks, by the request's name. */
static int sandbox_task(int fd, const void *request, size_t size)
{
    char name[32] = {0};
    memcpy(name, request, size < sizeof(name) - 1 ? size : sizeof(name) - 1);
    if (!strcmp(name, "answers"))
        return answer(fd);
    if (!strcmp(name, "locks")) {
        /* a lock the caller's threads take all the time: a fork of the
         * caller could hold it for ever, a new program never does */
        pthread_mutex_lock(&held_by_the_caller);
        pthread_mutex_unlock(&held_by_the_caller);
        return answer(fd);
    }
    if (!strcmp(name, "leaves-writer") || !strcmp(name, "sends-half")) {
        /* exits at once with nothing (or half) sent, while a grandchild of
         * its own keeps the pipe's write end open for 10 s: the case where
         * the parent never sees the pipe's end and must notice the exit */
        if (fork() == 0)
            hold_pipe_a_while();
        uint32_t half = 7;
        return name[0] == 's' && write(fd, &half, sizeof(half)) != (ssize_t)sizeof(half);
    }
    if (!strcmp(name, "spins")) {
        volatile uint64_t n = 0;
        while (n != UINT64_MAX)
            n++;
    }
    if (!strcmp(name, "sleeps"))
        sleep(60);
    if (!strcmp(name, "crashes"))
        raise(SIGSEGV);
    return 3;
}

static enum sb_result start_task(struct sb_sandbox *box, const struct sb_sandbox_limits *limits, const char *task)
{
    return sb_sandbox_start(box, limits, "/proc/self/exe", task, strlen(task), -1);
}

static atomic_bool stop_locking;

static void *lock_all_the_time(void *unused)
{
    (void)unused;
    while (!atomic_load(&stop_locking)) {
        pthread_mutex_lock(&held_by_the_caller);
        free(malloc(64));
        pthread_mutex_unlock(&held_by_the_caller);
    }
    return NULL;
}

static void test_sandbox(void)
{
    struct sb_sandbox box;
    uint32_t got[2] = {0};
    char why[160];
    CHECK(start_task(&box, NULL, "answers") == SB_OK, "start");
    CHECK(sb_sandbox_read(&box, got, sizeof(got)) && got[0] == 7 && got[1] == 11, "the answer arrives");
    sb_sandbox_finish(&box, why, sizeof(why)); /* with `why`, it waits for the helper's own exit */
    CHECK(box.reaped && WIFEXITED(box.status) && WEXITSTATUS(box.status) == 0, "the helper is reaped: %s", why);

    /* The static example's hang in CI: a forked child waited for ever on a
     * lock (AddressSanitizer's allocator's) that a thread of the caller (a
     * library's thread pool) held at the fork. The helper is a new program:
     * it answers however busy the caller's threads are with their locks. */
    pthread_t threads[3];
    atomic_store(&stop_locking, false);
    for (int i = 0; i < 3; i++)
        pthread_create(&threads[i], NULL, lock_all_the_time, NULL);
    int answered = 0;
    double t0 = seconds_now();
    for (int i = 0; i < 40; i++) {
        struct sb_sandbox_limits limits = {.wall_seconds = 10};
        if (start_task(&box, &limits, "locks") == SB_OK && sb_sandbox_read(&box, got, sizeof(got)))
            answered++;
        sb_sandbox_finish(&box, NULL, 0);
    }
    atomic_store(&stop_locking, true);
    for (int i = 0; i < 3; i++)
        pthread_join(threads[i], NULL);
    CHECK(answered == 40, "with the caller's threads taking locks, %d of 40 helpers answered (%.1f s)", answered,
          seconds_now() - t0);

    /* The mesh importer's hang in CI: a helper that exits with status 0 but
     * sends nothing, the pipe still held open elsewhere. The default
     * deadline is 60 s; the read must return as soon as the helper is gone. */
    static const struct {
        const char *task;
        const char *why;
    } gone[] = {
        {"leaves-writer", "exited before sending its whole answer"},
        {"sends-half", "exited before sending its whole answer"},
        {"crashes", "crashed"},
    };
    for (size_t i = 0; i < sizeof(gone) / sizeof(gone[0]); i++) {
        t0 = seconds_now();
        CHECK(start_task(&box, NULL, gone[i].task) == SB_OK, "start");
        bool read = sb_sandbox_read(&box, got, sizeof(got));
        double took = seconds_now() - t0;
        sb_sandbox_finish(&box, why, sizeof(why));
        CHECK(!read, "a helper that %s: the read fails", gone[i].task);
        CHECK(took < 5.0, "a helper that %s: the parent returns in %.2f s, not at its deadline", gone[i].task, took);
        CHECK(strstr(why, gone[i].why), "a helper that %s: \"%s\"", gone[i].task, why);
    }

    t0 = seconds_now();
    CHECK(start_task(&box, &(struct sb_sandbox_limits){.cpu_seconds = 1}, "spins") == SB_OK, "start");
    CHECK(!sb_sandbox_read(&box, got, sizeof(got)), "a helper that spins: no answer");
    sb_sandbox_finish(&box, why, sizeof(why));
    CHECK(strstr(why, "1 s of CPU time") && seconds_now() - t0 < 15, "a helper that spins: \"%s\" after %.1f s", why,
          seconds_now() - t0);

    t0 = seconds_now();
    CHECK(start_task(&box, &(struct sb_sandbox_limits){.wall_seconds = 1}, "sleeps") == SB_OK, "start");
    CHECK(!sb_sandbox_read(&box, got, sizeof(got)), "a helper that sleeps: no answer");
    sb_sandbox_finish(&box, why, sizeof(why));
    CHECK(strstr(why, "within 1 s") && seconds_now() - t0 < 5, "a helper that sleeps: \"%s\" after %.1f s", why,
          seconds_now() - t0);
    sb_sandbox_finish(&box, why, sizeof(why)); /* twice is harmless */

    /* A helper that is not there, or of another build, is an error naming it. */
    CHECK(sb_sandbox_start(&box, NULL, "/nonexistent/skybake-helper", "answers", 7, -1) == SB_ERR_IO,
          "a missing helper is refused");
    int status = -1;
    pid_t pid = fork();
    if (pid == 0) {
        int null = open("/dev/null", O_WRONLY);
        dup2(null, 2);
        char *argv[] = {"/proc/self/exe", "skybake-sandbox-1/0.0", "1", "1", NULL};
        execv(argv[0], argv);
        _exit(127);
    }
    waitpid(pid, &status, 0);
    CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 2, "a helper started by another build refuses (status %d)",
          status);
}

/* Every reader of a named file refuses a FIFO (which blocks an ordinary
 * open until a writer comes) at once, naming it, instead of hanging. */
static void alarm_fifo(int signal)
{
    (void)signal;
    static const char message[] = "test_formats: a reader blocked on a FIFO\n";
    (void)!write(2, message, sizeof(message) - 1);
    _exit(1);
}

static void test_fifos(void)
{
    char dir[256], fifo[300], pack[300], manifest[340];
    CHECK(test_temp_dir("skybake-fifo", dir, sizeof(dir)), "a temporary directory");
    snprintf(fifo, sizeof(fifo), "%s/fifo.json", dir);
    snprintf(pack, sizeof(pack), "%s/pack", dir);
    snprintf(manifest, sizeof(manifest), "%s/pack/manifest.json", dir);
    CHECK(mkfifo(fifo, 0600) == 0 && mkdir(pack, 0700) == 0 && mkfifo(manifest, 0600) == 0, "the FIFOs");
    signal(SIGALRM, alarm_fifo);
    alarm(60);
    struct sb_scene scene;
    CHECK(sb_scene_load(fifo, &scene) == SB_ERR_IO, "a scene that is a FIFO");
    struct sb_pack p;
    CHECK(sb_pack_open(pack, &p) != SB_OK, "a pack whose manifest is a FIFO");
    struct sb_lut3d lut;
    CHECK(sb_lut3d_load(fifo, &lut) == SB_ERR_IO, "a grade LUT that is a FIFO");
    struct sb_image image;
    struct sb_probe_layout layout;
    CHECK(sb_probes_read(fifo, "a", 0, &layout, &image) == SB_ERR_IO, "probes that are a FIFO");
    CHECK(sb_exr_read(fifo, "r", 0, &image, NULL, NULL) == SB_ERR_IO, "an EXR that is a FIFO");
    CHECK(sb_vdb_read(fifo, "a", 0, &image, NULL, NULL) == SB_ERR_IO, "a VDB that is a FIFO");
    char hash[SB_HASH_HEX_SIZE];
    CHECK(sb_hash_file(AT_FDCWD, fifo, hash) == SB_ERR_IO, "hashing a FIFO");
    alarm(0);
    signal(SIGALRM, SIG_DFL);
    unlink(manifest);
    rmdir(pack);
    unlink(fifo);
    rmdir(dir);
}

int main(int argc, char **argv)
{
    if (argc > 1) /* started by test_sandbox as its helper */
        return sb_sandbox_main(argc, argv, sandbox_task);
    if (!getenv("SKYBAKE_TEST_VERBOSE"))
        sb_log_set_sink(quiet, NULL);
    test_result_codes();
    test_sandbox();
    test_fifos();
    test_exr_round_trip();
    test_exr_cube();
    test_exr_threads();
    test_half();
    test_vdb();
    test_scenes();
    test_pack_reader();
    test_probes();
    test_lut3d();
    return test_finish("formats");
}
