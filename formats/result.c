#include "result.h"

static const char *const result_names[SB_RESULT_COUNT] = {
    [SB_OK] = "ok",
    [SB_ERR_IO] = "io",
    [SB_ERR_NOMEM] = "out-of-memory",
    [SB_ERR_JSON_SYNTAX] = "json-syntax",
    [SB_ERR_UNKNOWN_KEY] = "unknown-key",
    [SB_ERR_DUPLICATE_KEY] = "duplicate-key",
    [SB_ERR_WRONG_TYPE] = "wrong-type",
    [SB_ERR_OUT_OF_RANGE] = "out-of-range",
    [SB_ERR_MISSING_FIELD] = "missing-field",
    [SB_ERR_UNKNOWN_PRESET] = "unknown-preset",
    [SB_ERR_UNKNOWN_PRODUCT] = "unknown-product",
    [SB_ERR_EXR] = "exr",
    [SB_ERR_BAD_IMAGE] = "bad-image",
    [SB_ERR_NO_DEVICE] = "no-device",
    [SB_ERR_VULKAN] = "vulkan",
    [SB_ERR_VALIDATION] = "validation",
    [SB_ERR_NUMERIC] = "numeric",
    [SB_ERR_USAGE] = "usage",
    [SB_ERR_DEVICE_LIMIT] = "device-limit",
    [SB_ERR_VERSION] = "version",
    [SB_ERR_HASH_MISMATCH] = "hash-mismatch",
    [SB_ERR_UNSAFE_PATH] = "unsafe-path",
    [SB_ERR_TOLERANCE] = "tolerance",
};

const char *sb_result_name(enum sb_result result)
{
    if ((unsigned)result >= SB_RESULT_COUNT)
        return "unknown";
    return result_names[result];
}
