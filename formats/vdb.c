/*
 * vdb.h from the caller's side. OpenVDB itself runs only in the helper
 * program skybake-vdb (vdb.cpp, vdb_helper.h): the writer sends it the
 * volume and writes the bytes it answers; the reader checks the file's
 * structure here, then the helper parses it under the sandbox's limits.
 */
#include "vdb.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io.h"
#include "log.h"
#include "sandbox.h"
#include "vdb_helper.h"

#define DEFAULT_MAX_VOXELS (1ull << 28)
#define MAX_FILE_BYTES (1ull << 30)

/* A UUID-shaped string (8-4-4-4-12 hex digits) from the volume's content
 * hash and the attributes: the same file gives the same UUID, and two
 * different volumes differ in theirs, as tools that cache by UUID expect. */
static bool uuid_from(const struct sb_image *volume, const struct sb_attribute *attributes, int attribute_count,
                      char uuid[SB_VDB_UUID_SIZE + 1])
{
    char content[SB_HASH_HEX_SIZE], h[SB_HASH_HEX_SIZE];
    sb_image_content_hash(volume, content);
    size_t cap = SB_HASH_HEX_SIZE + 1 + (size_t)attribute_count * (sizeof(attributes[0]) + 2), n = 0;
    char *text = malloc(cap);
    if (!text)
        return false;
    n += (size_t)snprintf(text + n, cap - n, "%s\n", content);
    for (int a = 0; a < attribute_count; a++)
        n += (size_t)snprintf(text + n, cap - n, "%s=%s\n", attributes[a].name, attributes[a].value);
    sb_hash_bytes(text, n, h);
    free(text);
    snprintf(uuid, SB_VDB_UUID_SIZE + 1, "%.8s-%.4s-%.4s-%.4s-%.12s", h, h + 8, h + 12, h + 16, h + 20);
    return true;
}

/*
 * Start the helper on `job` (freed) with `fd` (closed: the helper has its
 * copy) and read its answer's header. SB_OK: the box is open and the
 * answer's rest follows. Otherwise the box is finished and the reason
 * logged: the helper's own message, or how its process ended, `doing`
 * what ("writing the volume").
 */
static enum sb_result ask_helper(const char *path, const struct sb_sandbox_limits *limits, struct sb_vdb_request *job,
                                 int fd, const char *doing, struct sb_sandbox *box, struct sb_vdb_answer *a)
{
    enum sb_result res = sb_sandbox_start(box, limits, SB_VDB_HELPER, job, sizeof(*job), fd);
    close(fd);
    free(job);
    if (res) {
        sb_error("%s: OpenVDB's process could not start %s", path, doing);
        return res;
    }
    char why[160];
    if (!sb_sandbox_read(box, a, sizeof(*a)) || a->magic != SB_VDB_MAGIC) {
        sb_sandbox_finish(box, why, sizeof(why));
        sb_error("%s: OpenVDB did not finish %s: its process %s", path, doing, why);
        return SB_ERR_VDB;
    }
    a->message[sizeof(a->message) - 1] = '\0';
    if (a->result) {
        sb_sandbox_finish(box, NULL, 0);
        if (a->message[0])
            sb_error("%s", a->message);
        else
            sb_error("%s: OpenVDB failed %s", path, doing);
        return (unsigned)a->result < SB_RESULT_COUNT ? (enum sb_result)a->result : SB_ERR_VDB;
    }
    return SB_OK;
}

/* The floats of `volume` in a memory file, for the helper. */
static int volume_file(const struct sb_image *volume)
{
    int fd = memfd_create("skybake-volume", MFD_CLOEXEC);
    if (fd >= 0 && (!sb_write_all(fd, volume->data, sb_image_float_count(volume) * sizeof(float)) ||
                    lseek(fd, 0, SEEK_SET) != 0)) {
        close(fd);
        fd = -1;
    }
    return fd;
}

