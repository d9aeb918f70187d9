/*
 * libFuzzer entry point: the probe-file parser (probes.h), as a pack reads
 * a sky-visibility artifact and a sun-bounce one (their channels, one byte
 * of the input choosing, and a cap on probes given). Any input is refused
 * with a code of the closed set or parsed into at most the cap of probes,
 * never a crash.
 */
#include <stdbool.h>
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
    /* the file's byte 20 (its channel count's low byte) picks the product:
     * the seeds stay valid files of either */
    bool sun = size > 20 && data[20] == SB_SUN_BOUNCE_CHANNEL_COUNT;
    const char *channels = sun ? SB_SUN_BOUNCE_CHANNELS : SB_SKY_VISIBILITY_CHANNELS;
    uint32_t count = sun ? SB_SUN_BOUNCE_CHANNEL_COUNT : SB_SKY_VISIBILITY_CHANNEL_COUNT;
    enum sb_result res = sb_probes_parse(data, size, "fuzz", channels, cap, &layout, &image);
    if ((unsigned)res >= SB_RESULT_COUNT)
        abort();
    if (res == SB_OK) {
        if (image.width > cap || image.channel_count != count)
            abort();
        sb_image_finish(&image);
        sb_probe_layout_finish(&layout); /* detail's columns and sight masks */
    }
    return 0;
}
