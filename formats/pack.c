#include "pack.h"

#include <cJSON.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <libgen.h>
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "config.h"
#include "family.h"
#include "json.h"
#include "log.h"
#include "scene.h"
#include "skybake_version.h"
#include "vdb.h"

#define PACK_MAX_ARTIFACTS 32

struct sb_pack_writer {
    char out_dir[4000];
    char tmp_dir[4096];
    int tmp_fd;                       /* the temporary directory, for removing it from a signal handler */
    const char *volatile pending;     /* the file being written, not yet an artifact */
    volatile sig_atomic_t publishing; /* renaming into place: the signal handler leaves it alone */
    int artifact_count;
    struct sb_artifact artifacts[PACK_MAX_ARTIFACTS];
    struct {
        uint32_t width, height, depth, channel_count;
        char channels[SB_IMAGE_MAX_CHANNELS][SB_CHANNEL_NAME_MAX];
    } shapes[PACK_MAX_ARTIFACTS];
};

/* Fault injection for the tests: with SKYBAKE_FAULT=NAME the process kills
 * itself (SIGKILL) at the point of publishing so named: "artifact" (the first
 * artifact written), "manifest" (written, not yet flushed), "publish" (just
 * before the rename), "published" (after it, before the old copy is removed). */
static void fault_point(const char *name)
{
    const char *want = getenv("SKYBAKE_FAULT");
    if (want && !strcmp(want, name))
        raise(SIGKILL);
}

/* Writers that own a temporary directory, for sb_pack_writers_remove_temporaries. */
#define PACK_MAX_WRITERS 8
static struct sb_pack_writer *volatile live_writers[PACK_MAX_WRITERS];

static void writer_register(struct sb_pack_writer *w, bool live)
{
    for (int i = 0; i < PACK_MAX_WRITERS; i++)
        if (live_writers[i] == (live ? NULL : w)) {
            live_writers[i] = live ? w : NULL;
            return;
        }
}

void sb_pack_writers_remove_temporaries(void)
{
    /* Only async-signal-safe calls: unlinkat and rmdir. */
    for (int i = 0; i < PACK_MAX_WRITERS; i++) {
        struct sb_pack_writer *w = live_writers[i];
        if (!w || w->publishing)
            continue;
        for (int a = 0; a < w->artifact_count; a++)
            unlinkat(w->tmp_fd, w->artifacts[a].file, 0);
        if (w->pending)
            unlinkat(w->tmp_fd, w->pending, 0);
        unlinkat(w->tmp_fd, SB_PACK_MANIFEST, 0);
        rmdir(w->tmp_dir);
    }
}

/* Remove the regular files of a flat directory, then the directory. */
static int remove_flat_dir(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return -1;
    struct dirent *e;
    char path[8192];
    int failed = 0;
    while ((e = readdir(d))) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        snprintf(path, sizeof(path), "%s/%s", dir, e->d_name);
        if (unlink(path) != 0)
            failed = -1;
    }
    closedir(d);
    return rmdir(dir) == 0 ? failed : -1;
}

static bool is_pack_or_empty(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return false;
    bool empty = true, manifest = false;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        empty = false;
        if (!strcmp(e->d_name, SB_PACK_MANIFEST))
            manifest = true;
    }
    closedir(d);
    return empty || manifest;
}

static int fsync_path(const char *path, bool directory)
{
    int fd = open(path, (directory ? O_RDONLY | O_DIRECTORY : O_RDONLY) | O_CLOEXEC);
    if (fd < 0)
        return -1;
    int rv = fsync(fd);
    close(fd);
    return rv;
}

static void parent_of(const char *path, char *out, size_t size)
{
    char tmp[4096];
    snprintf(tmp, sizeof(tmp), "%s", path);
    snprintf(out, size, "%s", dirname(tmp));
}

/*
 * Temporary directories beside out_dir ("NAME.tmp-PID-XXXXXX") left by a
 * bake that was killed (its process no longer exists): removed, since
 * SIGKILL gives no chance to clean up.
 */
static void remove_stale_temporaries(const char *out_dir)
{
    char parent[4096], base[4096], tmp[4096];
    parent_of(out_dir, parent, sizeof(parent));
    snprintf(tmp, sizeof(tmp), "%s", out_dir);
    snprintf(base, sizeof(base), "%s.tmp-", basename(tmp));
    DIR *d = opendir(parent);
    if (!d)
        return;
    size_t base_len = strlen(base);
    struct dirent *e;
    while ((e = readdir(d))) {
        if (strncmp(e->d_name, base, base_len) != 0)
            continue;
        char *end;
        long pid = strtol(e->d_name + base_len, &end, 10);
        if (end == e->d_name + base_len || *end != '-' || pid <= 0 || kill((pid_t)pid, 0) == 0 || errno != ESRCH)
            continue; /* not ours, or its process is still running */
        char path[8200];
        snprintf(path, sizeof(path), "%s/%s", parent, e->d_name);
        if (remove_flat_dir(path) == 0)
            sb_info("%s: removed, left by a bake that was stopped (process %ld)", path, pid);
    }
    closedir(d);
}

enum sb_result sb_pack_writer_create(const char *out_dir, struct sb_pack_writer **out)
{
    *out = NULL;
    size_t len = strlen(out_dir);
    while (len > 1 && out_dir[len - 1] == '/')
        len--;
    if (len == 0 || len >= 4000) {
        sb_error("output directory: empty or too long a path");
        return SB_ERR_USAGE;
    }
    struct sb_pack_writer *w = calloc(1, sizeof(*w));
    if (!w)
        return SB_ERR_NOMEM;
    memcpy(w->out_dir, out_dir, len);

