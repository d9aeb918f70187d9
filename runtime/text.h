/*
 * Text into RGBA pixels, for labels on skyview's contact sheets and its
 * on-screen overlays: a built-in 5 x 7 pixel font (the HD44780's shapes),
 * each glyph scaled by a whole factor, so nothing is read at run time. It
 * has digits, lower-case letters (upper case draws as lower case), space and
 * . , : ; - + / ( ) % = _ ' ! ? < > [ ] # * and the degree sign (UTF-8 °);
 * anything else draws as '?'.
 */
#ifndef SB_RUNTIME_TEXT_H
#define SB_RUNTIME_TEXT_H

#include <stdint.h>

#define SB_TEXT_GLYPH_W 5
#define SB_TEXT_GLYPH_H 7
#define SB_TEXT_ADVANCE 6 /* a glyph and one column of space, before scaling */

/* Width in pixels of `text` at `scale` (its last glyph's trailing space
 * excluded). */
uint32_t sb_text_width(const char *text, uint32_t scale);

/* Draw `text` with its top-left corner at (x, y) in an RGBA image of
 * width x height pixels (top row first), each glyph pixel scale x scale
 * pixels of `rgba`; pixels outside the image are skipped. */
void sb_text_draw(uint8_t *image, uint32_t width, uint32_t height, int x, int y, uint32_t scale, const char *text,
                  const uint8_t rgba[4]);

#endif
