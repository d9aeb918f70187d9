/*
 * 8-bit sRGB PNG files through libpng's simplified API: what skyview writes
 * for people to look at, and what its tests read back.
 */
#ifndef SB_PNG_H
#define SB_PNG_H

#include <stdint.h>

#include "result.h"

/* Write width x height RGBA pixels (top row first) to `path`, through a
 * temporary file renamed into place. SB_ERR_IO, naming the path, on failure. */
enum sb_result sb_png_write(const char *path, uint32_t width, uint32_t height, const uint8_t *rgba);

#endif
