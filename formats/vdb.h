/*
 * OpenVDB files of skybake volumes. OpenVDB (C++, no C API) runs only in
 * the helper program skybake-vdb (vdb.cpp, the one C++ file of skybake;
 * vdb_helper.h), never in the caller, whose start it slowed by 60 ms.
 *
 * A volume of C channels is C FloatGrids (VDB has no 4-vector grid), each
 * named after its channel, in channel order:
 * - class fog volume, background 0;
 * - dense: every voxel of the volume is active and stored in its leaf node;
 *   nothing is pruned to tiles, whatever the values;
 * - voxel (i, j, k) = texel (x, y, z); the index-to-world transform scales by
 *   1 / N per axis and shifts by half a voxel, so that world coordinates are
 *   the texture's coordinates in [0, 1)^3 (voxel centres at (i + 0.5) / N);
 * - stored as binary16 ("save float as half"), Blosc-compressed with the
 *   active mask;
 * - string metadata: the `attributes` (skybake.product, .format_version,
 *   .content_hash, .parameterization) on every grid and on the file.
 * The file's UUID, which OpenVDB draws at random, is derived from the
 * volume's content hash and the attributes, so that the same volume always
 * gives the same bytes.
 */
#ifndef SB_VDB_H
#define SB_VDB_H

#include <stdint.h>

#include "image.h"

#ifdef __cplusplus
extern "C" {
#endif

/*
 * Write `volume` to `path` (created or replaced). Every value must already
 * be a binary16 value (sb_image_round_to_half): the file stores binary16,
 * and a value that is not one is refused (SB_ERR_NUMERIC) rather than
 * silently changed. The helper serialises the volume; the caller writes
 * the file. Returns SB_OK, SB_ERR_IO (naming the system's reason, or the
 * helper's absence), SB_ERR_VDB (OpenVDB failed, or its process) or
 * SB_ERR_NUMERIC, logging the path and the reason. Thread-safe.
 */
enum sb_result sb_vdb_write(const char *path, const struct sb_image *volume, const struct sb_attribute *attributes,
                            int attribute_count);

/*
 * Read a file written by sb_vdb_write into `volume` (fp32, exact: binary16
 * values widened). The grids must be the channels named in channel_order
 * ("r,g,b"), in that order, and nothing else; each a dense fog-volume
 * FloatGrid stored as half whose active voxels are exactly the box from the
 * origin to the volume's size, the same for every grid. Files larger than
 * 1 GiB, and volumes of more than max_voxels voxels (0: 2^28), are refused
 * before their grids are read. String metadata whose names start with
 * "skybake." (the first grid's, which every grid must repeat) are returned
 * in `attributes` (may be NULL; at most SB_FILE_MAX_ATTRIBUTES).
 * Returns SB_OK, SB_ERR_IO, SB_ERR_VDB (OpenVDB refused the file) or
 * SB_ERR_BAD_IMAGE (a file that is not such a volume), logging the path and
 * the reason; *volume is then empty. Thread-safe.
 *
 * OpenVDB's reader is not hardened against hostile files, so the file's
 * layout is checked first (header, metadata, each grid's offsets within the
 * file) and OpenVDB parses the grids in a helper process under CPU-time,
 * memory and wall-clock limits (sandbox.h; the program skybake-vdb,
 * installed beside the library in libexecdir/skybake): a crafted file gets
 * SB_ERR_VDB, never a crash or a hang of the caller.
 */
enum sb_result sb_vdb_read(const char *path, const char *channel_order, uint64_t max_voxels, struct sb_image *volume,
                           struct sb_attribute *attributes, int *attribute_count);

#ifdef __cplusplus
}
#endif

#endif