    struct stat st;
    if (lstat(w->out_dir, &st) == 0) {
        if (!S_ISDIR(st.st_mode)) {
            sb_error("%s: exists and is not a directory; refusing to replace it", w->out_dir);
            free(w);
            return SB_ERR_IO;
        }
        if (!is_pack_or_empty(w->out_dir)) {
            sb_error("%s: exists and is neither empty nor a skybake pack (no %s); refusing to replace it", w->out_dir,
                     SB_PACK_MANIFEST);
            free(w);
            return SB_ERR_IO;
        }
    } else if (errno != ENOENT) {
        sb_error("%s: %s", w->out_dir, strerror(errno));
        free(w);
        return SB_ERR_IO;
    }

    remove_stale_temporaries(w->out_dir);
    snprintf(w->tmp_dir, sizeof(w->tmp_dir), "%s.tmp-%ld-XXXXXX", w->out_dir, (long)getpid());
    if (!mkdtemp(w->tmp_dir)) {
        char parent[4096];
        parent_of(w->out_dir, parent, sizeof(parent));
        sb_error("%s: cannot create a temporary directory beside the pack: %s", parent, strerror(errno));
        free(w);
        return SB_ERR_IO;
    }
    w->tmp_fd = open(w->tmp_dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (w->tmp_fd < 0) {
        sb_error("%s: %s", w->tmp_dir, strerror(errno));
        rmdir(w->tmp_dir);
        free(w);
        return SB_ERR_IO;
    }
    writer_register(w, true);
    /* mkdtemp makes 0700; a pack gets the permissions the umask gives. */
    mode_t mask = umask(0);
    umask(mask);
    chmod(w->tmp_dir, 0777 & ~mask);
    *out = w;
    return SB_OK;
}

void sb_artifact_set_world(struct sb_artifact *a, const char *world_hash, const char *world_path)
{
    snprintf(a->world_hash, sizeof(a->world_hash), "%s", world_hash);
    size_t length = strlen(world_path);
    if (length >= sizeof(a->world_path) || sb_utf8_check(world_path, length) != SIZE_MAX) {
        sb_warn("%s: the world's path is %s; the manifest does not record it (skyview will need --world)",
                sb_product_name(a->product), length >= sizeof(a->world_path) ? "too long" : "not UTF-8 text");
        a->world_path[0] = '\0';
        return;
    }
    memcpy(a->world_path, world_path, length + 1);
}

enum sb_result sb_pack_writer_add_image(struct sb_pack_writer *w, struct sb_artifact *artifact,
                                        const struct sb_image *image)
{
    if (w->artifact_count >= PACK_MAX_ARTIFACTS)
        return SB_ERR_OUT_OF_RANGE;
    if (strchr(artifact->file, '/') || !artifact->file[0] || artifact->file[0] == '.') {
        sb_error("pack: artifact file name \"%s\" must be a plain file name", artifact->file);
        return SB_ERR_OUT_OF_RANGE;
    }
    const struct sb_product_format *format = sb_product_format(artifact->product);
    int64_t bad = sb_image_find_nonfinite(image);
    if (bad >= 0) {
        uint64_t texel = (uint64_t)bad / image->channel_count;
        sb_error("%s: value at texel (%llu, %llu, %llu) channel %s is %g; refusing to write a non-finite product",
                 sb_product_name(artifact->product), (unsigned long long)(texel % image->width),
                 (unsigned long long)(texel / image->width % image->height),
                 (unsigned long long)(texel / image->width / image->height),
                 image->channel_names[bad % image->channel_count], image->data[bad]);
        return SB_ERR_NUMERIC;
    }
    /* What the manifest will say of it, checked now rather than written as
     * something else: settings are a JSON object, the world's path UTF-8. */
    cJSON *settings = cJSON_Parse(artifact->settings_json[0] ? artifact->settings_json : "{}");
    bool settings_ok = cJSON_IsObject(settings);
    cJSON_Delete(settings);
    if (!settings_ok) {
        sb_error("%s: its settings are not a JSON object: %s", sb_product_name(artifact->product),
                 artifact->settings_json);
        return SB_ERR_JSON_SYNTAX;
    }
    if (sb_utf8_check(artifact->world_path, strlen(artifact->world_path)) != SIZE_MAX) {
        sb_error("%s: the world's path is not UTF-8 text: %s", sb_product_name(artifact->product),
                 artifact->world_path);
        return SB_ERR_OUT_OF_RANGE;
    }
    if (format->storage == SB_STORAGE_PROBES)
        sb_probes_content_hash(image, &artifact->probes, artifact->content_hash);
    else
        sb_image_content_hash(image, artifact->content_hash);

    struct sb_attribute attrs[4];
    int n = 0;
    snprintf(attrs[n].name, sizeof(attrs[n].name), "skybake.product");
    snprintf(attrs[n++].value, sizeof(attrs[0].value), "%s", sb_product_name(artifact->product));
    snprintf(attrs[n].name, sizeof(attrs[n].name), "skybake.format_version");
    snprintf(attrs[n++].value, sizeof(attrs[0].value), "%d", SB_PACK_FORMAT_VERSION);
    snprintf(attrs[n].name, sizeof(attrs[n].name), "skybake.content_hash");
    snprintf(attrs[n++].value, sizeof(attrs[0].value), "%s", artifact->content_hash);
    snprintf(attrs[n].name, sizeof(attrs[n].name), "skybake.parameterization");
    snprintf(attrs[n++].value, sizeof(attrs[0].value), "%s", artifact->parameterization);

    char path[8192];
    snprintf(path, sizeof(path), "%s/%s", w->tmp_dir, artifact->file);
    int i = w->artifact_count;
    w->artifacts[i] = *artifact;
    w->pending = w->artifacts[i].file;
    enum sb_result res;
    if (format->storage == SB_STORAGE_PROBES) {
        snprintf(artifact->probes.key, sizeof(artifact->probes.key), "%s", artifact->key);
        w->artifacts[i] = *artifact;
        res = sb_probes_write(path, &artifact->probes, image, !strcmp(format->pixel_type, "float16"));
    } else {
        res = format->storage == SB_STORAGE_VDB_HALF   ? sb_vdb_write(path, image, attrs, n)
              : format->storage == SB_STORAGE_EXR_CUBE ? sb_exr_cube_write(path, image, attrs, n)
                                                       : sb_exr_write(path, image, attrs, n);
    }
    if (!res && (res = sb_hash_file(w->tmp_fd, artifact->file, artifact->file_hash)))
        sb_error("%s: cannot read the file back: %s", path, strerror(errno));
    if (res) {
        unlink(path);
        w->pending = NULL;
        return res;
    }
    w->artifacts[i] = *artifact;
    w->artifacts[i].probes.columns = NULL; /* the caller's: the manifest needs neither */
    w->artifacts[i].probes.sight = NULL;
    w->artifacts[i].probes.tiles = NULL;
    w->artifact_count++;
    w->pending = NULL;
    fault_point("artifact");
    w->shapes[i].width = image->width;
    w->shapes[i].height = image->height;
    w->shapes[i].depth = image->depth;
    w->shapes[i].channel_count = image->channel_count;
    memcpy(w->shapes[i].channels, image->channel_names, sizeof(w->shapes[i].channels));
    return SB_OK;
}

static char *manifest_json(const struct sb_pack_writer *w, const char *scene_json, const struct sb_device_info *device)
{
    cJSON *root = cJSON_CreateObject();
    if (!root)
        return NULL;
    char scene_hash[SB_HASH_HEX_SIZE];
    sb_hash_bytes(scene_json, strlen(scene_json), scene_hash);
    cJSON_AddStringToObject(root, "format", "skybake-pack");
    cJSON_AddNumberToObject(root, "format_version", SB_PACK_FORMAT_VERSION);
    cJSON_AddStringToObject(root, "skybake_version", SKYBAKE_VERSION);
    cJSON *scene = cJSON_Parse(scene_json);
    cJSON_AddItemToObject(root, "scene", scene ? scene : cJSON_CreateNull());
    cJSON_AddStringToObject(root, "scene_hash", scene_hash);
    cJSON *dev = cJSON_AddObjectToObject(root, "device");
    cJSON_AddStringToObject(dev, "name", device->name);
    cJSON_AddStringToObject(dev, "driver", device->driver);
    cJSON_AddStringToObject(dev, "api_version", device->api_version);
    cJSON_AddNumberToObject(dev, "vendor_id", device->vendor_id);
    cJSON_AddNumberToObject(dev, "device_id", device->device_id);
    cJSON *arr = cJSON_AddArrayToObject(root, "artifacts");
    for (int i = 0; i < w->artifact_count; i++) {
        const struct sb_artifact *a = &w->artifacts[i];
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "name", sb_product_name(a->product));
        cJSON_AddStringToObject(o, "file", a->file);
        cJSON_AddNumberToObject(o, "width", w->shapes[i].width);
        cJSON_AddNumberToObject(o, "height", w->shapes[i].height);
        cJSON_AddNumberToObject(o, "depth", w->shapes[i].depth);
        cJSON *ch = cJSON_AddArrayToObject(o, "channels");
        for (uint32_t c = 0; c < w->shapes[i].channel_count; c++)
            cJSON_AddItemToArray(ch, cJSON_CreateString(w->shapes[i].channels[c]));
        cJSON_AddStringToObject(o, "pixel_type", sb_product_format(a->product)->pixel_type);
        cJSON_AddStringToObject(o, "parameterization", a->parameterization);
        cJSON *settings = cJSON_Parse(a->settings_json[0] ? a->settings_json : "{}");
        if (!cJSON_IsObject(settings)) { /* sb_pack_writer_add_image checked them: out of memory */
            cJSON_Delete(settings);
            cJSON_Delete(o);
            cJSON_Delete(root);
            return NULL;
        }
        cJSON_AddItemToObject(o, "settings", settings);
        if (a->world_hash[0]) {
            cJSON_AddStringToObject(o, "world_hash", a->world_hash);
            cJSON_AddStringToObject(o, "world_path", a->world_path);
        }
        cJSON_AddNumberToObject(o, "bake_ms", a->bake_ms);
        cJSON_AddNumberToObject(o, "gpu_ms", a->gpu_ms);
        cJSON_AddStringToObject(o, "content_hash", a->content_hash);
        cJSON_AddStringToObject(o, "file_hash", a->file_hash);
        if (a->key[0])
            cJSON_AddStringToObject(o, "key", a->key);
        cJSON_AddItemToArray(arr, o);
    }
    char *text = cJSON_Print(root);
    cJSON_Delete(root);
    return text;
}

