/*
 * What vdb.c (the caller's side of vdb.h) and its helper program
 * skybake-vdb (vdb_helper.c and vdb.cpp: the one process in which OpenVDB
 * runs) say to each other, through formats/sandbox.h. OpenVDB stays out of
 * the programs and the library: linked, its 57,000 symbols bound at load
 * took 60 ms of every process's start.
 *
 * A request names its task:
 * - SB_VDB_READ: the file is open on SB_SANDBOX_FILE_FD. The answer's
 *   header; after a header with result 0, the attributes
 *   (SB_FILE_MAX_ATTRIBUTES of them) and width x height x depth x
 *   channel_count floats.
 * - SB_VDB_WRITE: the volume's floats (binary16 values, as fp32) are a
 *   memory file on SB_SANDBOX_FILE_FD, its shape and names in `volume`
 *   (whose data pointer means nothing here). The answer's header; after a
 *   header with result 0, the file's `size` bytes, which the caller writes.
 * Both sides are of one build (the sandbox checks), so the structs go as
 * bytes.
 */
#ifndef SB_VDB_HELPER_H
#define SB_VDB_HELPER_H

#include <stddef.h>
#include <stdint.h>

#include "image.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SB_VDB_HELPER "skybake-vdb"
#define SB_VDB_MAGIC 0x534b4256u /* "SKBV" */

/* The OpenVDB file version the helper writes and reads (vdb.cpp checks
 * it against OpenVDB's; the caller checks files against it). */
#define SB_VDB_FILE_VERSION 224
/* The header: magic (8 bytes), file version, library major and minor (4
 * each), the grid offsets flag (1), then the UUID as 36 characters
 * (openvdb/io/Archive.cc, writeHeader). */
#define SB_VDB_UUID_OFFSET (8 + 4 + 4 + 4 + 1)
#define SB_VDB_UUID_SIZE 36

enum sb_vdb_task { SB_VDB_READ = 1, SB_VDB_WRITE = 2 };

struct sb_vdb_request {
    uint32_t task;
    char path[4096]; /* for messages */
    /* read */
    uint64_t max_voxels;
    char channel_order[128]; /* the grids' names, comma-separated */
    /* write */
    struct sb_image volume;
    int32_t attribute_count;
    struct sb_attribute attributes[SB_FILE_MAX_ATTRIBUTES];
    char uuid[SB_VDB_UUID_SIZE + 1]; /* the file's, from its content */
};

struct sb_vdb_answer {
    uint32_t magic;
    int32_t result;
    uint32_t width, height, depth, channel_count; /* read */
    int32_t attribute_count;                      /* read */
    uint64_t size;                                /* write: the file's bytes */
    char message[512];                            /* the first warning or error the helper logged */
};

/* The helper's task (sandbox.h's sb_sandbox_fn), in vdb.cpp with the rest
 * of OpenVDB. */
int sb_vdb_task(int fd, const void *request, size_t size);

#ifdef __cplusplus
}
#endif

#endif
