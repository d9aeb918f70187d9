/*
 * libFuzzer entry point: the probe-file parser (probes.h), as a pack reads
 * a sky-visibility artifact (its channels and a cap on probes given). Any
 * input is refused with a code of the closed set or parsed into at most the
 * cap of probes, never a crash.
 */
#include <stdlib.h>

#include "fuzz.h"
#include "log.h"
#include "probes.h"

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    static int quiet;
    if (!quiet++)
        sb_log_set_sink(fuzz_quiet, NULL);
    struct sb_probe_layout layout;
    struct sb_image image;
    const uint32_t cap = 4096;
    enum sb_result res = sb_probes_parse(data, size, "fuzz", SB_SKY_VISIBILITY_CHANNELS, cap, &layout, &image);
    if ((unsigned)res >= SB_RESULT_COUNT)
        abort();
    if (res == SB_OK) {
        if (image.width > cap || image.channel_count != SB_SKY_VISIBILITY_CHANNEL_COUNT)
            abort();
        sb_image_finish(&image);
        sb_probe_layout_finish(&layout); /* detail's columns and sight masks */
    }
    return 0;
}