enum sb_result sb_pack_writer_commit(struct sb_pack_writer **writer, const char *scene_json,
                                     const struct sb_device_info *device)
{
    struct sb_pack_writer *w = *writer;
    char path[8192];
    char *text = manifest_json(w, scene_json, device);
    if (!text)
        return SB_ERR_NOMEM;
    /* Scene files are read as UTF-8 only; this guards what else reaches
     * the manifest (a path, a device's name), so that it stays JSON. */
    size_t bad = sb_utf8_check(text, strlen(text));
    if (bad != SIZE_MAX) {
        sb_error("%s: the manifest would hold a byte that is not UTF-8 (byte %zu): a name or path is not UTF-8",
                 w->out_dir, bad);
        free(text);
        return SB_ERR_OUT_OF_RANGE;
    }
    snprintf(path, sizeof(path), "%s/%s", w->tmp_dir, SB_PACK_MANIFEST);
    FILE *f = fopen(path, "wb");
    bool ok = f && fputs(text, f) >= 0 && fputc('\n', f) != EOF;
    ok = f && fclose(f) == 0 && ok;
    free(text);
    if (!ok) {
        sb_error("%s: cannot write the manifest: %s", path, strerror(errno));
        return SB_ERR_IO;
    }
    fault_point("manifest");
    /* Everything reaches the disk before the pack becomes visible. */
    for (int i = 0; i < w->artifact_count; i++) {
        snprintf(path, sizeof(path), "%s/%s", w->tmp_dir, w->artifacts[i].file);
        if (fsync_path(path, false) != 0) {
            sb_error("%s: fsync failed: %s", path, strerror(errno));
            return SB_ERR_IO;
        }
    }
    snprintf(path, sizeof(path), "%s/%s", w->tmp_dir, SB_PACK_MANIFEST);
    if (fsync_path(path, false) != 0 || fsync_path(w->tmp_dir, true) != 0) {
        sb_error("%s: fsync failed: %s", w->tmp_dir, strerror(errno));
        return SB_ERR_IO;
    }

    fault_point("publish");
    struct stat st;
    w->publishing = 1;
    if (lstat(w->out_dir, &st) == 0) {
        /* Swap atomically; the old pack ends up at the temporary name. */
        if (renameat2(AT_FDCWD, w->tmp_dir, AT_FDCWD, w->out_dir, RENAME_EXCHANGE) != 0) {
            sb_error("%s: cannot replace the pack: %s", w->out_dir, strerror(errno));
            w->publishing = 0;
            return SB_ERR_IO;
        }
        fault_point("published");
        if (remove_flat_dir(w->tmp_dir) != 0)
            sb_warn("%s: the previous pack was replaced but its old copy could not be removed", w->tmp_dir);
    } else if (rename(w->tmp_dir, w->out_dir) != 0) {
        sb_error("%s: cannot publish the pack: %s", w->out_dir, strerror(errno));
        w->publishing = 0;
        return SB_ERR_IO;
    }
    char parent[4096];
    parent_of(w->out_dir, parent, sizeof(parent));
    fsync_path(parent, true);
    writer_register(w, false);
    close(w->tmp_fd);
    free(w);
    *writer = NULL;
    return SB_OK;
}

