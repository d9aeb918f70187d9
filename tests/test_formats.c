/* formats/: EXR round trips, content hashes, scene parsing and validation,
 * packs written and read back, and packs that must be refused. */
#include <cJSON.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "exr.h"
#include "harness.h"
#include "image.h"
#include "log.h"
#include "pack.h"
#include "scene.h"
#include "synthetic_pack.h"

static void quiet(void *user, enum sb_log_level level, const char *msg)
{
    (void)user;
    (void)level;
    (void)msg;
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
    struct sb_exr_attribute attrs[2] = {{"skybake.product", "transmittance"}, {"skybake.content_hash", "abc"}};
    CHECK(sb_exr_write(path, &img, attrs, 2) == SB_OK, "write");
    struct sb_exr_attribute got[SB_EXR_MAX_ATTRIBUTES];
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
    FILE *f = fopen(path, "rb");
    fseek(f, 0, SEEK_END);
    long size = ftell(f);
    rewind(f);
    unsigned char *bytes = malloc(size);
    CHECK(fread(bytes, 1, size, f) == (size_t)size, "read back");
    fclose(f);
    int accepted = 0;
    for (long cut = 0; cut < size; cut += (cut < 512 ? 1 : 97)) {
        f = fopen(path, "wb");
        fwrite(bytes, 1, cut, f);
        fclose(f);
        struct sb_image t;
        if (sb_exr_read(path, "r,g,b", 0, &t, NULL, NULL) == SB_OK) {
            accepted++;
            sb_image_finish(&t);
        }
    }
    CHECK(accepted == 0, "%d truncated files were accepted", accepted);
    free(bytes);
    unlink(path);
    /* The hash sees every value and the shape. */
    img.data[5] = nextafterf(img.data[5], INFINITY);
    sb_image_content_hash(&img, h2);
    CHECK(strcmp(h1, h2) != 0, "one ulp must change the hash");
    sb_image_finish(&img);
    sb_image_finish(&back);
    sb_image_finish(&reordered);
}

struct scene_case {
    const char *json;
    enum sb_result expect;
};

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
        {"{\"atmosphere\":{\"preset\":\"earth\"},\"products\":[\"transmittance\",\"transmittance\"]}", SB_ERR_DUPLICATE_KEY},
        {"\x89PNG\r\n\x1a\n\xff\xfe{[", SB_ERR_JSON_SYNTAX},
        {"{\"atmosphere\":{\"preset\":\"earth}}", SB_ERR_JSON_SYNTAX},
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
}

/* ---- packs ---------------------------------------------------------------------- */

static char pack_root[200];

static void run(const char *command)
{
    CHECK(system(command) == 0, "%s", command);
}

