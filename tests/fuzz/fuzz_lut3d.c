/*
 * libFuzzer entry point: the .cube reader skyview grades with. Any input
 * gets a code of the closed set, never a crash; an accepted LUT has a size
 * in range, every entry finite and a domain whose minimum lies below its
 * maximum.
 */
#include <math.h>
#include <stdlib.h>

#include "fuzz.h"
#include "log.h"
#include "lut3d.h"

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    sb_log_set_sink(fuzz_quiet, NULL);
    struct sb_lut3d lut;
    enum sb_result res = sb_lut3d_parse((const char *)data, size, "fuzz", &lut);
    if ((unsigned)res >= SB_RESULT_COUNT)
        abort();
    if (res)
        return 0;
    if (lut.size < SB_LUT3D_MIN_SIZE || lut.size > SB_LUT3D_MAX_SIZE || !lut.rgb)
        abort();
    for (size_t i = 0; i < (size_t)lut.size * lut.size * lut.size * 3; i++)
        if (!isfinite(lut.rgb[i]))
            abort();
    for (int c = 0; c < 3; c++)
        if (!(lut.domain_min[c] < lut.domain_max[c]))
            abort();
    sb_lut3d_finish(&lut);
    return 0;
}