void sb_pack_writer_destroy(struct sb_pack_writer **writer)
{
    struct sb_pack_writer *w = *writer;
    if (!w)
        return;
    writer_register(w, false);
    if (remove_flat_dir(w->tmp_dir) != 0 && errno != ENOENT)
        sb_warn("%s: could not remove the temporary directory", w->tmp_dir);
    close(w->tmp_fd);
    free(w);
    *writer = NULL;
}

/* ---- Reading ------------------------------------------------------------------ */

#define PACK_MANIFEST_MAX_BYTES (1u << 20)

/* The member `key` of `object`, or NULL, logged as missing. */
static const cJSON *manifest_item(const cJSON *object, const char *key, const char *source, const char *where)
{
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(object, key);
    if (!item)
        sb_error("%s: %s%s: missing", source, where, key);
    return item;
}

/* A number member, or NULL with *res saying why. */
static const cJSON *manifest_number(const cJSON *object, const char *key, const char *source, const char *where,
                                    enum sb_result *res)
{
    const cJSON *item = manifest_item(object, key, source, where);
    *res = item ? SB_OK : SB_ERR_MISSING_FIELD;
    if (item && !cJSON_IsNumber(item)) {
        sb_error("%s: %s%s: expected a number", source, where, key);
        *res = SB_ERR_WRONG_TYPE;
        item = NULL;
    }
    return item;
}

/* A string member of `object`, copied into out[size]; absent, another type
 * or too long is an error naming where. */
static enum sb_result manifest_string(const cJSON *object, const char *key, char *out, size_t size, const char *source,
                                      const char *where)
{
    const cJSON *item = manifest_item(object, key, source, where);
    if (!item)
        return SB_ERR_MISSING_FIELD;
    if (!cJSON_IsString(item)) {
        sb_error("%s: %s%s: expected a string", source, where, key);
        return SB_ERR_WRONG_TYPE;
    }
    if (strlen(item->valuestring) >= size) {
        sb_error("%s: %s%s: longer than %zu characters", source, where, key, size - 1);
        return SB_ERR_OUT_OF_RANGE;
    }
    snprintf(out, size, "%s", item->valuestring);
    return SB_OK;
}

/* An integer member in [0, 2^32). */
static enum sb_result manifest_u32(const cJSON *object, const char *key, uint32_t *out, const char *source,
                                   const char *where)
{
    enum sb_result res;
    const cJSON *item = manifest_number(object, key, source, where, &res);
    if (!item)
        return res;
    double v = item->valuedouble;
    if (!(v >= 0 && v <= 4294967295.0) || v != floor(v)) {
        sb_error("%s: %s%s: expected an integer in [0, 2^32), got %g", source, where, key, v);
        return SB_ERR_OUT_OF_RANGE;
    }
    *out = (uint32_t)v;
    return SB_OK;
}

/* An integer member that must equal `expect`. */
static enum sb_result manifest_expect_int(const cJSON *object, const char *key, uint32_t expect, const char *source,
                                          const char *where, const char *product)
{
    enum sb_result res;
    const cJSON *item = manifest_number(object, key, source, where, &res);
    if (!item)
        return res;
    if (item->valuedouble != (double)expect) {
        sb_error("%s: %s%s: %s has %u for the pack's scene, the manifest says %g (an older skybake's, or not "
                 "this scene's: bake the pack again)",
                 source, where, key, product, expect, item->valuedouble);
        return SB_ERR_BAD_IMAGE;
    }
    return SB_OK;
}

/* The manifest's description of one artifact, checked against its product's
 * format and, for the shapes the scene sets, the pack's scene (NULL when it
 * did not read). */
