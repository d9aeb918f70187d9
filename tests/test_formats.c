/* formats/: EXR round trips, content hashes, scene parsing and validation. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "exr.h"
#include "harness.h"
#include "image.h"
#include "log.h"
#include "scene.h"

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
    CHECK(back.width == 37 && back.height == 11 && back.channel_count == 3, "shape %ux%ux%u", back.width,
          back.height, back.channel_count);
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
        {"{\"atmosphere\":{\"preset\":\"mars\"}}", SB_ERR_UNKNOWN_PRESET},
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
    };
    for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
        struct sb_scene scene;
        enum sb_result got = sb_scene_parse(cases[i].json, strlen(cases[i].json), "case", &scene);
        CHECK(got == cases[i].expect, "case %zu (%s): got %s, expected %s", i, cases[i].json, sb_result_name(got),
              sb_result_name(cases[i].expect));
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
}

int main(void)
{
    sb_log_set_sink(quiet, NULL);
    test_exr_round_trip();
    test_scenes();
    return test_finish("formats");
}
