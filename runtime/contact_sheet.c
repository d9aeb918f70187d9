#include "contact_sheet.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "text.h"

#define MAX_SIDE 16384
static const uint8_t background[4] = {24, 24, 24, 255};
static const uint8_t ink[4] = {235, 235, 235, 255};

/* The label's scale: glyphs about a twentieth of the frame's height, and
 * LABEL_CHARS of them across it at most; at least 1. */
#define LABEL_CHARS 28
static uint32_t label_scale(uint32_t tile_width, uint32_t tile_height)
{
    uint32_t s = tile_height / (20 * SB_TEXT_GLYPH_H / 2 + 1), across = tile_width / (LABEL_CHARS * SB_TEXT_ADVANCE);
    s = s < across ? s : across;
    return s < 1 ? 1 : s > 6 ? 6 : s;
}

enum sb_result sb_contact_sheet_init(struct sb_contact_sheet *s, uint32_t tile_width, uint32_t tile_height,
                                     uint32_t count)
{
    memset(s, 0, sizeof(*s));
    if (!count || !tile_width || !tile_height)
        return SB_ERR_OUT_OF_RANGE;
    s->tile_width = tile_width;
    s->tile_height = tile_height;
    s->columns = (uint32_t)ceil(sqrt((double)count));
    s->rows = (count + s->columns - 1) / s->columns;
    uint32_t scale = label_scale(tile_width, tile_height);
    s->label_height = (SB_TEXT_GLYPH_H + 4) * scale;
    s->gap = 2 * scale;
    uint64_t w = (uint64_t)s->columns * (tile_width + s->gap) + s->gap;
    uint64_t h = (uint64_t)s->rows * (tile_height + s->label_height + s->gap) + s->gap;
    if (w > MAX_SIDE || h > MAX_SIDE) {
        sb_error("a contact sheet of %u frames of %ux%u would be %llux%llu pixels, past %u a side", count, tile_width,
                 tile_height, (unsigned long long)w, (unsigned long long)h, MAX_SIDE);
        return SB_ERR_TOO_LARGE;
    }
    s->width = (uint32_t)w;
    s->height = (uint32_t)h;
    s->rgba = malloc((size_t)w * h * 4);
    if (!s->rgba)
        return SB_ERR_NOMEM;
    for (size_t i = 0; i < (size_t)w * h; i++)
        memcpy(s->rgba + 4 * i, background, 4);
    return SB_OK;
}

void sb_contact_sheet_put(struct sb_contact_sheet *s, uint32_t index, const uint8_t *rgba, const char *label)
{
    if (index >= s->columns * s->rows)
        return;
    uint32_t x0 = s->gap + index % s->columns * (s->tile_width + s->gap);
    uint32_t y0 = s->gap + index / s->columns * (s->tile_height + s->label_height + s->gap);
    for (uint32_t y = 0; y < s->tile_height; y++)
        memcpy(s->rgba + (((size_t)y0 + y) * s->width + x0) * 4, rgba + (size_t)y * s->tile_width * 4,
               (size_t)s->tile_width * 4);
    /* Draw into a strip the cell's width, so a long label is cut there. */
    uint32_t scale = label_scale(s->tile_width, s->tile_height);
    uint8_t *strip = malloc((size_t)s->tile_width * s->label_height * 4);
    if (!strip)
        return;
    for (size_t i = 0; i < (size_t)s->tile_width * s->label_height; i++)
        memcpy(strip + 4 * i, background, 4);
    sb_text_draw(strip, s->tile_width, s->label_height, 0, (int)(2 * scale), scale, label, ink);
    for (uint32_t y = 0; y < s->label_height; y++)
        memcpy(s->rgba + (((size_t)y0 + s->tile_height + y) * s->width + x0) * 4, strip + (size_t)y * s->tile_width * 4,
               (size_t)s->tile_width * 4);
    free(strip);
}

void sb_contact_sheet_finish(struct sb_contact_sheet *s)
{
    free(s->rgba);
    memset(s, 0, sizeof(*s));
}
