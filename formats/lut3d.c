#include "lut3d.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io.h"
#include "log.h"

#define LUT_MAX_LINE 256
#define LUT_MAX_VALUE 1e6 /* entries and domains: |v| at most this, so fp32 arithmetic on them stays finite */

/* The parser's position, for errors: "source:line: reason". */
struct cursor {
    const char *source;
    unsigned line;
};

#define lut_error(c, fmt, ...) sb_error("%s:%u: " fmt, (c)->source, (c)->line, __VA_ARGS__)

/* `count` numbers from s, nothing after them; false on anything else. */
static bool parse_numbers(const char *s, double *out, int count)
{
    for (int i = 0; i < count; i++) {
        char *end;
        errno = 0;
        out[i] = strtod(s, &end);
        if (end == s || errno == ERANGE || !(fabs(out[i]) <= LUT_MAX_VALUE))
            return false;
        s = end;
    }
    while (*s == ' ' || *s == '\t')
        s++;
    return *s == '\0';
}

static bool keyword_is(const char *line, const char *word, const char **rest)
{
    size_t n = strlen(word);
    if (strncmp(line, word, n) || (line[n] != ' ' && line[n] != '\t' && line[n] != '\0'))
        return false;
    *rest = line + n;
    return true;
}

enum { SEEN_TITLE = 1, SEEN_MIN = 2, SEEN_MAX = 4, SEEN_RANGE = 8 };

/* False, with an error, when the keyword `bit` stands for was given before,
 * or the domain both ways. */
static bool first_time(struct cursor *c, const char *word, unsigned bit, unsigned *seen)
{
    unsigned clash = bit == SEEN_RANGE ? SEEN_MIN | SEEN_MAX : bit & (SEEN_MIN | SEEN_MAX) ? SEEN_RANGE : 0;
    if (*seen & (bit | clash)) {
        lut_error(c, "%s %s", word,
                  *seen & bit ? "given twice" : "with DOMAIN_MIN/DOMAIN_MAX and LUT_3D_INPUT_RANGE both");
        return false;
    }
    *seen |= bit;
    return true;
}

static enum sb_result parse_keyword(struct cursor *c, const char *line, struct sb_lut3d *lut, unsigned *seen)
{
    const char *rest;
    double v[3];
    if (keyword_is(line, "TITLE", &rest)) {
        if (!first_time(c, "TITLE", SEEN_TITLE, seen))
            return SB_ERR_DUPLICATE_KEY;
        while (*rest == ' ' || *rest == '\t')
            rest++;
        size_t n = strlen(rest);
        if (n < 2 || rest[0] != '"' || rest[n - 1] != '"' || memchr(rest + 1, '"', n - 2)) {
            lut_error(c, "%s", "TITLE needs one quoted string");
            return SB_ERR_OUT_OF_RANGE;
        }
        snprintf(lut->title, sizeof(lut->title), "%.*s", (int)(n - 2), rest + 1);
        return SB_OK;
    }
    if (keyword_is(line, "LUT_3D_SIZE", &rest)) {
        if (lut->size) {
            lut_error(c, "%s", "LUT_3D_SIZE given twice");
            return SB_ERR_DUPLICATE_KEY;
        }
        if (!parse_numbers(rest, v, 1) || v[0] != floor(v[0]) || v[0] < SB_LUT3D_MIN_SIZE || v[0] > SB_LUT3D_MAX_SIZE) {
            lut_error(c, "LUT_3D_SIZE must be a whole number from %d to %d", SB_LUT3D_MIN_SIZE, SB_LUT3D_MAX_SIZE);
            return v[0] > SB_LUT3D_MAX_SIZE ? SB_ERR_TOO_LARGE : SB_ERR_OUT_OF_RANGE;
        }
        lut->size = (uint32_t)v[0];
        return SB_OK;
    }
    if (keyword_is(line, "LUT_1D_SIZE", &rest) || keyword_is(line, "LUT_1D_INPUT_RANGE", &rest)) {
        lut_error(c, "%s", "a 1D LUT; skyview grades through a 3D LUT (LUT_3D_SIZE)");
        return SB_ERR_BAD_IMAGE;
    }
    bool min = keyword_is(line, "DOMAIN_MIN", &rest), max = !min && keyword_is(line, "DOMAIN_MAX", &rest);
    if (min || max) {
        if (!first_time(c, min ? "DOMAIN_MIN" : "DOMAIN_MAX", min ? SEEN_MIN : SEEN_MAX, seen))
            return SB_ERR_DUPLICATE_KEY;
        if (!parse_numbers(rest, v, 3)) {
            lut_error(c, "%s needs three numbers within +-1e6", min ? "DOMAIN_MIN" : "DOMAIN_MAX");
            return SB_ERR_OUT_OF_RANGE;
        }
        for (int i = 0; i < 3; i++)
            (min ? lut->domain_min : lut->domain_max)[i] = (float)v[i];
        return SB_OK;
    }
    if (keyword_is(line, "LUT_3D_INPUT_RANGE", &rest)) {
        if (!first_time(c, "LUT_3D_INPUT_RANGE", SEEN_RANGE, seen))
            return SB_ERR_DUPLICATE_KEY;
        if (!parse_numbers(rest, v, 2)) {
            lut_error(c, "%s", "LUT_3D_INPUT_RANGE needs two numbers within +-1e6");
            return SB_ERR_OUT_OF_RANGE;
        }
        for (int i = 0; i < 3; i++) {
            lut->domain_min[i] = (float)v[0];
            lut->domain_max[i] = (float)v[1];
        }
        return SB_OK;
    }
    int n = 0;
    while (n < 32 && line[n] && line[n] != ' ' && line[n] != '\t')
        n++;
    lut_error(c, "unknown keyword '%.*s' (TITLE, LUT_3D_SIZE, DOMAIN_MIN, DOMAIN_MAX, LUT_3D_INPUT_RANGE)", n, line);
    return SB_ERR_UNKNOWN_KEY;
}

