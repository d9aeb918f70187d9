/*
 * The closed set of outcomes of every reader, writer and check in skybake.
 * Tests compare codes, never message strings; messages for people are logged
 * where the error is found and name the file, the field and the reason.
 */
#ifndef SB_RESULT_H
#define SB_RESULT_H

enum sb_result {
    SB_OK = 0,
    SB_ERR_IO,              /* a file could not be opened, read, written or renamed */
    SB_ERR_NOMEM,           /* an allocation failed */
    SB_ERR_JSON_SYNTAX,     /* not well-formed JSON */
    SB_ERR_UNKNOWN_KEY,     /* a key the schema does not define */
    SB_ERR_DUPLICATE_KEY,   /* a key given twice in one object */
    SB_ERR_WRONG_TYPE,      /* a value of the wrong JSON type */
    SB_ERR_OUT_OF_RANGE,    /* a value outside its documented domain */
    SB_ERR_MISSING_FIELD,   /* a required key is absent */
    SB_ERR_UNKNOWN_PRESET,  /* a preset name skybake does not know */
    SB_ERR_UNKNOWN_PRODUCT, /* a product name skybake does not know */
    SB_ERR_EXR,             /* OpenEXR refused the file or the data */
    SB_ERR_BAD_IMAGE,       /* an image whose shape or channels are not the expected ones */
    SB_ERR_NO_DEVICE,       /* no Vulkan device (or none matching --device) */
    SB_ERR_VULKAN,          /* a Vulkan call failed */
    SB_ERR_VALIDATION,      /* the validation layers reported a message */
    SB_ERR_NUMERIC,         /* a product holds NaN, Inf or a value outside its range */
    SB_ERR_USAGE,           /* bad command line */
    SB_ERR_DEVICE_LIMIT,    /* a kernel needs more than the device offers, or it ended it early */
    SB_ERR_VERSION,         /* a pack of a format version this build does not read: rebake needed */
    SB_ERR_HASH_MISMATCH,   /* an artifact's content differs from the hash its manifest records */
    SB_ERR_UNSAFE_PATH,     /* a path that leaves the pack or goes through a symbolic link */
    SB_ERR_TOLERANCE,       /* no setting of a product reaches the scene's tolerance */
    SB_ERR_UNLISTED_FILE,   /* a pack holds a file its manifest does not list */
    SB_ERR_VDB,             /* OpenVDB refused the file or the data */
    SB_ERR_MESH,            /* a mesh file assimp refuses, or one with no usable triangle */
    SB_ERR_TOO_LARGE,       /* a file or count past its documented cap, refused before allocating */
    SB_ERR_PROBES,          /* not a probe file, or a header field out of range */
    SB_RESULT_COUNT,
};

/* Short stable name of a code, e.g. "out-of-range"; "unknown" outside the
 * set. Never NULL. */
const char *sb_result_name(enum sb_result result);

/* What a code means, in a few words. Never NULL. */
const char *sb_result_description(enum sb_result result);

#endif
