/*
 * libFuzzer entry point: the scene parser. Any input gets a code of the
 * closed set, never a crash; an accepted scene's normalised form parses
 * again to the same form (the hash that names a scene is stable).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz.h"
#include "log.h"
#include "scene.h"

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    sb_log_set_sink(fuzz_quiet, NULL);
    struct sb_scene scene;
    enum sb_result res = sb_scene_parse((const char *)data, size, "fuzz", &scene);
    if ((unsigned)res >= SB_RESULT_COUNT)
        abort();
    if (res)
        return 0;
    char *normal = sb_scene_normalized_json(&scene);
    if (!normal)
        return 0;
    struct sb_scene again;
    if (sb_scene_parse(normal, strlen(normal), "normalised", &again) != SB_OK)
        abort();
    char *normal2 = sb_scene_normalized_json(&again);
    if (!normal2 || strcmp(normal, normal2) != 0)
        abort();
    free(normal);
    free(normal2);
    return 0;
}
