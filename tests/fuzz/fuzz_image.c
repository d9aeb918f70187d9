/*
 * libFuzzer entry point: an image a model names (geometry/mesh_texture.h),
 * decoded by libpng or libjpeg-turbo as the mesh import's helper does. Any
 * input is refused with a code of the closed set or decoded into texels
 * whose size is within the caps, never a crash.
 */
#include <stdlib.h>
#include <string.h>

#include "fuzz.h"
#include "mesh_texture.h"

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    static int quiet;
    if (!quiet++)
        sb_log_set_sink(fuzz_quiet, NULL);
    struct sb_mesh_texture t = {.name = "fuzz.png"};
    enum sb_result res = sb_texture_decode(data, size, "fuzz.gltf", &t);
    if ((unsigned)res >= SB_RESULT_COUNT)
        abort();
    if (!res) {
        if (!t.rgba || !t.width || !t.height || t.width > SB_TEXTURE_MAX_SIDE || t.height > SB_TEXTURE_MAX_SIDE)
            abort();
        volatile uint8_t last = t.rgba[sb_texture_bytes(&t) - 1]; /* every texel written is readable */
        (void)last;
    } else if (t.rgba) {
        abort();
    }
    free(t.rgba);
    return 0;
}
