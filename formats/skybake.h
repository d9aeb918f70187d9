/*
 * libskybake-formats: read, verify and write skybake packs, and parse scene
 * files, with no Vulkan. The public header for engines and tools:
 *
 *     #include <skybake.h>
 *     cc app.c $(pkg-config --cflags --libs skybake-formats)
 *
 * Loading a pack:
 *
 *     struct sb_pack pack;
 *     enum sb_result res = sb_pack_open("out", &pack);
 *     if (res) { fprintf(stderr, "%s\n", sb_result_description(res)); return 1; }
 *     // pack.images[SB_PRODUCT_TRANSMITTANCE] ... : verified, finite fp32
 *     // pack.images[SB_PRODUCT_CLOUD_SHAPE]: a volume (depth > 1), when baked
 *     // pack.scene->atmosphere: the coefficients the pack was baked with
 *     sb_pack_close(&pack);
 *
 * What each function checks and returns is documented in its header:
 * pack.h (packs: sb_pack_open, sb_pack_verify, the writer), image.h (the
 * images and content hashes), exr.h and vdb.h (single EXR images and VDB
 * volumes), scene.h (scene files), result.h (the closed set of result
 * codes), log.h (where messages go: install a sink to route them into the
 * engine's log). docs/pack.md
 * describes the format and its versioning. Not thread safe: the log's sink
 * is global, and packs are read by one thread at a time.
 */
#ifndef SKYBAKE_H
#define SKYBAKE_H

#include "exr.h"
#include "image.h"
#include "log.h"
#include "pack.h"
#include "result.h"
#include "scene.h"
#include "vdb.h"

#endif
