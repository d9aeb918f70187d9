/*
 * 3D colour lookup tables from .cube files, as Adobe's Cube LUT
 * Specification 1.0 defines them and DaVinci Resolve writes them: keywords
 * (TITLE, LUT_3D_SIZE, DOMAIN_MIN, DOMAIN_MAX, or Resolve's older
 * LUT_3D_INPUT_RANGE), then N^3 lines of "R G B", red changing fastest.
 * A file that breaks a rule is refused with its name, line and reason.
 */
#ifndef SB_LUT3D_H
#define SB_LUT3D_H

#include <stddef.h>
#include <stdint.h>

#include "result.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SB_LUT3D_MIN_SIZE 2
#define SB_LUT3D_MAX_SIZE 128           /* 25 MB of floats; the spec's 256 would be 200 */
#define SB_LUT3D_MAX_BYTES (128u << 20) /* 128^3 lines of three numbers with room to spare */

struct sb_lut3d {
    uint32_t size;                      /* N: N^3 entries */
    float domain_min[3], domain_max[3]; /* the input range, per channel (default 0 and 1) */
    float *rgb;                         /* N^3 RGB triples, red fastest, then green, then blue */
    char title[128];                    /* TITLE, empty without one */
};

/* Parse `size` bytes of .cube text; errors name `source`. On failure
 * *lut is empty. */
enum sb_result sb_lut3d_parse(const char *text, size_t size, const char *source, struct sb_lut3d *lut);

/* Read and parse the file at `path` (at most SB_LUT3D_MAX_BYTES). */
enum sb_result sb_lut3d_load(const char *path, struct sb_lut3d *lut);

void sb_lut3d_finish(struct sb_lut3d *lut);

#ifdef __cplusplus
}
#endif

#endif
