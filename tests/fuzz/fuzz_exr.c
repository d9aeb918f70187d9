/*
 * libFuzzer entry point: the EXR reader, as a pack reads an artifact (its
 * channels and a cap on pixels given). Any input is refused with a code of
 * the closed set or read into an image of at most the cap, never a crash.
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
        snprintf(path, sizeof(path), "/tmp/skybake-fuzz-exr-%ld.exr", (long)getpid());
    }
    fuzz_write(path, data, size);
    struct sb_image image;
    const uint64_t cap = 4096;
    enum sb_result res = sb_exr_read(path, "r,g,b", cap, &image, NULL, NULL);
    if ((unsigned)res >= SB_RESULT_COUNT)
        abort();
    if (res == SB_OK) {
        if ((uint64_t)image.width * image.height > cap || image.channel_count != 3)
            abort();
        sb_image_finish(&image);
    }
    unlink(path);
    return 0;
}
