#include "result.h"

/* The one table of outcomes: a short stable name and what it means. */
static const struct {
    const char *name, *description;
} results[SB_RESULT_COUNT] = {
    [SB_OK] = {"ok", "success"},
    [SB_ERR_IO] = {"io", "a file could not be opened, read, written or renamed"},
    [SB_ERR_NOMEM] = {"out-of-memory", "an allocation failed"},
    [SB_ERR_JSON_SYNTAX] = {"json-syntax", "not well-formed JSON"},
    [SB_ERR_UNKNOWN_KEY] = {"unknown-key", "a key the schema does not define"},
    [SB_ERR_DUPLICATE_KEY] = {"duplicate-key", "a key or artifact given twice"},
    [SB_ERR_WRONG_TYPE] = {"wrong-type", "a value of the wrong JSON type"},
    [SB_ERR_OUT_OF_RANGE] = {"out-of-range", "a value outside its documented domain"},
    [SB_ERR_MISSING_FIELD] = {"missing-field", "a required key is absent"},
    [SB_ERR_UNKNOWN_PRESET] = {"unknown-preset", "a preset name skybake does not know"},
    [SB_ERR_UNKNOWN_PRODUCT] = {"unknown-product", "a product name skybake does not know"},
    [SB_ERR_EXR] = {"exr", "OpenEXR refused the file or the data"},
    [SB_ERR_BAD_IMAGE] = {"bad-image", "an image whose shape, channels or type are not the product's"},
    [SB_ERR_NO_DEVICE] = {"no-device", "no Vulkan device, or none matching --device"},
    [SB_ERR_VULKAN] = {"vulkan", "a Vulkan call failed"},
    [SB_ERR_VALIDATION] = {"validation", "the Vulkan validation layers reported a message"},
    [SB_ERR_NUMERIC] = {"numeric", "NaN, Inf or a value outside the product's range"},
    [SB_ERR_USAGE] = {"usage", "bad command line"},
    [SB_ERR_DEVICE_LIMIT] = {"device-limit",
                             "a kernel needs more than the device offers, or the device ended it early"},
    [SB_ERR_VERSION] = {"version", "a pack of a format this build does not read: rebake needed"},
    [SB_ERR_HASH_MISMATCH] = {"hash-mismatch", "content that differs from the hash recorded for it"},
    [SB_ERR_UNSAFE_PATH] = {"unsafe-path", "a path that leaves the pack or goes through a symbolic link"},
    [SB_ERR_TOLERANCE] = {"tolerance", "no setting of a product reaches the scene's tolerance"},
    [SB_ERR_UNLISTED_FILE] = {"unlisted-file", "a file in a pack that its manifest does not list"},
    [SB_ERR_VDB] = {"vdb", "OpenVDB refused the file or the data"},
    [SB_ERR_MESH] = {"mesh", "a mesh file assimp refuses, or one with no usable triangle"},
    [SB_ERR_TOO_LARGE] = {"too-large", "a file or count past its documented cap"},
    [SB_ERR_PROBES] = {"probes", "not a probe file, or a header field out of range"},
};

const char *sb_result_name(enum sb_result result)
{
    return (unsigned)result < SB_RESULT_COUNT ? results[result].name : "unknown";
}

const char *sb_result_description(enum sb_result result)
{
    return (unsigned)result < SB_RESULT_COUNT ? results[result].description : "an unknown outcome";
}
