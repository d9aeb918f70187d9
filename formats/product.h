/*
 * The products a pack may hold, as its format names and stores them: one
 * row of product.c's table a product, and the families that bake them
 * (family.h). Files and scenes read this table; it reads neither.
 */
#ifndef SB_PRODUCT_H
#define SB_PRODUCT_H

#include <stdbool.h>
#include <stdint.h>

enum sb_product_id {
    /* The atmosphere (format version 1 on). */
    SB_PRODUCT_TRANSMITTANCE,
    SB_PRODUCT_MULTISCATTERING,
    SB_PRODUCT_IRRADIANCE_GROUND,
    SB_PRODUCT_IRRADIANCE_SKY,
    /* Cloud noise (format version 2 on). */
    SB_PRODUCT_CLOUD_SHAPE,
    SB_PRODUCT_CLOUD_DETAIL,
    SB_PRODUCT_CLOUD_CURL,
    SB_PRODUCT_WEATHER,
    /* Probes over the scene's world (format version 3 on). */
    SB_PRODUCT_SKY_VISIBILITY,
    SB_PRODUCT_SKY_BOUNCE, /* format version 4 on */
    /* Reflections (format version 5 on). */
    SB_PRODUCT_DFG,
    SB_PRODUCT_REFLECTION_CUBES,  /* format version 6 on */
    SB_PRODUCT_REFLECTION_PROBES, /* format version 6 on */
    SB_PRODUCT_COUNT,
};

/* Ids below this are the atmosphere's, the rest cloud noise. */
#define SB_ATMOSPHERE_PRODUCT_COUNT SB_PRODUCT_CLOUD_SHAPE

static inline bool sb_product_is_cloud(enum sb_product_id id)
{
    return id >= SB_PRODUCT_CLOUD_SHAPE && id <= SB_PRODUCT_WEATHER;
}

/* Families of products: each is one file of its own per tier plus a row in
 * the family tables (formats/family.h, baker/family.h). */
enum sb_family {
    SB_FAMILY_ATMOSPHERE,
    SB_FAMILY_CLOUDS,
    SB_FAMILY_PROBES,
    SB_FAMILY_REFLECTIONS,
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
    const char *pixel_type; /* the manifest's pixel_type: "float32", "float16" */
    const char *extension;  /* of its file: "exr", "vdb" */
    enum sb_family family;
};

const struct sb_product_format *sb_product_format(enum sb_product_id id);
const char *sb_product_name(enum sb_product_id id);
bool sb_product_from_name(const char *name, enum sb_product_id *id);

#endif
