/*
 * skybake info: what a pack holds, for people and for pipelines. The pack
 * is opened with sb_pack_open, so everything printed has been verified
 * (format version, files, shapes, finite values, content hashes, scene).
 */
#ifndef SB_BAKER_PACK_INFO_H
#define SB_BAKER_PACK_INFO_H

#include <stdbool.h>

#include "pack.h"

/* Print the open pack read from `dir` as a table, or as one JSON object, on stdout. */
void sb_pack_info_print(const struct sb_pack *pack, const char *dir, bool json);

#endif
