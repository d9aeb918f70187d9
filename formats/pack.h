/*
 * Packs: a directory holding manifest.json and one file per artifact.
 * This header reads and verifies packs and writes them atomically (the
 * products they hold are named in product.h): everything goes into a temporary directory beside the
 * destination, which is renamed into place only when complete, so a failed
 * bake leaves the previous pack as it was. docs/pack.md describes the format.
 */
#ifndef SB_PACK_H
#define SB_PACK_H

#include <stdbool.h>
#include <stdint.h>

#include "exr.h"
#include "image.h"
#include "probes.h"
#include "product.h"
#include "result.h"

/* This build writes SB_PACK_FORMAT_VERSION (product.h, the last of
 * products.def's) and reads it and every older one (each a subset of the
 * next; docs/pack.md). */
#define SB_PACK_FORMAT_VERSION_OLDEST 1
#define SB_PACK_MANIFEST "manifest.json"

/* One artifact of a manifest. Strings are copied when the artifact is added. */
struct sb_artifact {
    enum sb_product_id product;
    char file[64];             /* relative to the pack, no directories */
    char parameterization[64]; /* mapping id, see docs/pack.md */
    char settings_json[1024];  /* compact JSON object of the bake settings */
    double bake_ms;            /* wall time of the product's bake, host side */
    double gpu_ms;             /* GPU time between the product's timestamps */
    char content_hash[SB_HASH_HEX_SIZE];
    char file_hash[SB_HASH_HEX_SIZE]; /* of the file's bytes; "" in a version 1 pack */
    char key[SB_HASH_HEX_SIZE];       /* the bake key (baker/bake.h); "" when not recorded */
    /* The world a probe or reflection product was baked against: its
     * geometry's hash (geometry/mesh.h, sb_mesh_hash) and its file as the
     * baker read it (absolute, UTF-8; "" when not known); "" for the rest. */
    char world_hash[SB_HASH_HEX_SIZE];
    char world_path[1024];
    struct sb_probe_layout probes; /* where a probe product's probes are (its file's header) */
};

/* Record the world an artifact was baked against. A path that is not UTF-8
 * or does not fit is recorded as "" (skyview then needs --world), with a
 * warning. */
void sb_artifact_set_world(struct sb_artifact *artifact, const char *world_hash, const char *world_path);

struct sb_device_info {
    char name[256];
    char driver[2 * 256 + 2];
    char api_version[32];
    uint32_t vendor_id;
    uint32_t device_id;
};

struct sb_pack_writer;

/*
 * Begin a pack that will replace `out_dir`. Refuses (SB_ERR_IO) when out_dir
 * exists and is neither an empty directory nor a pack, or when its parent
 * cannot be written. The returned writer owns a temporary directory.
 */
enum sb_result sb_pack_writer_create(const char *out_dir, struct sb_pack_writer **writer);

/* Write one artifact's file into the pack (EXR or VDB, as its product is
 * stored) and record it; fills artifact->content_hash from the image and
 * artifact->file_hash from the file. A product stored as half must hold
 * binary16 values already (sb_image_round_to_half), so that its content
 * hash is that of what the file holds. */
enum sb_result sb_pack_writer_add_image(struct sb_pack_writer *writer, struct sb_artifact *artifact,
                                        const struct sb_image *image);

/*
 * Write the manifest, flush everything to disk and rename the pack into
 * place. scene_json is the normalised scene (sb_scene_normalized_json).
 * On success the writer is destroyed and *writer set to NULL.
 */
enum sb_result sb_pack_writer_commit(struct sb_pack_writer **writer, const char *scene_json,
                                     const struct sb_device_info *device);

/* Abandon the pack: remove the temporary directory. Accepts NULL. */
void sb_pack_writer_destroy(struct sb_pack_writer **writer);

/*
 * Remove the temporary directory of every writer not yet publishing, with
 * async-signal-safe calls only: for a SIGINT or SIGTERM handler, which then
 * ends the process. (A writer killed outright leaves its directory, named
 * NAME.tmp-PID-XXXXXX; the next writer for NAME removes it once that
 * process is gone.)
 */
void sb_pack_writers_remove_temporaries(void);

/*
 * A pack as read back: the manifest's fields and every artifact's image
 * (volumes: depth > 1), each verified. Products the pack does not hold have
 * present[id] false.
 */

struct sb_pack {
    int format_version;
    char skybake_version[32];
    char scene_hash[SB_HASH_HEX_SIZE];
    struct sb_scene *scene; /* owned: the scene it was baked from (scene.h) */
    struct sb_device_info device;
    bool present[SB_PRODUCT_COUNT];
    struct sb_artifact artifacts[SB_PRODUCT_COUNT];
    struct sb_image images[SB_PRODUCT_COUNT];
};

/*
 * Read the pack in `dir` and verify all of it before returning: the
 * manifest (at most 1 MiB, strict JSON, no key twice), its format version
 * (SB_ERR_VERSION for one this build does not read: "rebake needed", never
 * a guess), every artifact's name (a product of this version, at most once),
 * file (a plain name inside the pack, not a symbolic link), dimensions,
 * channels and pixel type against the product's format (checked before any
 * pixel is read), the file's bytes against its file_hash (version 2 on;
 * before the file is parsed), the EXR or VDB itself, that it holds only
 * finite values, and its content hash against the manifest's; the scene the manifest records
 * (a valid scene, whose normalised form hashes to scene_hash); and that the
 * pack holds no file the manifest does not list. Every problem is logged
 * naming the pack, the artifact and the reason; the first one's code is
 * returned, and *pack is then empty. A pack is untrusted input whatever its
 * hashes say (docs/pack.md): its VDB files are parsed in a helper
 * process (vdb.h, sandbox.h), so the caller sees a child come and go.
 */
enum sb_result sb_pack_open(const char *dir, struct sb_pack *pack);

/*
 * Everything sb_pack_open checks, and files in the pack that the manifest
 * does not list (SB_ERR_UNLISTED_FILE), going on past each problem that
 * leaves the rest readable, so that every one is logged: each artifact's
 * entry and file is checked whatever the others' state. Returns the first
 * problem's code (SB_OK when all holds); *problem_count counts them.
 * sb_pack_open reads the same way.
 */
enum sb_result sb_pack_verify(const char *dir, unsigned *problem_count);

/* Free the images; accepts an empty or closed pack. */
void sb_pack_close(struct sb_pack *pack);

#endif
