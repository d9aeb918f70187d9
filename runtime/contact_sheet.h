/*
 * A contact sheet: frames laid out in a grid, each with a label strip under
 * it (runtime/text.h's font), as one RGBA image for a quick review of a
 * sequence (skyview's day at fixed hours). The caller owns the struct.
 */
#ifndef SB_RUNTIME_CONTACT_SHEET_H
#define SB_RUNTIME_CONTACT_SHEET_H

#include <stdint.h>

#include "result.h"

struct sb_contact_sheet {
    uint32_t tile_width, tile_height; /* each frame's size */
    uint32_t columns, rows;           /* the grid: near square, columns >= rows */
    uint32_t label_height;            /* the strip under each frame, pixels */
    uint32_t gap;                     /* pixels between cells and around the sheet */
    uint32_t width, height;           /* the sheet's size */
    uint8_t *rgba;                    /* width * height * 4 bytes, top row first */
};

/* A dark sheet with room for `count` frames of tile_width x tile_height;
 * SB_ERR_TOO_LARGE past 16384 pixels a side, SB_ERR_NOMEM. */
enum sb_result sb_contact_sheet_init(struct sb_contact_sheet *sheet, uint32_t tile_width, uint32_t tile_height,
                                     uint32_t count);
/* Copy frame `index` (row-major order in the grid; tile_width x tile_height
 * RGBA) into its cell and write `label` under it (sized for 28 characters
 * across the cell; cut at its width). */
void sb_contact_sheet_put(struct sb_contact_sheet *sheet, uint32_t index, const uint8_t *rgba, const char *label);
void sb_contact_sheet_finish(struct sb_contact_sheet *sheet);

#endif