enum sb_result sb_vdb_write(const char *path, const struct sb_image *volume, const struct sb_attribute *attributes,
                            int attribute_count)
{
    int64_t bad = sb_image_find_not_half(volume);
    if (bad >= 0) {
        sb_error("%s: value %lld (%.9g) is not a binary16 value, which the file stores; round first", path,
                 (long long)bad, (double)volume->data[bad]);
        return SB_ERR_NUMERIC;
    }
    if (attribute_count < 0 || attribute_count > SB_FILE_MAX_ATTRIBUTES) {
        sb_error("%s: %d attributes (at most %d)", path, attribute_count, SB_FILE_MAX_ATTRIBUTES);
        return SB_ERR_USAGE;
    }
    struct sb_vdb_request *job = calloc(1, sizeof(*job));
    if (!job)
        return SB_ERR_NOMEM;
    enum sb_result res = SB_OK;
    job->task = SB_VDB_WRITE;
    if (snprintf(job->path, sizeof(job->path), "%s", path) >= (int)sizeof(job->path)) {
        sb_error("%s: the path is too long to write it", path);
        free(job);
        return SB_ERR_IO;
    }
    job->volume = *volume;
    job->volume.data = NULL;
    job->attribute_count = attribute_count;
    if (attribute_count)
        memcpy(job->attributes, attributes, (size_t)attribute_count * sizeof(attributes[0]));
    if (!uuid_from(volume, attributes, attribute_count, job->uuid)) {
        free(job);
        return SB_ERR_NOMEM;
    }
    int fd = volume_file(volume);
    if (fd < 0) {
        sb_error("%s: cannot hand the volume to OpenVDB's process: %s", path, strerror(errno));
        free(job);
        return SB_ERR_IO;
    }
    /* Memory for the mapped floats, OpenVDB's trees and the file's bytes
     * (twice: the stream and its copy), and OpenVDB's own buffers; time
     * for a slow machine's 2^28 voxels. */
    uint64_t floats = sb_image_float_count(volume);
    struct sb_sandbox_limits limits = {.cpu_seconds = 60 + (unsigned)(floats >> 22),
                                       .address_space_bytes = (256ull << 20) + 16 * floats};
    struct sb_sandbox box;
    struct sb_vdb_answer a;
    char why[160];
    void *bytes = NULL;
    if ((res = ask_helper(path, &limits, job, fd, "writing the volume", &box, &a)))
        return res;
    if (a.size < SB_VDB_UUID_OFFSET + SB_VDB_UUID_SIZE || a.size > MAX_FILE_BYTES) {
        sb_sandbox_finish(&box, NULL, 0);
        sb_error("%s: OpenVDB's process answered a file of %llu bytes (the reader takes at most %llu)", path,
                 (unsigned long long)a.size, (unsigned long long)MAX_FILE_BYTES);
        return SB_ERR_VDB;
    }
    if (!(bytes = malloc(a.size))) {
        sb_sandbox_finish(&box, NULL, 0);
        return SB_ERR_NOMEM;
    }
    if (!sb_sandbox_read(&box, bytes, a.size)) {
        sb_sandbox_finish(&box, why, sizeof(why));
        sb_error("%s: OpenVDB stopped half way through the volume: its process %s", path, why);
        free(bytes);
        return SB_ERR_VDB;
    }
    sb_sandbox_finish(&box, NULL, 0);
    res = sb_write_file(path, bytes, a.size, "VDB file");
    free(bytes);
    return res;
}

/* ---- the file's structure, checked before OpenVDB parses it ---------------------------
 *
 * OpenVDB trusts the lengths in a file: a VDB cut to 100 bytes made it
 * allocate 20 GB, and other cuts read lengths it never set. So the layout
 * OpenVDB's File::open walks (openvdb/io/Archive.cc, File.cc,
 * GridDescriptor.cc) is walked here first, every length and offset bounded
 * by the file: the header, the file's metadata, then each grid's
 * descriptor, whose offsets must lie in order within the file and end
 * exactly at its end. What lies inside a grid is left to OpenVDB, in the
 * helper. */

#define VDB_MAGIC 0x56444220   /* OPENVDB_MAGIC, " BDV" */
#define FIRST_FILE_VERSION 222 /* node mask compression, the UUID, instancing */
#define MAX_STRING 4096
#define MAX_META 256
#define MAX_META_BYTES (1u << 20)

struct cursor {
    int fd;
    uint64_t size, at;
    bool ok;
};

static bool cursor_seek(struct cursor *c, uint64_t to)
{
    return c->ok = c->ok && to <= c->size ? (c->at = to, true) : false;
}

static bool cursor_bytes(struct cursor *c, void *out, uint64_t n)
{
    if (!c->ok || n > c->size - c->at)
        return c->ok = false;
    char *p = out;
    for (uint64_t done = 0; done < n;) {
        ssize_t got = pread(c->fd, p + done, n - done, (off_t)(c->at + done));
        if (got < 0 && errno == EINTR)
            continue;
        if (got <= 0)
            return c->ok = false;
        done += (uint64_t)got;
    }
    c->at += n;
    return true;
}

static uint32_t cursor_u32(struct cursor *c)
{
    uint32_t v = 0;
    cursor_bytes(c, &v, sizeof(v));
    return v;
}