static enum sb_result read_artifact_entry(const cJSON *entry, int index, struct sb_pack *pack,
                                          const struct sb_scene *scene, const char *source, enum sb_product_id *out_id,
                                          uint32_t out_shape[3])
{
    char where[64];
    snprintf(where, sizeof(where), "artifacts[%d].", index);
    if (!cJSON_IsObject(entry)) {
        sb_error("%s: artifacts[%d]: expected an object", source, index);
        return SB_ERR_WRONG_TYPE;
    }
    enum sb_result res = sb_json_check_duplicates(entry, source, where);
    char name[64];
    if (res || (res = manifest_string(entry, "name", name, sizeof(name), source, where)))
        return res;
    enum sb_product_id id;
    if (!sb_product_from_name(name, &id) || sb_product_format(id)->since_version > pack->format_version) {
        sb_error("%s: %sname: \"%s\" is not a product of format version %d", source, where, name, pack->format_version);
        return SB_ERR_UNKNOWN_PRODUCT;
    }
    if (pack->present[id]) {
        sb_error("%s: %sname: %s is listed twice", source, where, name);
        return SB_ERR_DUPLICATE_KEY;
    }
    const struct sb_product_format *format = sb_product_format(id);
    struct sb_artifact *a = &pack->artifacts[id];
    a->product = id;
    pack->present[id] = true; /* listed, whether or not the rest of the entry holds */
    if ((res = manifest_string(entry, "file", a->file, sizeof(a->file), source, where)) ||
        (res = manifest_string(entry, "content_hash", a->content_hash, sizeof(a->content_hash), source, where)) ||
        (res = manifest_string(entry, "parameterization", a->parameterization, sizeof(a->parameterization), source,
                               where)))
        return res;
    /* Version 2 on: the file's bytes are checked before they are parsed. */
    if (pack->format_version >= 2 || cJSON_GetObjectItemCaseSensitive(entry, "file_hash")) {
        if ((res = manifest_string(entry, "file_hash", a->file_hash, sizeof(a->file_hash), source, where)))
            return res;
        if (strlen(a->file_hash) != SB_HASH_HEX_SIZE - 1 ||
            strspn(a->file_hash, "0123456789abcdef") != SB_HASH_HEX_SIZE - 1) {
            sb_error("%s: %sfile_hash: \"%s\" is not 32 lowercase hex digits", source, where, a->file_hash);
            a->file_hash[0] = '\0';
            return SB_ERR_OUT_OF_RANGE;
        }
    }
    if (!a->file[0] || strchr(a->file, '/') || a->file[0] == '.') {
        sb_error("%s: %sfile: \"%s\" is not a plain file name inside the pack; refused", source, where, a->file);
        return SB_ERR_UNSAFE_PATH;
    }
    if (strcmp(a->parameterization, format->parameterization) != 0) {
        sb_error("%s: %sparameterization: \"%s\", but this build's %s is \"%s\" (docs/pack.md): bake the pack "
                 "again",
                 source, where, a->parameterization, name, format->parameterization);
        return SB_ERR_BAD_IMAGE;
    }
    if (!scene && !format->width) {
        sb_error("%s: %s: cannot be checked: its shape is the scene's, which did not read", source, name);
        return SB_ERR_BAD_IMAGE;
    }
    uint32_t shape[3] = {format->width, format->height, format->depth};
    if (scene)
        sb_product_shape(scene, id, shape);
    /* A probe grid's count follows from the world's geometry, which this
     * tier does not read: the manifest says it, the file must agree. (The
     * reflection probes' count is the scene's, checked like any shape.) */
    if (format->storage == SB_STORAGE_PROBES && !shape[0] &&
        ((res = manifest_u32(entry, "width", &shape[0], source, where)) || !shape[0] ||
         shape[0] > SB_PROBES_MAX_COUNT)) {
        sb_error("%s: %swidth: %s needs 1 to %u probes", source, where, name, SB_PROBES_MAX_COUNT);
        return res ? res : SB_ERR_OUT_OF_RANGE;
    }
    memcpy(out_shape, shape, sizeof(shape));
    if ((res = manifest_expect_int(entry, "width", shape[0], source, where, name)) ||
        (res = manifest_expect_int(entry, "height", shape[1], source, where, name)) ||
        (res = manifest_expect_int(entry, "depth", shape[2], source, where, name)))
        return res;
    char pixel_type[16];
    if ((res = manifest_string(entry, "pixel_type", pixel_type, sizeof(pixel_type), source, where)))
        return res;
    const char *want_type = sb_product_pixel_type(id, pack->format_version);
    if (strcmp(pixel_type, want_type) != 0) {
        sb_error("%s: %spixel_type: \"%s\", expected \"%s\"", source, where, pixel_type, want_type);
        return SB_ERR_BAD_IMAGE;
    }
    /* Channels: the product's, in its order. */
    const cJSON *channels = cJSON_GetObjectItemCaseSensitive(entry, "channels");
    if (!cJSON_IsArray(channels)) {
        sb_error("%s: %schannels: expected an array of names", source, where);
        return channels ? SB_ERR_WRONG_TYPE : SB_ERR_MISSING_FIELD;
    }
    char expect[4096], got[4096] = "";
    snprintf(expect, sizeof(expect), "%s", format->channel_names);
    const cJSON *c;
    cJSON_ArrayForEach(c, channels)
    {
        if (!cJSON_IsString(c) || strlen(got) + strlen(c->valuestring) + 2 > sizeof(got)) {
            sb_error("%s: %schannels: expected names", source, where);
            return SB_ERR_WRONG_TYPE;
        }
        if (got[0])
            strcat(got, ",");
        strcat(got, c->valuestring);
    }
    if (strcmp(got, expect) != 0) {
        sb_error("%s: %schannels: \"%s\", but %s has \"%s\"", source, where, got, name, expect);
        return SB_ERR_BAD_IMAGE;
    }
    const cJSON *settings = cJSON_GetObjectItemCaseSensitive(entry, "settings");
    if (cJSON_IsObject(settings) &&
        !cJSON_PrintPreallocated((cJSON *)settings, a->settings_json, (int)sizeof(a->settings_json) - 5, false))
        a->settings_json[0] = '\0';
    /* The world a probe or reflection product was baked against: its own
     * fields, or (packs of skybake before them) the same names in settings. */
    const cJSON *world = cJSON_GetObjectItemCaseSensitive(entry, "world_hash") ? entry : settings;
    if (cJSON_GetObjectItemCaseSensitive(world, "world_hash")) {
        if ((res = manifest_string(world, "world_hash", a->world_hash, sizeof(a->world_hash), source, where)))
            return res;
        if (a->world_hash[0] && (strlen(a->world_hash) != SB_HASH_HEX_SIZE - 1 ||
                                 strspn(a->world_hash, "0123456789abcdef") != SB_HASH_HEX_SIZE - 1)) {
            sb_error("%s: %sworld_hash: \"%s\" is not 32 lowercase hex digits", source, where, a->world_hash);
            a->world_hash[0] = '\0';
            return SB_ERR_OUT_OF_RANGE;
        }
        if (cJSON_GetObjectItemCaseSensitive(world, "world_path") &&
            (res = manifest_string(world, "world_path", a->world_path, sizeof(a->world_path), source, where)))
            return res;
    }
    const cJSON *ms = cJSON_GetObjectItemCaseSensitive(entry, "bake_ms");
    a->bake_ms = cJSON_IsNumber(ms) ? ms->valuedouble : 0.0;
    ms = cJSON_GetObjectItemCaseSensitive(entry, "gpu_ms");
    a->gpu_ms = cJSON_IsNumber(ms) ? ms->valuedouble : 0.0;
    /* Optional: without a key (or with one this build cannot hold) the
     * artifact is never reused, only rebaked. */
    const cJSON *key = cJSON_GetObjectItemCaseSensitive(entry, "key");
    if (cJSON_IsString(key) && strlen(key->valuestring) < sizeof(a->key))
        snprintf(a->key, sizeof(a->key), "%s", key->valuestring);
    *out_id = id;
    return SB_OK;
}

