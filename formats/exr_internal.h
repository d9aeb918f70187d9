/*
 * What skybake's two EXR writers and readers share (exr.c: scanline
 * images; exr_cube.c: tiled mip-mapped cube maps): OpenEXR's errors
 * reported as skybake's, and a compressor that keeps a chunk raw where
 * ZIP does not shrink it. Internal to formats/.
 */
#ifndef SB_EXR_INTERNAL_H
#define SB_EXR_INTERNAL_H

#include <openexr.h>
#include <stdbool.h>

#include "image.h"
#include "result.h"

/* For exr_context_initializer_t.error_handler_fn: keeps OpenEXR's message
 * for the thread's next sb_exr_fail instead of printing it. */
void sb_exr_error_handler(exr_const_context_t ctxt, exr_result_t code, const char *msg);

/* Log "path: what: OpenEXR's reason" and map the code (SB_ERR_IO for file
 * access and writes, else SB_ERR_EXR). */
enum sb_result sb_exr_fail(const char *path, const char *what, exr_result_t rv);

/*
 * exr_start_read on `path`, through a descriptor of ours: only a regular
 * file is opened (io.h's sb_open_regular: a FIFO cannot block the reader),
 * and OpenEXR reads it with pread. *fd receives the descriptor (-1 on
 * failure); it must outlive the context: close it after exr_finish. Logs
 * and returns SB_ERR_IO or SB_ERR_EXR on failure.
 */
enum sb_result sb_exr_start_read(const char *path, exr_context_initializer_t *init, exr_context_t *ctxt, int *fd);

/* Run `call`; on failure set `res` from sb_exr_fail and go to `cleanup`. */
#define SB_EXR_TRY(call, what)                                                                                         \
    do {                                                                                                               \
        exr_result_t rv_ = (call);                                                                                     \
        if (rv_ != EXR_ERR_SUCCESS) {                                                                                  \
            res = sb_exr_fail(path, what, rv_);                                                                        \
            goto cleanup;                                                                                              \
        }                                                                                                              \
    } while (0)

/*
 * After exr_encoding_choose_default_routines: wrap the encoder's
 * compressor so that a chunk whose compressed size is not smaller than its
 * raw size is stored raw. OpenEXR 3.1's ZIP keeps a stream exactly as long
 * as the raw bytes, which its reader (and every reader) then takes as raw:
 * corrupt pixels (OpenEXR issue 2306, fixed in 3.4.7).
 */
void sb_exr_keep_raw_when_larger(exr_encode_pipeline_t *encoder);

/* Where channel `name` is in the image, or channel_count. */
uint32_t sb_exr_channel_index(const struct sb_image *image, const char *name);

/* Point a coder's channels (encode_from_ptr, or decode_to_ptr when
 * `decode`) at pixel (x0, y0) of a level that starts at `base` and is
 * `width` wide, the image's channels interleaved as float. False when a
 * channel is not the image's. */
bool sb_exr_point_channels(exr_coding_channel_info_t *channels, int16_t count, const struct sb_image *image,
                           float *base, uint32_t width, int32_t x0, int32_t y0, bool decode);

/* How a writer's chunks are found: chunk `index`'s info
 * (exr_write_scanline_chunk_info or exr_write_tile_chunk_info), and its
 * channels pointed at the image's pixels (false: a channel the image does
 * not have). Both are called from several threads at once. */
struct sb_exr_chunks {
    exr_result_t (*info)(void *user, exr_context_t ctxt, int part, int index, exr_chunk_info_t *cinfo);
    bool (*point)(void *user, int index, exr_coding_channel_info_t *channels, int16_t count);
    void *user;
};

/*
 * Encode and write chunks 0 to count - 1 of `part` (the file's chunk
 * order), after its header: compressed on sb_parallel_for's threads (ZIP
 * is most of a large file's time), written in order, each with its own
 * coder (sb_exr_keep_raw_when_larger's), so that the file's bytes do not
 * depend on the thread count. Returns SB_OK or the first failure, logged
 * naming `path`; the chunks after a failure are not written.
 */
enum sb_result sb_exr_write_chunks(exr_context_t ctxt, const char *path, int part, int count,
                                   const struct sb_exr_chunks *chunks);

#endif