static int64_t cursor_i64(struct cursor *c)
{
    int64_t v = 0;
    cursor_bytes(c, &v, sizeof(v));
    return v;
}

/* readString: a 32-bit length, then the characters (kept NUL-terminated
 * in out[MAX_STRING + 1] when `out` is not NULL, else skipped). */
static bool cursor_string(struct cursor *c, char *out)
{
    uint32_t n = cursor_u32(c);
    if (!c->ok || n > MAX_STRING)
        return c->ok = false;
    if (!out)
        return cursor_seek(c, c->at + n);
    out[n] = '\0';
    return cursor_bytes(c, out, n);
}

static bool is_uuid(const char *s)
{
    for (int i = 0; i < SB_VDB_UUID_SIZE; i++) {
        bool dash = i == 8 || i == 13 || i == 18 || i == 23;
        if (dash ? s[i] != '-' : !isxdigit((unsigned char)s[i]))
            return false;
    }
    return true;
}

/* True when the layout holds; else what is wrong in why[size], for
 * "path: ...", and *code SB_ERR_BAD_IMAGE for a sound VDB file of other
 * grids, else SB_ERR_VDB. */
static bool check_structure(int fd, uint64_t size, uint32_t grids_expected, char *why, size_t why_size,
                            enum sb_result *code)
{
    *code = SB_ERR_VDB;
    struct cursor c = {.fd = fd, .size = size, .ok = true};
    char unique[MAX_STRING + 1]; /* a metadata's or a grid's name */
    int64_t magic = cursor_i64(&c);
    if (!c.ok || magic != VDB_MAGIC) {
        snprintf(why, why_size, "not a VDB file (no magic number)");
        return false;
    }
    uint32_t version = cursor_u32(&c);
    if (version < FIRST_FILE_VERSION || version > SB_VDB_FILE_VERSION) {
        snprintf(why, why_size, "file format version %u, not one this reader knows (%d to %d)", version,
                 FIRST_FILE_VERSION, SB_VDB_FILE_VERSION);
        return false;
    }
    cursor_u32(&c); /* the library's major and minor version */
    cursor_u32(&c);
    uint8_t offsets = 0;
    cursor_bytes(&c, &offsets, 1);
    if (c.ok && offsets != 1) {
        snprintf(why, why_size, "no grid offsets (skybake's files have them)");
        return false;
    }
    char uuid[SB_VDB_UUID_SIZE];
    if (!cursor_bytes(&c, uuid, sizeof(uuid)) || !is_uuid(uuid)) {
        snprintf(why, why_size, "the header ends early or has no UUID");
        return false;
    }
    uint32_t metas = cursor_u32(&c);
    if (!c.ok || metas > MAX_META) {
        snprintf(why, why_size, "the file's metadata count is cut or past %d", MAX_META);
        return false;
    }
    for (uint32_t m = 0; m < metas; m++) {
        if (!cursor_string(&c, unique) || !cursor_string(&c, NULL)) {
            snprintf(why, why_size, "metadata %u: its name or type is cut or too long", m);
            return false;
        }
        uint32_t n = cursor_u32(&c);
        if (!c.ok || n > MAX_META_BYTES || !cursor_seek(&c, c.at + n)) {
            snprintf(why, why_size, "metadata \"%.200s\": its value is cut or larger than 1 MiB", unique);
            return false;
        }
    }
    int32_t grids = (int32_t)cursor_u32(&c);
    if (c.ok && grids >= 0 && (uint32_t)grids != grids_expected)
        *code = SB_ERR_BAD_IMAGE;
    if (!c.ok || grids < 0 || (uint32_t)grids != grids_expected) {
        snprintf(why, why_size, "holds %d grids, expected %u (the channels)", grids, grids_expected);
        return false;
    }
    for (int32_t g = 0; g < grids; g++) {
        if (!cursor_string(&c, unique) || !cursor_string(&c, NULL) || !cursor_string(&c, NULL)) {
            snprintf(why, why_size, "grid %d: its descriptor is cut", g);
            return false;
        }
        int64_t grid_pos = cursor_i64(&c), block_pos = cursor_i64(&c), end_pos = cursor_i64(&c);
        if (!c.ok || grid_pos < (int64_t)c.at || block_pos < grid_pos || end_pos < block_pos ||
            (uint64_t)end_pos > size || (g + 1 == grids && (uint64_t)end_pos != size)) {
            snprintf(why, why_size,
                     "grid \"%.200s\": its offsets %lld, %lld, %lld do not lie in order within the file's %llu bytes",
                     unique, (long long)grid_pos, (long long)block_pos, (long long)end_pos, (unsigned long long)size);
            return false;
        }
        cursor_seek(&c, (uint64_t)end_pos);
    }
    return true;
}