/* Read one artifact's file (a regular file, not a link, whose bytes are
 * those the manifest records) and verify its content; `shape` is what the
 * entry was checked against. */
static enum sb_result read_artifact_image(const char *dir, int dir_fd, struct sb_pack *pack, enum sb_product_id id,
                                          const uint32_t shape[3])
{
    struct sb_artifact *a = &pack->artifacts[id];
    const struct sb_product_format *format = sb_product_format(id);
    const char *name = sb_product_name(id);
    char path[8192];
    snprintf(path, sizeof(path), "%s/%s", dir, a->file);
    struct stat st;
    if (fstatat(dir_fd, a->file, &st, AT_SYMLINK_NOFOLLOW) != 0) {
        sb_error("%s: %s: cannot read %s: %s", path, name, a->file, strerror(errno));
        return SB_ERR_IO;
    }
    if (S_ISLNK(st.st_mode)) {
        sb_error("%s: %s: is a symbolic link; refused", path, name);
        return SB_ERR_UNSAFE_PATH;
    }
    if (!S_ISREG(st.st_mode)) {
        sb_error("%s: %s: not a regular file", path, name);
        return SB_ERR_IO;
    }
    if (a->file_hash[0]) {
        char hash[SB_HASH_HEX_SIZE];
        enum sb_result res = sb_hash_file(dir_fd, a->file, hash);
        if (res) {
            sb_error("%s: %s: cannot read: %s", path, name, strerror(errno));
            return res;
        }
        if (strcmp(hash, a->file_hash) != 0) {
            sb_error("%s: %s: the file's bytes hash to %s, the manifest records file_hash %s: the file was changed or "
                     "corrupted",
                     path, name, hash, a->file_hash);
            return SB_ERR_HASH_MISMATCH;
        }
    } else if (format->storage != SB_STORAGE_EXR_FLOAT32) {
        /* OpenVDB's reader is not hardened, and probe files are version 3 on:
         * never parse bytes nobody vouched for. */
        sb_error("%s: %s: no file_hash; refused", path, name);
        return SB_ERR_MISSING_FIELD;
    }
    struct sb_image *image = &pack->images[id];
    uint64_t texels = (uint64_t)shape[0] * shape[1] * shape[2];
    enum sb_result res;
    if (format->storage == SB_STORAGE_PROBES) {
        res = sb_probes_read(path, format->channel_names, shape[0], &a->probes, image);
        if (!res && strcmp(a->probes.key, a->key) != 0) {
            sb_error("%s: %s: the file was baked with key %s, the manifest records %s", path, name, a->probes.key,
                     a->key);
            res = SB_ERR_HASH_MISMATCH;
        }
        if (!res && a->probes.layer_count && pack->format_version < 7) {
            sb_error("%s: %s: a grid in layers, which format version %d cannot hold (7 and later)", path, name,
                     pack->format_version);
            res = SB_ERR_PROBES;
        }
        if (!res && a->probes.column_count && pack->format_version < 8) {
            sb_error("%s: %s: detail probes, which format version %d cannot hold (8 and later)", path, name,
                     pack->format_version);
            res = SB_ERR_PROBES;
        }
        if (!res && a->probes.half != !strcmp(sb_product_pixel_type(id, pack->format_version), "float16")) {
            sb_error("%s: %s: values stored as %s, the pack's format version %d stores %s", path, name,
                     a->probes.half ? "binary16" : "fp32", pack->format_version,
                     sb_product_pixel_type(id, pack->format_version));
            res = SB_ERR_PROBES;
        }
        if (!res && a->probes.sight && pack->format_version < 9) {
            sb_error("%s: %s: sight masks of detail probes, which format version %d cannot hold (9 and later)", path,
                     name, pack->format_version);
            res = SB_ERR_PROBES;
        }
        if (!res && a->probes.tile_count && pack->format_version < 11) {
            sb_error("%s: %s: probes in tiles, which format version %d cannot hold (11 and later)", path, name,
                     pack->format_version);
            res = SB_ERR_PROBES;
        }
        if (res)
            sb_probe_layout_finish(&a->probes);
    } else {
        res = format->storage == SB_STORAGE_VDB_HALF
                  ? sb_vdb_read(path, format->channel_names, texels, image, NULL, NULL)
              : format->storage == SB_STORAGE_EXR_CUBE
                  ? sb_exr_cube_read(path, format->channel_names, shape[0], shape[2], image)
                  : sb_exr_read(path, format->channel_names, texels, image, NULL, NULL);
    }
    if (res)
        return res;
    if (image->width != shape[0] || image->height != shape[1] || image->depth != shape[2]) {
        sb_error("%s: %s: the file is %ux%ux%u, the product %ux%ux%u", path, name, image->width, image->height,
                 image->depth, shape[0], shape[1], shape[2]);
        return SB_ERR_BAD_IMAGE;
    }
    if (sb_image_find_nonfinite(image) >= 0) {
        sb_error("%s: %s: holds NaN or Inf", path, name);
        return SB_ERR_NUMERIC;
    }
    for (uint64_t i = 0, n = sb_image_float_count(image); format->nonnegative && i < n; i++)
        if (image->data[i] < 0) {
            uint64_t texel = i / image->channel_count;
            sb_error("%s: %s: texel (%llu, %llu) channel %s is %g, and the product is a radiance (>= 0)", path, name,
                     (unsigned long long)(texel % image->width), (unsigned long long)(texel / image->width),
                     image->channel_names[i % image->channel_count], image->data[i]);
            return SB_ERR_NUMERIC;
        }
    char hash[SB_HASH_HEX_SIZE];
    if (format->storage == SB_STORAGE_PROBES)
        sb_probes_content_hash(image, &a->probes, hash);
    else
        sb_image_content_hash(image, hash);
    if (strcmp(hash, a->content_hash) != 0) {
        sb_error("%s: %s: content hash %s, the manifest records %s: the file was changed or corrupted", path, name,
                 hash, a->content_hash);
        return SB_ERR_HASH_MISMATCH;
    }
    return SB_OK;
}