enum sb_result sb_lut3d_parse(const char *text, size_t size, const char *source, struct sb_lut3d *lut)
{
    memset(lut, 0, sizeof(*lut));
    for (int i = 0; i < 3; i++)
        lut->domain_max[i] = 1.0f;
    struct cursor c = {.source = source};
    enum sb_result res = SB_OK;
    size_t entries = 0, expected = 0;
    unsigned seen = 0;
    if (memchr(text, '\0', size)) {
        sb_error("%s: holds a NUL byte; not a .cube text file", source);
        return SB_ERR_BAD_IMAGE;
    }
    for (size_t at = 0; at < size && !res;) {
        const char *start = text + at, *nl = memchr(start, '\n', size - at);
        size_t len = nl ? (size_t)(nl - start) : size - at;
        at += len + 1;
        c.line++;
        if (len && start[len - 1] == '\r')
            len--;
        while (len && (*start == ' ' || *start == '\t')) {
            start++;
            len--;
        }
        while (len && (start[len - 1] == ' ' || start[len - 1] == '\t'))
            len--;
        if (!len || *start == '#')
            continue;
        if (len >= LUT_MAX_LINE) {
            lut_error(&c, "a line of %zu characters; at most %d", len, LUT_MAX_LINE - 1);
            res = SB_ERR_OUT_OF_RANGE;
            break;
        }
        char line[LUT_MAX_LINE];
        memcpy(line, start, len);
        line[len] = '\0';
        char *after;
        strtod(line, &after); /* a line that opens with a number (nan and inf too) is an entry */
        bool data = after != line;
        if (!data) {
            if (entries) {
                lut_error(&c, "%s", "a keyword after the table's first entry");
                res = SB_ERR_OUT_OF_RANGE;
            } else {
                res = parse_keyword(&c, line, lut, &seen);
            }
            continue;
        }
        if (!lut->size) {
            lut_error(&c, "%s", "an entry before LUT_3D_SIZE");
            res = SB_ERR_MISSING_FIELD;
            break;
        }
        if (!lut->rgb) {
            expected = (size_t)lut->size * lut->size * lut->size;
            if (!(lut->rgb = malloc(expected * 3 * sizeof(float)))) {
                res = SB_ERR_NOMEM;
                break;
            }
        }
        double v[3];
        if (!parse_numbers(line, v, 3)) {
            lut_error(&c, "%s", "an entry must be three numbers within +-1e6 (R G B)");
            res = SB_ERR_OUT_OF_RANGE;
        } else if (entries == expected) {
            lut_error(&c, "more than the %zu entries LUT_3D_SIZE %u makes", expected, lut->size);
            res = SB_ERR_OUT_OF_RANGE;
        } else {
            for (int i = 0; i < 3; i++)
                lut->rgb[entries * 3 + i] = (float)v[i];
            entries++;
        }
    }
    if (!res && !lut->size) {
        sb_error("%s: no LUT_3D_SIZE; not a 3D .cube LUT", source);
        res = SB_ERR_MISSING_FIELD;
    }
    expected = (size_t)lut->size * lut->size * lut->size;
    if (!res && entries != expected) {
        sb_error("%s: %zu entries; LUT_3D_SIZE %u needs %zu", source, entries, lut->size, expected);
        res = SB_ERR_OUT_OF_RANGE;
    }
    for (int i = 0; i < 3 && !res; i++)
        if (!(lut->domain_min[i] < lut->domain_max[i])) {
            sb_error("%s: the domain's minimum (%g) is not below its maximum (%g) in channel %d", source,
                     lut->domain_min[i], lut->domain_max[i], i);
            res = SB_ERR_OUT_OF_RANGE;
        }
    if (res)
        sb_lut3d_finish(lut);
    return res;
}

enum sb_result sb_lut3d_load(const char *path, struct sb_lut3d *lut)
{
    memset(lut, 0, sizeof(*lut));
    char *text;
    size_t size;
    enum sb_result res = sb_read_file(AT_FDCWD, path, path, SB_LUT3D_MAX_BYTES, true, &text, &size);
    if (res)
        return res;
    res = sb_lut3d_parse(text, size, path, lut);
    free(text);
    return res;
}

void sb_lut3d_finish(struct sb_lut3d *lut)
{
    free(lut->rgb);
    memset(lut, 0, sizeof(*lut));
}
