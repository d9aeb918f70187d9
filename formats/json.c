#include "json.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io.h"
#include "log.h"

enum sb_result sb_json_parse(const char *text, size_t size, const char *source, cJSON **root)
{
    *root = NULL;
    if (size == 0) {
        sb_error("%s: empty file, expected a JSON object", source);
        return SB_ERR_JSON_SYNTAX;
    }
    if (memchr(text, '\0', size)) {
        sb_error("%s: contains a NUL byte: not a JSON text", source);
        return SB_ERR_JSON_SYNTAX;
    }
    const char *end = NULL;
    cJSON *value = cJSON_ParseWithLengthOpts(text, size, &end, false);
    if (!value) {
        size_t offset = end ? (size_t)(end - text) : 0;
        size_t line = 1;
        for (size_t i = 0; i < offset && i < size; i++)
            line += text[i] == '\n';
        sb_error("%s: line %zu: malformed JSON near byte %zu", source, line, offset);
        return SB_ERR_JSON_SYNTAX;
    }
    /* Anything but whitespace after the value is an error. */
    for (const char *c = end; c && c < text + size; c++)
        if (*c != ' ' && *c != '\t' && *c != '\n' && *c != '\r') {
            sb_error("%s: trailing data after the JSON value at byte %zu", source, (size_t)(c - text));
            cJSON_Delete(value);
            return SB_ERR_JSON_SYNTAX;
        }
    *root = value;
    return SB_OK;
}

enum sb_result sb_json_load(int dir, const char *path, const char *source, size_t max_bytes, bool follow_symlinks,
                            cJSON **root)
{
    *root = NULL;
    char *buf;
    size_t n;
    enum sb_result res = sb_read_file(dir, path, source, max_bytes, follow_symlinks, &buf, &n);
    if (res)
        return res;
    res = sb_json_parse(buf, n, source, root);
    free(buf);
    return res;
}

enum sb_result sb_json_check_duplicates(const cJSON *object, const char *source, const char *where)
{
    for (const cJSON *a = object->child; a; a = a->next)
        for (const cJSON *b = a->next; b; b = b->next)
            if (a->string && b->string && strcmp(a->string, b->string) == 0) {
                sb_error("%s: %s%s%s: key given twice", source, where, *where ? "." : "", a->string);
                return SB_ERR_DUPLICATE_KEY;
            }
    return SB_OK;
}

bool sb_json_emit(FILE *out, cJSON *root)
{
    char *text = root ? cJSON_Print(root) : NULL;
    bool ok = text && fprintf(out, "%s\n", text) >= 0;
    free(text);
    cJSON_Delete(root);
    return ok;
}

enum sb_result sb_json_number(const cJSON *item, const char *source, const char *path, double lo, double hi,
                              double *out)
{
    if (!cJSON_IsNumber(item)) {
        sb_error("%s: %s: expected a number", source, path);
        return SB_ERR_WRONG_TYPE;
    }
    if (!isfinite(item->valuedouble) || item->valuedouble < lo || item->valuedouble > hi) {
        sb_error("%s: %s: %.17g is out of range, expected %g to %g", source, path, item->valuedouble, lo, hi);
        return SB_ERR_OUT_OF_RANGE;
    }
    *out = item->valuedouble;
    return SB_OK;
}

enum sb_result sb_json_vec3(const cJSON *item, const char *source, const char *path, double lo, double hi,
                            double out[3])
{
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != 3) {
        sb_error("%s: %s: expected an array of 3 numbers", source, path);
        return SB_ERR_WRONG_TYPE;
    }
    char element[160];
    for (int i = 0; i < 3; i++) {
        snprintf(element, sizeof(element), "%s[%d]", path, i);
        enum sb_result res = sb_json_number(cJSON_GetArrayItem(item, i), source, element, lo, hi, &out[i]);
        if (res)
            return res;
    }
    return SB_OK;
}

enum sb_result sb_json_only_keys(const cJSON *obj, const char *source, const char *section, const char *const *keys)
{
    if (!cJSON_IsObject(obj)) {
        sb_error("%s: %s: expected an object", source, section);
        return SB_ERR_WRONG_TYPE;
    }
    enum sb_result res = sb_json_check_duplicates(obj, source, section);
    for (const cJSON *item = obj->child; item && !res; item = item->next) {
        bool known = false;
        for (const char *const *k = keys; *k; k++)
            known |= !strcmp(*k, item->string);
        if (!known) {
            sb_error("%s: %s.%s: unknown key (see docs/scene.md)", source, section, item->string);
            res = SB_ERR_UNKNOWN_KEY;
        }
    }
    return res;
}

bool sb_json_safe(const char *s)
{
    for (; *s; s++)
        if (*s == '"' || *s == '\\' || (unsigned char)*s < 0x20)
            return false;
    return true;
}

enum sb_result sb_json_box(const cJSON *item, const char *source, const char *path, double lo, double hi,
                           double box[2][3])
{
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != 2) {
        sb_error("%s: %s: expected [[min x, y, z], [max x, y, z]]", source, path);
        return SB_ERR_WRONG_TYPE;
    }
    enum sb_result res = SB_OK;
    char corner[160];
    for (int c = 0; c < 2 && !res; c++) {
        snprintf(corner, sizeof(corner), "%s[%d]", path, c);
        res = sb_json_vec3(cJSON_GetArrayItem(item, c), source, corner, lo, hi, box[c]);
    }
    for (int k = 0; k < 3 && !res; k++)
        if (!(box[1][k] - box[0][k] >= 0.01)) {
            sb_error("%s: %s: %g m along %c; a box is at least 0.01 m on every side (max corner above min)", source,
                     path, box[1][k] - box[0][k], "xyz"[k]);
            res = SB_ERR_OUT_OF_RANGE;
        }
    return res;
}

enum sb_result sb_json_member_number(const cJSON *obj, const char *where, const char *key, double lo, double hi,
                                     const char *source, double *out)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    char path[128];
    snprintf(path, sizeof(path), "%s.%s", where, key);
    return item ? sb_json_number(item, source, path, lo, hi, out) : SB_OK;
}

enum sb_result sb_json_member_vec3(const cJSON *obj, const char *where, const char *key, double lo, double hi,
                                   const char *source, double out[3])
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    char path[128];
    snprintf(path, sizeof(path), "%s.%s", where, key);
    return item ? sb_json_vec3(item, source, path, lo, hi, out) : SB_OK;
}