enum sb_result sb_vdb_read(const char *path, const char *channel_order, uint64_t max_voxels, struct sb_image *volume,
                           struct sb_attribute *attributes, int *attribute_count)
{
    memset(volume, 0, sizeof(*volume));
    if (attribute_count)
        *attribute_count = 0;
    if (!max_voxels)
        max_voxels = DEFAULT_MAX_VOXELS;
    struct sb_vdb_request *job = calloc(1, sizeof(*job));
    if (!job)
        return SB_ERR_NOMEM;
    sb_image_set_channel_names(&job->volume, channel_order);
    uint32_t channels = 0;
    while (channels < SB_IMAGE_MAX_CHANNELS && job->volume.channel_names[channels][0])
        channels++;
    int fd = sb_open_regular(AT_FDCWD, path, true, NULL);
    if (fd < 0) {
        sb_error("%s: cannot open the VDB file: %s", path, errno == EINVAL ? "not a regular file" : strerror(errno));
        free(job);
        return SB_ERR_IO;
    }
    struct stat st;
    if (fstat(fd, &st) != 0 || (uint64_t)st.st_size > MAX_FILE_BYTES) {
        sb_error("%s: not a file of at most %llu bytes", path, (unsigned long long)MAX_FILE_BYTES);
        close(fd);
        free(job);
        return SB_ERR_IO;
    }
    enum sb_result code;
    char wrong[512];
    if (!check_structure(fd, (uint64_t)st.st_size, channels, wrong, sizeof(wrong), &code)) {
        sb_error("%s: %s", path, wrong);
        close(fd);
        free(job);
        return code;
    }
    /* OpenVDB in its helper: the grids' contents are still OpenVDB's to
     * parse. Memory for its tree and our copy: three times the volume, and
     * room for OpenVDB's own buffers. */
    job->task = SB_VDB_READ;
    job->max_voxels = max_voxels;
    if (snprintf(job->path, sizeof(job->path), "%s", path) >= (int)sizeof(job->path) ||
        snprintf(job->channel_order, sizeof(job->channel_order), "%s", channel_order) >=
            (int)sizeof(job->channel_order)) {
        sb_error("%s: the path or the channel list is too long to read it", path);
        close(fd);
        free(job);
        return SB_ERR_IO;
    }
    struct sb_sandbox_limits limits = {
        .cpu_seconds = 60,
        .address_space_bytes =
            (128ull << 20) +
            3 * (max_voxels < DEFAULT_MAX_VOXELS ? max_voxels : DEFAULT_MAX_VOXELS) * channels * sizeof(float),
    };
    struct sb_sandbox box;
    struct sb_vdb_answer a;
    char why[160];
    enum sb_result res = ask_helper(path, &limits, job, fd, "reading the file", &box, &a);
    if (res)
        return res;
    struct sb_attribute got[SB_FILE_MAX_ATTRIBUTES];
    uint64_t voxels = (uint64_t)a.width * a.height * a.depth;
    if (a.channel_count != channels || !a.width || !a.height || !a.depth || voxels > max_voxels ||
        a.attribute_count < 0 || a.attribute_count > SB_FILE_MAX_ATTRIBUTES) {
        sb_sandbox_finish(&box, NULL, 0);
        sb_error("%s: the reading process answered %ux%ux%u voxels of %u channels: not what was asked", path, a.width,
                 a.height, a.depth, a.channel_count);
        return SB_ERR_VDB;
    }
    res = sb_image_init_volume(volume, a.width, a.height, a.depth, channels);
    if (!res && !(sb_sandbox_read(&box, got, sizeof(got)) &&
                  sb_sandbox_read(&box, volume->data, sb_image_float_count(volume) * sizeof(float)))) {
        sb_sandbox_finish(&box, why, sizeof(why));
        sb_error("%s: OpenVDB stopped half way: its process %s", path, why);
        res = SB_ERR_VDB;
    }
    sb_sandbox_finish(&box, NULL, 0);
    if (res) {
        sb_image_finish(volume);
        return res;
    }
    sb_image_set_channel_names(volume, channel_order);
    for (int i = 0; attributes && i < a.attribute_count; i++) {
        got[i].name[sizeof(got[i].name) - 1] = '\0';
        got[i].value[sizeof(got[i].value) - 1] = '\0';
        attributes[i] = got[i];
    }
    if (attribute_count)
        *attribute_count = attributes ? a.attribute_count : 0;
    return SB_OK;
}
