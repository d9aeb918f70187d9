/*
 * libFuzzer entry point: a world file read as a scene's world (level.h),
 * instances and scatters included. The input is written alone into a
 * folder of its own as w.json, so what it places is itself (a cycle), a
 * missing file or a path outside (refused); any input is refused with a
 * code of the closed set or read into a level whose counts add up, never
 * a crash.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "fuzz.h"
#include "level.h"
#include "log.h"
#include "scene.h"

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    static char dir[64], path[96];
    static struct sb_world_params world;
    if (!dir[0]) {
        sb_log_set_sink(fuzz_quiet, NULL);
        snprintf(dir, sizeof(dir), "/tmp/skybake-fuzz-world-%ld", (long)getpid());
        mkdir(dir, 0700);
        snprintf(path, sizeof(path), "%s/w.json", dir);
        snprintf(world.file, sizeof(world.file), "%s", path);
        world.units_m = world.scale = 1;
    }
    fuzz_write(path, data, size);
    struct sb_level level;
    enum sb_result res = sb_level_load(&world, "", &level, NULL, 0);
    if ((unsigned)res >= SB_RESULT_COUNT)
        abort();
    if (res == SB_OK) {
        uint64_t triangles = 0;
        for (uint32_t i = 0; i < level.instance_count; i++) {
            if (level.instances[i].mesh >= level.mesh_count)
                abort();
            triangles += level.meshes[level.instances[i].mesh].triangle_count;
        }
        if (level.instance_count && triangles != level.placed_triangles)
            abort();
        sb_level_finish(&level);
    }
    return 0;
}
