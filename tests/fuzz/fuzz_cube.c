/*
 * libFuzzer entry point: the cube EXR reader, as a pack reads
 * reflection_cubes (2 cubes of 8 texels a face, channels R, G, B
 * expected). Any input is refused with a code of the closed set or read
 * into exactly that shape, never a crash.
 */
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "exr.h"
#include "fuzz.h"
#include "log.h"

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    static char path[64];
    if (!path[0]) {
        sb_log_set_sink(fuzz_quiet, NULL);
        snprintf(path, sizeof(path), "/tmp/skybake-fuzz-cube-%ld.exr", (long)getpid());
    }
    fuzz_write(path, data, size);
    struct sb_image image;
    enum sb_result res = sb_exr_cube_read(path, "R,G,B", 8, 2, &image);
    if ((unsigned)res >= SB_RESULT_COUNT)
        abort();
    if (res == SB_OK) {
        if (image.width != 8 || image.height != 48 || image.depth != 2 || image.levels != 4 || image.channel_count != 3)
            abort();
        sb_image_finish(&image);
    }
    unlink(path);
    return 0;
}
