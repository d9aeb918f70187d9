#include "product.h"

#include <string.h>

#include "config.h"
#include "family.h"
#include "probes.h"

#define CLOUD_PARAMETERIZATION "tileable-texel-centers-v1"
static const struct sb_product_format product_formats[SB_PRODUCT_COUNT] = {
    [SB_PRODUCT_TRANSMITTANCE] = {"transmittance", SB_TRANSMITTANCE_WIDTH, SB_TRANSMITTANCE_HEIGHT, 1,
                                  SB_TRANSMITTANCE_CHANNELS, "r,g,b", "transmittance-hillaire2020-v1", 1,
                                  SB_STORAGE_EXR_FLOAT32, "float32", "exr", SB_FAMILY_ATMOSPHERE},
    [SB_PRODUCT_MULTISCATTERING] = {"multiscattering", SB_MULTISCATTERING_SIZE, SB_MULTISCATTERING_SIZE, 1,
                                    SB_MULTISCATTERING_CHANNELS, "r,g,b", "multiscattering-hillaire2020-subtexel-v1", 1,
                                    SB_STORAGE_EXR_FLOAT32, "float32", "exr", SB_FAMILY_ATMOSPHERE},
    [SB_PRODUCT_IRRADIANCE_GROUND] = {"irradiance_ground", SB_IRRADIANCE_WIDTH, SB_IRRADIANCE_HEIGHT, 1,
                                      SB_IRRADIANCE_GROUND_CHANNELS, "direct.r,direct.g,direct.b,sky.r,sky.g,sky.b",
                                      "irradiance-bruneton2017-subtexel-v1", 1, SB_STORAGE_EXR_FLOAT32, "float32",
                                      "exr", SB_FAMILY_ATMOSPHERE},
    [SB_PRODUCT_IRRADIANCE_SKY] = {"irradiance_sky", SB_IRRADIANCE_WIDTH, SB_IRRADIANCE_HEIGHT, 1,
                                   SB_IRRADIANCE_SKY_CHANNELS,
                                   "rayleigh.r,rayleigh.g,rayleigh.b,mie.r,mie.g,mie.b,ground.r,ground.g,ground.b",
                                   "irradiance-bruneton2017-subtexel-v1", 1, SB_STORAGE_EXR_FLOAT32, "float32", "exr",
                                   SB_FAMILY_ATMOSPHERE},
    [SB_PRODUCT_CLOUD_SHAPE] = {"cloud_shape", 0, 0, 0, 4, "perlin_worley,worley.0,worley.1,worley.2",
                                CLOUD_PARAMETERIZATION, 2, SB_STORAGE_VDB_HALF, "float16", "vdb", SB_FAMILY_CLOUDS},
    [SB_PRODUCT_CLOUD_DETAIL] = {"cloud_detail", 0, 0, 0, 3, "worley.0,worley.1,worley.2", CLOUD_PARAMETERIZATION, 2,
                                 SB_STORAGE_VDB_HALF, "float16", "vdb", SB_FAMILY_CLOUDS},
    [SB_PRODUCT_CLOUD_CURL] = {"cloud_curl", 0, 0, 1, 3, "curl.x,curl.y,curl.z", CLOUD_PARAMETERIZATION, 2,
                               SB_STORAGE_EXR_FLOAT32, "float32", "exr", SB_FAMILY_CLOUDS},
    [SB_PRODUCT_WEATHER] = {"weather", 0, 0, 1, 3, "coverage,precipitation,type", CLOUD_PARAMETERIZATION, 2,
                            SB_STORAGE_EXR_FLOAT32, "float32", "exr", SB_FAMILY_CLOUDS},
    [SB_PRODUCT_SKY_VISIBILITY] = {"sky_visibility", 0, 1, 1, SB_SKY_VISIBILITY_CHANNEL_COUNT,
                                   SB_SKY_VISIBILITY_CHANNELS, "probes-sh2-fibonacci-v1", 3, SB_STORAGE_PROBES,
                                   "float32", "sbprobes", SB_FAMILY_PROBES},
    [SB_PRODUCT_SKY_BOUNCE] = {"sky_bounce", 0, 1, 1, SB_SKY_BOUNCE_CHANNEL_COUNT, SB_SKY_BOUNCE_CHANNELS,
                               "probes-bounce-sh1x2-fibonacci-v1", 4, SB_STORAGE_PROBES, "float32", "sbprobes",
                               SB_FAMILY_PROBES},
    [SB_PRODUCT_DFG] = {"dfg", SB_DFG_SIZE, SB_DFG_SIZE, 1, 2, "dfg.x,dfg.y", "dfg-ggx-smith-nv-roughness-v1", 5,
                        SB_STORAGE_EXR_FLOAT32, "float32", "exr", SB_FAMILY_REFLECTIONS},
    [SB_PRODUCT_REFLECTION_CUBES] = {"reflection_cubes", 0, 0, 0, 3, "R,G,B", "cube-exr-ggx-filament-lod-v1", 6,
                                     SB_STORAGE_EXR_CUBE, "float32", "exr", SB_FAMILY_REFLECTIONS},
    [SB_PRODUCT_REFLECTION_PROBES] = {"reflection_probes", 0, 1, 1, SB_REFLECTION_PROBES_CHANNEL_COUNT,
                                      SB_REFLECTION_PROBES_CHANNELS, "reflection-probes-sh2-irradiance-v1", 6,
                                      SB_STORAGE_PROBES, "float32", "sbprobes", SB_FAMILY_REFLECTIONS},
};

const struct sb_product_format *sb_product_format(enum sb_product_id id)
{
    return &product_formats[id];
}

const char *sb_product_name(enum sb_product_id id)
{
    return (unsigned)id < SB_PRODUCT_COUNT ? product_formats[id].name : "unknown";
}

bool sb_product_from_name(const char *name, enum sb_product_id *id)
{
    for (int p = 0; p < SB_PRODUCT_COUNT; p++)
        if (strcmp(name, product_formats[p].name) == 0) {
            *id = (enum sb_product_id)p;
            return true;
        }
    return false;
}
