/*
 * The products a pack may hold, as its format names and stores them: one
 * row of products.def a product, and the families that bake them
 * (family.h). Files and scenes read this table; it reads neither.
 */
#ifndef SB_PRODUCT_H
#define SB_PRODUCT_H

#include <stdbool.h>
#include <stdint.h>

/* The pack format's versions (products.def); this build writes the last. */
enum sb_format_version {
    SB_FORMAT_VERSION_NONE,
#define SB_FORMAT_VERSION(version, what) SB_FORMAT_VERSION_##version,
#include "products.def"
    SB_FORMAT_VERSION_NEXT,
};
#define SB_PACK_FORMAT_VERSION ((int)SB_FORMAT_VERSION_NEXT - 1)

enum sb_product_id {
#define SB_PRODUCT(id, family, since, ...) SB_PRODUCT_##id,
#include "products.def"
    SB_PRODUCT_COUNT,
};

/* Ids below this are the atmosphere's, the rest cloud noise. */
#define SB_ATMOSPHERE_PRODUCT_COUNT SB_PRODUCT_CLOUD_SHAPE

static inline bool sb_product_is_cloud(enum sb_product_id id)
{
    return id >= SB_PRODUCT_CLOUD_SHAPE && id <= SB_PRODUCT_WEATHER;
}

/* Families of products: each is one file of its own per tier plus its rows
 * in products.def. */
enum sb_family {
#define SB_FAMILY(id, name) SB_FAMILY_##id,
#include "products.def"
    SB_FAMILY_COUNT,
};

/* How an artifact is stored. */
enum sb_storage {
    SB_STORAGE_EXR_FLOAT32, /* EXR, FLOAT channels (exr.h) */
    SB_STORAGE_VDB_HALF,    /* OpenVDB, one half-stored FloatGrid per channel (vdb.h) */
    SB_STORAGE_PROBES,      /* skybake's probe file, one fp32 record a probe (probes.h) */
    SB_STORAGE_EXR_CUBE,    /* EXR, a tiled mip-mapped cube a part, FLOAT channels (exr.h) */
};

/* What a product's file holds in this format version. */
struct sb_product_format {
    const char *name;              /* "transmittance", ..., "cloud_shape", "cloud_detail", "cloud_curl", "weather" */
    uint32_t width, height, depth; /* 0: set by the scene (sb_product_shape, family.h) */
    uint32_t channel_count;
    const char *channel_names;    /* comma-separated, in storage order */
    const char *parameterization; /* mapping id, see docs/pack.md */
    int since_version;            /* the first format version holding the product */
    enum sb_storage storage;
    const char *pixel_type;   /* the manifest's pixel_type: "float32", "float16" */
    int half_since;           /* a probe product stored as float16 from this format version on, float32 before; 0 */
    const char *extension;    /* of its file: "exr", "vdb" */
    bool nonnegative;         /* every value >= 0 (a radiance): a reader refuses a negative one */
    bool named_only;          /* baked only when a scene names it, not by default */
    const char *no_tolerance; /* why a scene's tolerance does not apply to it (its family's, else); NULL */
    enum sb_family family;
};

const struct sb_product_format *sb_product_format(enum sb_product_id id);
const char *sb_product_name(enum sb_product_id id);
/* The pixel_type of the product's files in packs of `format_version`. */
const char *sb_product_pixel_type(enum sb_product_id id, int format_version);
bool sb_product_from_name(const char *name, enum sb_product_id *id);

#endif
