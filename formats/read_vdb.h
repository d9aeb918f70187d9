/*
 * What sb_vdb_read (vdb.cpp) and its helper program skybake-read-vdb
 * (read_vdb.c, the one process in which OpenVDB parses a file) say to each other,
 * through formats/sandbox.h: the request, then the answer's header; after a
 * header with result 0 come the attributes (SB_FILE_MAX_ATTRIBUTES of
 * them) and width x height x depth x channel_count floats. The file itself
 * is open on SB_SANDBOX_FILE_FD. Both sides are of one build (the sandbox
 * checks), so the structs go as bytes.
 */
#ifndef SB_READ_VDB_H
#define SB_READ_VDB_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SB_READ_VDB_HELPER "skybake-read-vdb"
#define SB_READ_VDB_MAGIC 0x534b4256u /* "SKBV" */

struct sb_read_vdb_request {
    uint64_t max_voxels;
    char path[4096];         /* for messages */
    char channel_order[128]; /* the grids' names, comma-separated */
};

struct sb_read_vdb_answer {
    uint32_t magic;
    int32_t result;
    uint32_t width, height, depth, channel_count;
    int32_t attribute_count;
    char message[512]; /* the first warning or error the helper logged */
};

/* The helper's task (sandbox.h's sb_sandbox_fn), in vdb.cpp with the rest
 * of OpenVDB; hidden from the shared library's users. */
__attribute__((visibility("hidden"))) int sb_vdb_read_task(int fd, const void *request, size_t size);

#ifdef __cplusplus
}
#endif

#endif