/* Copy the good pack to `bad`, let `edit` change its manifest (may be NULL), and return the code opening it gives. */
static enum sb_result open_edited(const char *good, const char *bad, void (*edit)(cJSON *root), const char *shell)
{
    char cmd[1024];
    snprintf(cmd, sizeof(cmd), "rm -rf '%s' && cp -r '%s' '%s'", bad, good, bad);
    run(cmd);
    if (edit) {
        char path[512];
        snprintf(path, sizeof(path), "%s/manifest.json", bad);
        FILE *f = fopen(path, "rb");
        char *text = calloc(1, 1 << 20);
        size_t n = f ? fread(text, 1, (1 << 20) - 1, f) : 0;
        if (f)
            fclose(f);
        cJSON *root = cJSON_ParseWithLength(text, n);
        free(text);
        CHECK(root != NULL, "manifest parses");
        if (!root)
            return SB_OK;
        edit(root);
        char *out = cJSON_Print(root);
        cJSON_Delete(root);
        f = fopen(path, "wb");
        fputs(out, f);
        fclose(f);
        free(out);
    }
    if (shell) {
        snprintf(cmd, sizeof(cmd), "cd '%s' && %s", bad, shell);
        run(cmd);
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
    cJSON_ReplaceItemInObject(r, "format_version", cJSON_CreateNumber(2));
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
static void edit_artifact_number(cJSON *r)
{
    cJSON_ReplaceItemInArray(cJSON_GetObjectItem(r, "artifacts"), 1, cJSON_CreateNumber(1));
}

static void test_pack_reader(void)
{
    const char *tmp = getenv("TMPDIR");
    snprintf(pack_root, sizeof(pack_root), "%s/skybake-pack-test-%s", tmp && *tmp ? tmp : "/tmp", "XXXXXX");
    CHECK(mkdtemp(pack_root) != NULL, "temporary directory");
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
    CHECK(pack->scene && !strcmp(pack->scene->name, "test") && pack->scene->atmosphere.mie_g == 0.8,
          "the scene reads back");
    sb_pack_close(pack);
    free(pack);

    static const struct {
        const char *what;
        void (*edit)(cJSON *root);
        const char *shell;
        enum sb_result expect;
    } cases[] = {
        {"unchanged copy", NULL, NULL, SB_OK},
        {"unknown format version", edit_version, NULL, SB_ERR_VERSION},
        {"no format version", edit_no_version, NULL, SB_ERR_MISSING_FIELD},
        {"file in the parent directory", edit_parent_path, NULL, SB_ERR_UNSAFE_PATH},
        {"absolute file", edit_absolute_path, NULL, SB_ERR_UNSAFE_PATH},
        {"hidden file", edit_hidden_path, NULL, SB_ERR_UNSAFE_PATH},
        {"artifact that is a symbolic link", NULL, "mv transmittance.exr t.exr && ln -s t.exr transmittance.exr",
         SB_ERR_UNSAFE_PATH},
        {"manifest that is a symbolic link", NULL, "mv manifest.json m && ln -s m manifest.json", SB_ERR_UNSAFE_PATH},
        {"missing artifact", NULL, "rm multiscattering.exr", SB_ERR_IO},
        {"recorded hash differs", edit_hash, NULL, SB_ERR_HASH_MISMATCH},
        {"artifact replaced by another product's file", NULL, "cp irradiance_sky.exr irradiance_ground.exr",
         SB_ERR_BAD_IMAGE},
        {"truncated artifact", NULL, "head -c 3000 transmittance.exr > t && mv t transmittance.exr", SB_ERR_EXR},
        {"one flipped byte in the compressed pixels", NULL,
         "printf '\\x55' | dd of=multiscattering.exr bs=1 seek=$(( $(stat -c %s multiscattering.exr) - 40 )) "
         "conv=notrunc 2>/dev/null",
         SB_ERR_EXR},
        {"width differs from the product's", edit_width, NULL, SB_ERR_BAD_IMAGE},
        {"absurd height", edit_huge, NULL, SB_ERR_BAD_IMAGE},
        {"channels of the wrong type", edit_channels, NULL, SB_ERR_WRONG_TYPE},
        {"pixel type", edit_pixel_type, NULL, SB_ERR_BAD_IMAGE},
        {"device without a name", edit_device, NULL, SB_ERR_MISSING_FIELD},
        {"scene edited", edit_scene_value, NULL, SB_ERR_HASH_MISMATCH},
        {"scene out of range", edit_scene_invalid, NULL, SB_ERR_OUT_OF_RANGE},
        {"no scene", edit_no_scene, NULL, SB_ERR_MISSING_FIELD},
        {"unknown product", edit_unknown, NULL, SB_ERR_UNKNOWN_PRODUCT},
        {"product listed twice", edit_duplicate, NULL, SB_ERR_DUPLICATE_KEY},
        {"manifest is binary garbage", NULL, "printf '\\211PNG\\r\\n\\032\\n\\000\\377{[' > manifest.json",
         SB_ERR_JSON_SYNTAX},
        {"manifest is a truncated object", NULL, "head -c 200 manifest.json > m && mv m manifest.json",
         SB_ERR_JSON_SYNTAX},
        {"manifest is empty", NULL, ": > manifest.json", SB_ERR_JSON_SYNTAX},
        {"manifest over 1 MiB", NULL, "head -c 1100000 /dev/zero | tr '\\\\0' ' ' >> manifest.json",
         SB_ERR_OUT_OF_RANGE},
        {"no manifest", NULL, "rm manifest.json", SB_ERR_IO},
        {"file the manifest does not list", NULL, "echo x > notes.txt", SB_ERR_UNLISTED_FILE},
        {"directory the manifest does not list", NULL, "mkdir sub", SB_ERR_UNLISTED_FILE},
        {"another format", edit_format, NULL, SB_ERR_VERSION},
        {"artifacts not an array", edit_artifacts_type, NULL, SB_ERR_WRONG_TYPE},
        {"artifact entry not an object", edit_artifact_number, NULL, SB_ERR_WRONG_TYPE},
        {"key given twice in the manifest", NULL, "sed -i '0,/\"skybake_version\"/s//\"skybake_version\": \"x\", \"skybake_version\"/' manifest.json",
         SB_ERR_DUPLICATE_KEY},
        {"artifact holding NaN", NULL, "cp ../nan.exr multiscattering.exr", SB_ERR_NUMERIC},
        {"pack directory replaced by a file", NULL, "cd .. && rm -rf bad && echo x > bad", SB_ERR_IO},
    };
    for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
        enum sb_result got = open_edited(good, bad, cases[i].edit, cases[i].shell);
        CHECK(got == cases[i].expect, "pack with %s: got %s, expected %s", cases[i].what, sb_result_name(got),
              sb_result_name(cases[i].expect));
    }
    /* verify goes on past each problem: three of them, each counted. */
    open_edited(good, bad, edit_hash, "rm irradiance_ground.exr && echo x > notes.txt");
    unsigned problems = 0;
    enum sb_result got_code = sb_pack_verify(bad, &problems);
    CHECK(got_code == SB_ERR_HASH_MISMATCH && problems == 3, "verify of a pack with three problems: %s, %u problems",
          sb_result_name(got_code), problems);
    got_code = sb_pack_verify(good, &problems);
    CHECK(got_code == SB_OK && problems == 0, "verify of a good pack: %s, %u problems", sb_result_name(got_code),
          problems);

    /* A well-formed EXR whose pixels differ from what the manifest recorded. */
    open_edited(good, bad, NULL, NULL);
    char path[512];
    snprintf(path, sizeof(path), "%s/transmittance.exr", bad);
    struct sb_image t;
    CHECK(sb_exr_read(path, "r,g,b", 0, &t, NULL, NULL) == SB_OK, "read");
    t.data[7] = nextafterf(t.data[7], 2.0f);
    CHECK(sb_exr_write(path, &t, NULL, 0) == SB_OK, "rewrite");
    sb_image_finish(&t);
    pack = calloc(1, sizeof(*pack));
    enum sb_result got = sb_pack_open(bad, pack);
    CHECK(got == SB_ERR_HASH_MISMATCH, "one ulp changed in a pixel: got %s", sb_result_name(got));
    CHECK(!pack->present[0] && !pack->images[0].data, "a refused pack is left empty");
    free(pack);

    char cmd[512];
    snprintf(cmd, sizeof(cmd), "rm -rf '%s'", pack_root);
    run(cmd);
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
    CHECK(!strcmp(sb_result_name(SB_RESULT_COUNT), "unknown") && !strcmp(sb_result_name((enum sb_result)-1), "unknown"),
          "outside the set: unknown");
}

int main(void)
{
    if (!getenv("SKYBAKE_TEST_VERBOSE"))
        sb_log_set_sink(quiet, NULL);
    test_result_codes();
    test_exr_round_trip();
    test_scenes();
    test_pack_reader();
    return test_finish("formats");
}