/* The scene must parse as a scene file would, and its normalised form must
 * be what the scene hash names: an edited scene is as bad as an edited LUT. */
static enum sb_result read_scene(const cJSON *root, struct sb_pack *pack, const char *source)
{
    const cJSON *obj = cJSON_GetObjectItemCaseSensitive(root, "scene");
    if (!cJSON_IsObject(obj)) {
        sb_error("%s: scene: %s", source, obj ? "expected an object" : "missing");
        return obj ? SB_ERR_WRONG_TYPE : SB_ERR_MISSING_FIELD;
    }
    char scene_source[4300];
    snprintf(scene_source, sizeof(scene_source), "%s: scene", source);
    char *text = cJSON_PrintUnformatted(obj);
    pack->scene = calloc(1, sizeof(*pack->scene));
    if (!text || !pack->scene) {
        free(text);
        return SB_ERR_NOMEM;
    }
    enum sb_result res = sb_scene_parse(text, strlen(text), scene_source, pack->scene);
    free(text);
    if (res)
        return res;
    char *normal = sb_scene_normalized_json(pack->scene);
    if (!normal)
        return SB_ERR_NOMEM;
    char hash[SB_HASH_HEX_SIZE];
    sb_hash_bytes(normal, strlen(normal), hash);
    free(normal);
    if (strcmp(hash, pack->scene_hash) != 0) {
        sb_error("%s: scene: its normalised form hashes to %s, the manifest records scene_hash %s: the manifest was "
                 "edited or corrupted",
                 source, hash, pack->scene_hash);
        return SB_ERR_HASH_MISMATCH;
    }
    return SB_OK;
}

/* Problems found so far: the first one's code and how many. */
struct pack_problems {
    enum sb_result first;
    unsigned count;
};

static enum sb_result note(struct pack_problems *p, enum sb_result res)
{
    if (res) {
        if (!p->first)
            p->first = res;
        p->count++;
    }
    return res;
}

/* The manifest's header: what the rest is read as. Problems here end the
 * reading, since nothing after them can be trusted to mean anything. */
static enum sb_result read_header(const cJSON *root, struct sb_pack *pack, const char *source)
{
    char format[32];
    enum sb_result res = manifest_string(root, "format", format, sizeof(format), source, "");
    if (res)
        return res;
    if (strcmp(format, "skybake-pack") != 0) {
        sb_error("%s: format: \"%s\" is not a skybake pack", source, format);
        return SB_ERR_VERSION;
    }
    const cJSON *version = cJSON_GetObjectItemCaseSensitive(root, "format_version");
    if (!cJSON_IsNumber(version)) {
        sb_error("%s: format_version: %s", source, version ? "expected a number" : "missing");
        return version ? SB_ERR_WRONG_TYPE : SB_ERR_MISSING_FIELD;
    }
    double v = version->valuedouble;
    if (!(v >= SB_PACK_FORMAT_VERSION_OLDEST && v <= SB_PACK_FORMAT_VERSION) || v != floor(v)) {
        sb_error("%s: format_version %g; this build reads versions %d to %d: rebake needed", source, v,
                 SB_PACK_FORMAT_VERSION_OLDEST, SB_PACK_FORMAT_VERSION);
        return SB_ERR_VERSION;
    }
    pack->format_version = (int)v;
    return SB_OK;
}

static enum sb_result read_device(const cJSON *root, struct sb_device_info *d, const char *source)
{
    const cJSON *device = cJSON_GetObjectItemCaseSensitive(root, "device");
    if (!cJSON_IsObject(device)) {
        sb_error("%s: device: %s", source, device ? "expected an object" : "missing");
        return device ? SB_ERR_WRONG_TYPE : SB_ERR_MISSING_FIELD;
    }
    struct pack_problems p = {0};
    note(&p, manifest_string(device, "name", d->name, sizeof(d->name), source, "device."));
    note(&p, manifest_string(device, "driver", d->driver, sizeof(d->driver), source, "device."));
    note(&p, manifest_string(device, "api_version", d->api_version, sizeof(d->api_version), source, "device."));
    note(&p, manifest_u32(device, "vendor_id", &d->vendor_id, source, "device."));
    note(&p, manifest_u32(device, "device_id", &d->device_id, source, "device."));
    return p.first;
}

/* Files in the pack's directory that its manifest does not list. */
static void find_unlisted(const char *dir, const struct sb_pack *pack, struct pack_problems *p)
{
    DIR *d = opendir(dir);
    if (!d)
        return; /* already reported: the manifest could not be read either */
    struct dirent *e;
    while ((e = readdir(d))) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..") || !strcmp(e->d_name, SB_PACK_MANIFEST))
            continue;
        bool listed = false;
        for (int i = 0; i < SB_PRODUCT_COUNT && !listed; i++)
            listed = pack->present[i] && !strcmp(pack->artifacts[i].file, e->d_name);
        if (!listed) {
            sb_error("%s/%s: not listed in the manifest", dir, e->d_name);
            note(p, SB_ERR_UNLISTED_FILE);
        }
    }
    closedir(d);
}

/* Read and verify the pack, going on past every problem that leaves the
 * rest readable, so that each is logged. */
static enum sb_result pack_read(const char *dir, struct sb_pack *pack, unsigned *problem_count)
{
    memset(pack, 0, sizeof(*pack));
    struct pack_problems p = {0};
    char source[4200];
    snprintf(source, sizeof(source), "%s/%s", dir, SB_PACK_MANIFEST);
    int dir_fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir_fd < 0) {
        sb_error("%s: cannot open the pack: %s", dir, strerror(errno));
        note(&p, SB_ERR_IO);
        goto done;
    }
    cJSON *root = NULL;
    enum sb_result res = sb_json_load(dir_fd, SB_PACK_MANIFEST, source, PACK_MANIFEST_MAX_BYTES, false, &root);
    if (!res && !cJSON_IsObject(root)) {
        sb_error("%s: expected a JSON object", source);
        res = SB_ERR_WRONG_TYPE;
    }
    if (!res)
        res = sb_json_check_duplicates(root, source, "");
    if (!res)
        res = read_header(root, pack, source);
    if (note(&p, res))
        goto done_root;
    note(&p,
         manifest_string(root, "skybake_version", pack->skybake_version, sizeof(pack->skybake_version), source, ""));
    bool scene_ok = false;
    if (!note(&p, manifest_string(root, "scene_hash", pack->scene_hash, sizeof(pack->scene_hash), source, "")))
        scene_ok = !note(&p, read_scene(root, pack, source));
    note(&p, read_device(root, &pack->device, source));
    const cJSON *artifacts = cJSON_GetObjectItemCaseSensitive(root, "artifacts");
    if (!cJSON_IsArray(artifacts)) {
        sb_error("%s: artifacts: %s", source, artifacts ? "expected an array" : "missing");
        note(&p, artifacts ? SB_ERR_WRONG_TYPE : SB_ERR_MISSING_FIELD);
        goto done_root;
    }
    /* Every entry is checked before any pixel is read. */
    int index = 0;
    const cJSON *entry;
    bool entry_ok[SB_PRODUCT_COUNT] = {0};
    uint32_t entry_shape[SB_PRODUCT_COUNT][3] = {{0}};
    cJSON_ArrayForEach(entry, artifacts)
    {
        enum sb_product_id id;
        if (index >= PACK_MAX_ARTIFACTS) {
            sb_error("%s: artifacts: more than %d entries", source, PACK_MAX_ARTIFACTS);
            note(&p, SB_ERR_OUT_OF_RANGE);
            break;
        }
        uint32_t shape[3];
        if (!note(&p, read_artifact_entry(entry, index++, pack, scene_ok ? pack->scene : NULL, source, &id, shape))) {
            entry_ok[id] = true;
            memcpy(entry_shape[id], shape, sizeof(shape));
        }
    }
    for (int i = 0; i < SB_PRODUCT_COUNT; i++) {
        if (!entry_ok[i])
            continue;
        note(&p, read_artifact_image(dir, dir_fd, pack, (enum sb_product_id)i, entry_shape[i]));
    }
    find_unlisted(dir, pack, &p);
done_root:
    cJSON_Delete(root);
done:
    if (dir_fd >= 0)
        close(dir_fd);
    if (p.first)
        sb_pack_close(pack);
    if (problem_count)
        *problem_count = p.count;
    return p.first;
}

enum sb_result sb_pack_open(const char *dir, struct sb_pack *pack)
{
    return pack_read(dir, pack, NULL);
}

enum sb_result sb_pack_verify(const char *dir, unsigned *problem_count)
{
    struct sb_pack *pack = malloc(sizeof(*pack));
    if (!pack) {
        *problem_count = 1;
        return SB_ERR_NOMEM;
    }
    enum sb_result res = pack_read(dir, pack, problem_count);
    sb_pack_close(pack);
    free(pack);
    return res;
}

void sb_pack_close(struct sb_pack *pack)
{
    for (int p = 0; p < SB_PRODUCT_COUNT; p++) {
        sb_image_finish(&pack->images[p]);
        sb_probe_layout_finish(&pack->artifacts[p].probes);
    }
    free(pack->scene);
    memset(pack, 0, sizeof(*pack));
}
