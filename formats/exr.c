#include "exr.h"

#include <errno.h>
#include <fcntl.h>
#include <openexr.h>
#include <pthread.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "exr_internal.h"
#include "io.h"
#include "log.h"
#include "parallel.h"

#define EXR_DEFAULT_MAX_PIXELS (64ull << 20)

/* OpenEXR's own message for the last error of this thread: it names the
 * system's reason (e.g. "File too large"), which the codes do not. */
static _Thread_local char last_message[256];

void sb_exr_error_handler(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    (void)ctxt;
    snprintf(last_message, sizeof(last_message), "%s", msg ? msg : "");
    sb_debug("openexr: %s (%d)", msg, (int)code);
}

enum sb_result sb_exr_fail(const char *path, const char *what, exr_result_t rv)
{
    sb_error("%s: %s: %s%s%s", path, what, exr_get_default_error_message(rv), last_message[0] ? ": " : "",
             last_message);
    last_message[0] = '\0';
    return rv == EXR_ERR_FILE_ACCESS || rv == EXR_ERR_WRITE_IO ? SB_ERR_IO : SB_ERR_EXR;
}

static int64_t read_fd(exr_const_context_t ctxt, void *user, void *buffer, uint64_t size, uint64_t offset,
                       exr_stream_error_func_ptr_t error_cb)
{
    int fd = *(const int *)user;
    uint8_t *p = buffer;
    uint64_t done = 0;
    while (done < size) {
        ssize_t n = pread(fd, p + done, size - done, (off_t)(offset + done));
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0) {
            error_cb(ctxt, EXR_ERR_READ_IO, "cannot read: %s", strerror(errno));
            return -1;
        }
        if (n == 0)
            break;
        done += (uint64_t)n;
    }
    return (int64_t)done;
}

static int64_t size_fd(exr_const_context_t ctxt, void *user)
{
    (void)ctxt;
    struct stat st;
    return fstat(*(const int *)user, &st) == 0 ? (int64_t)st.st_size : -1;
}

enum sb_result sb_exr_start_read(const char *path, exr_context_initializer_t *init, exr_context_t *ctxt, int *fd)
{
    *ctxt = NULL;
    *fd = sb_open_regular(AT_FDCWD, path, true, path);
    if (*fd < 0)
        return SB_ERR_IO;
    init->user_data = fd;
    init->read_fn = read_fd;
    init->size_fn = size_fd;
    exr_result_t rv = exr_start_read(ctxt, path, init);
    if (rv != EXR_ERR_SUCCESS) {
        sb_error("%s: not a readable EXR file: %s", path, exr_get_default_error_message(rv));
        close(*fd);
        *fd = -1;
        *ctxt = NULL;
        return rv == EXR_ERR_FILE_ACCESS || rv == EXR_ERR_READ_IO ? SB_ERR_IO : SB_ERR_EXR;
    }
    return SB_OK;
}

static _Thread_local exr_result_t (*library_compress)(exr_encode_pipeline_t *);

static exr_result_t compress_or_keep(exr_encode_pipeline_t *encode)
{
    exr_result_t rv = library_compress(encode);
    if (rv == EXR_ERR_SUCCESS && encode->compressed_bytes >= encode->packed_bytes) {
        if (encode->compressed_alloc_size < encode->packed_bytes)
            return EXR_ERR_OUT_OF_MEMORY;
        memcpy(encode->compressed_buffer, encode->packed_buffer, encode->packed_bytes);
        encode->compressed_bytes = encode->packed_bytes;
    }
    return rv;
}

void sb_exr_keep_raw_when_larger(exr_encode_pipeline_t *encoder)
{
    if (encoder->compress_fn && encoder->compress_fn != compress_or_keep) {
        library_compress = encoder->compress_fn;
        encoder->compress_fn = compress_or_keep;
    }
}

/* Where channel `name` is in the image, or channel_count. */
uint32_t sb_exr_channel_index(const struct sb_image *image, const char *name)
{
    uint32_t c = 0;
    while (c < image->channel_count && strcmp(image->channel_names[c], name) != 0)
        c++;
    return c;
}

/* Point a coder's channels at pixel (x0, y0) of a level that starts at
 * `base` and is `width` wide, the image's channels interleaved. */
bool sb_exr_point_channels(exr_coding_channel_info_t *channels, int16_t count, const struct sb_image *image,
                           float *base, uint32_t width, int32_t x0, int32_t y0, bool decode)
{
    size_t pixel = (size_t)image->channel_count * sizeof(float);
    base += ((size_t)y0 * width + (size_t)x0) * image->channel_count;
    for (int16_t ch = 0; ch < count; ch++) {
        exr_coding_channel_info_t *info = &channels[ch];
        uint32_t c = sb_exr_channel_index(image, info->channel_name);
        if (c == image->channel_count)
            return false;
        if (decode)
            info->decode_to_ptr = (uint8_t *)(base + c);
        else
            info->encode_from_ptr = (const uint8_t *)(base + c);
        info->user_pixel_stride = (int32_t)pixel;
        info->user_line_stride = (int32_t)(pixel * width);
        info->user_bytes_per_element = 4;
        info->user_data_type = EXR_PIXEL_FLOAT;
    }
    return true;
}

/*
 * The chunks of a part, compressed on every thread and written in order.
 * sb_parallel_for hands the indices out in increasing order; a chunk
 * compresses as soon as it is taken, then waits for its turn (OpenEXR's
 * yield_until_ready_fn) until every chunk before it is written. Each chunk
 * has its own coder, so the bytes are the same whatever the thread count.
 */
struct chunk_writer {
    exr_context_t ctxt;
    const char *path;
    int part;
    const struct sb_exr_chunks *chunks;
    pthread_mutex_t lock;
    pthread_cond_t turn;
    int written;        /* chunks in the file, in order */
    enum sb_result res; /* the first failure; the chunks after it give up */
};

struct chunk_turn {
    struct chunk_writer *w;
    int index;
    exr_result_t (*library_yield)(exr_encode_pipeline_t *);
    exr_result_t (*library_write)(exr_encode_pipeline_t *);
};

static exr_result_t wait_for_turn(exr_encode_pipeline_t *encoder)
{
    struct chunk_turn *t = encoder->encoding_user_data;
    struct chunk_writer *w = t->w;
    pthread_mutex_lock(&w->lock);
    while (w->written < t->index && !w->res)
        pthread_cond_wait(&w->turn, &w->lock);
    bool go = !w->res;
    pthread_mutex_unlock(&w->lock);
    return go ? t->library_yield(encoder) : EXR_ERR_INCORRECT_CHUNK;
}

static exr_result_t write_and_pass(exr_encode_pipeline_t *encoder)
{
    struct chunk_turn *t = encoder->encoding_user_data;
    exr_result_t rv = t->library_write(encoder);
    if (rv == EXR_ERR_SUCCESS) {
        pthread_mutex_lock(&t->w->lock);
        t->w->written++;
        pthread_cond_broadcast(&t->w->turn);
        pthread_mutex_unlock(&t->w->lock);
    }
    return rv;
}

/* Log the chunk's failure (`what` NULL: its channels are not the
 * image's) unless an earlier one stopped the part. */
static void chunk_failed(struct chunk_writer *w, const char *what, exr_result_t rv)
{
    pthread_mutex_lock(&w->lock);
    if (!w->res && what)
        w->res = sb_exr_fail(w->path, what, rv);
    else if (!w->res) {
        sb_error("%s: a channel of the file is not the image's", w->path);
        w->res = SB_ERR_EXR;
    }
    pthread_cond_broadcast(&w->turn);
    pthread_mutex_unlock(&w->lock);
}

static void write_chunk(void *user, int index)
{
    struct chunk_writer *w = user;
    struct chunk_turn turn = {.w = w, .index = index};
    exr_encode_pipeline_t encoder = EXR_ENCODE_PIPELINE_INITIALIZER;
    exr_chunk_info_t cinfo;
    const char *what = NULL;
    exr_result_t rv = w->chunks->info(w->chunks->user, w->ctxt, w->part, index, &cinfo);
    if (rv != EXR_ERR_SUCCESS)
        what = "preparing a chunk";
    else if ((rv = exr_encoding_initialize(w->ctxt, w->part, &cinfo, &encoder)) != EXR_ERR_SUCCESS) {
        chunk_failed(w, "starting the encoder", rv);
        return;
    }
    if (!what && !w->chunks->point(w->chunks->user, index, encoder.channels, encoder.channel_count))
        chunk_failed(w, NULL, rv);
    else if (!what && (rv = exr_encoding_choose_default_routines(w->ctxt, w->part, &encoder)) != EXR_ERR_SUCCESS)
        what = "choosing the encoder";
    else if (!what) {
        sb_exr_keep_raw_when_larger(&encoder);
        turn.library_yield = encoder.yield_until_ready_fn;
        turn.library_write = encoder.write_fn;
        encoder.yield_until_ready_fn = wait_for_turn;
        encoder.write_fn = write_and_pass;
        encoder.encoding_user_data = &turn;
        if ((rv = exr_encoding_run(w->ctxt, w->part, &encoder)) != EXR_ERR_SUCCESS)
            what = "encoding";
    }
    if (what)
        chunk_failed(w, what, rv);
    if (encoder.context)
        exr_encoding_destroy(w->ctxt, &encoder);
}

enum sb_result sb_exr_write_chunks(exr_context_t ctxt, const char *path, int part, int count,
                                   const struct sb_exr_chunks *chunks)
{
    struct chunk_writer w = {.ctxt = ctxt, .path = path, .part = part, .chunks = chunks};
    pthread_mutex_init(&w.lock, NULL);
    pthread_cond_init(&w.turn, NULL);
    sb_parallel_for(count, write_chunk, &w);
    pthread_cond_destroy(&w.turn);
    pthread_mutex_destroy(&w.lock);
    return w.res;
}

struct scanlines {
    const struct sb_image *image;
    int32_t lines_per_chunk;
};

static exr_result_t scanline_info(void *user, exr_context_t ctxt, int part, int index, exr_chunk_info_t *cinfo)
{
    const struct scanlines *s = user;
    return exr_write_scanline_chunk_info(ctxt, part, index * s->lines_per_chunk, cinfo);
}

static bool point_scanlines(void *user, int index, exr_coding_channel_info_t *channels, int16_t count)
{
    const struct scanlines *s = user;
    return sb_exr_point_channels(channels, count, s->image, s->image->data, s->image->width, 0,
                                 index * s->lines_per_chunk, false);
}

enum sb_result sb_exr_write(const char *path, const struct sb_image *image, const struct sb_attribute *attributes,
                            int attribute_count)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = sb_exr_error_handler;
    exr_context_t ctxt = NULL;
    enum sb_result res = SB_OK;
    exr_result_t rv;
    int part = 0;

    if (image->depth != 1) {
        sb_error("%s: a volume (depth %u) cannot be written as an EXR image", path, image->depth);
        return SB_ERR_BAD_IMAGE;
    }
    rv = exr_start_write(&ctxt, path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv != EXR_ERR_SUCCESS) {
        sb_error("%s: cannot create EXR file: %s", path, exr_get_default_error_message(rv));
        return SB_ERR_IO;
    }

    SB_EXR_TRY(exr_add_part(ctxt, "main", EXR_STORAGE_SCANLINE, &part), "adding the part");
    SB_EXR_TRY(exr_initialize_required_attr_simple(ctxt, part, (int32_t)image->width, (int32_t)image->height,
                                                   EXR_COMPRESSION_ZIP),
               "setting the header");
    for (uint32_t c = 0; c < image->channel_count; c++)
        SB_EXR_TRY(exr_add_channel(ctxt, part, image->channel_names[c], EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LINEAR, 1, 1),
                   "adding a channel");
    for (int a = 0; a < attribute_count; a++)
        SB_EXR_TRY(exr_attr_set_string(ctxt, part, attributes[a].name, attributes[a].value), "setting an attribute");
    SB_EXR_TRY(exr_write_header(ctxt), "writing the header");

    struct scanlines lines = {.image = image, .lines_per_chunk = 1};
    int32_t chunks = 0;
    SB_EXR_TRY(exr_get_scanlines_per_chunk(ctxt, part, &lines.lines_per_chunk), "querying chunks");
    SB_EXR_TRY(exr_get_chunk_count(ctxt, part, &chunks), "querying chunks");
    const struct sb_exr_chunks each = {.info = scanline_info, .point = point_scanlines, .user = &lines};
    res = sb_exr_write_chunks(ctxt, path, part, chunks, &each);

cleanup:
    rv = exr_finish(&ctxt);
    if (rv != EXR_ERR_SUCCESS && res == SB_OK) {
        sb_error("%s: finishing the EXR file: %s", path, exr_get_default_error_message(rv));
        res = SB_ERR_IO;
    }
    return res;
}

enum sb_result sb_exr_read(const char *path, const char *channel_order, uint64_t max_pixels, struct sb_image *image,
                           struct sb_attribute *attributes, int *attribute_count)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = sb_exr_error_handler;
    exr_context_t ctxt = NULL;
    exr_decode_pipeline_t decoder;
    bool decoder_live = false;
    enum sb_result res = SB_OK;
    int map[SB_IMAGE_MAX_CHANNELS]; /* file channel -> image channel */

    memset(image, 0, sizeof(*image));
    if (attribute_count)
        *attribute_count = 0;
    if (!max_pixels)
        max_pixels = EXR_DEFAULT_MAX_PIXELS;

    int fd;
    if ((res = sb_exr_start_read(path, &init, &ctxt, &fd)))
        return res;
    int parts = 0;
    SB_EXR_TRY(exr_get_count(ctxt, &parts), "counting parts");
    exr_storage_t storage;
    SB_EXR_TRY(exr_get_storage(ctxt, 0, &storage), "reading the storage type");
    if (parts != 1 || storage != EXR_STORAGE_SCANLINE) {
        sb_error("%s: expected one scanline part, found %d part(s)", path, parts);
        res = SB_ERR_BAD_IMAGE;
        goto cleanup;
    }
    exr_attr_box2i_t window;
    SB_EXR_TRY(exr_get_data_window(ctxt, 0, &window), "reading the data window");
    int64_t width = (int64_t)window.max.x - window.min.x + 1, height = (int64_t)window.max.y - window.min.y + 1;
    if (width <= 0 || height <= 0 || (uint64_t)(width * height) > max_pixels) {
        sb_error("%s: data window %lldx%lld is empty or larger than %llu pixels", path, (long long)width,
                 (long long)height, (unsigned long long)max_pixels);
        res = SB_ERR_BAD_IMAGE;
        goto cleanup;
    }
    const exr_attr_chlist_t *chlist = NULL;
    SB_EXR_TRY(exr_get_channels(ctxt, 0, &chlist), "reading the channel list");
    int file_channels = chlist->num_channels;
    if (file_channels <= 0 || file_channels > SB_IMAGE_MAX_CHANNELS) {
        sb_error("%s: %d channels; skybake images have 1 to %d", path, file_channels, SB_IMAGE_MAX_CHANNELS);
        res = SB_ERR_BAD_IMAGE;
        goto cleanup;
    }
    for (int c = 0; c < file_channels; c++) {
        const exr_attr_chlist_entry_t *e = &chlist->entries[c];
        if (e->x_sampling != 1 || e->y_sampling != 1 || e->pixel_type == EXR_PIXEL_UINT) {
            sb_error("%s: channel %s is subsampled or not a float channel", path, e->name.str);
            res = SB_ERR_BAD_IMAGE;
            goto cleanup;
        }
    }

    /* Decide the image's channel order. */
    struct sb_image tmp = {0};
    uint32_t count = (uint32_t)file_channels;
    if (channel_order) {
        sb_image_set_channel_names(&tmp, channel_order);
        count = 0;
        while (count < SB_IMAGE_MAX_CHANNELS && tmp.channel_names[count][0])
            count++;
        if (count != (uint32_t)file_channels) {
            sb_error("%s: %d channels, expected %u (%s)", path, file_channels, count, channel_order);
            res = SB_ERR_BAD_IMAGE;
            goto cleanup;
        }
    }
    for (int c = 0; c < file_channels; c++) {
        const char *name = chlist->entries[c].name.str;
        map[c] = c;
        if (channel_order) {
            map[c] = -1;
            for (uint32_t k = 0; k < count; k++)
                if (strcmp(tmp.channel_names[k], name) == 0)
                    map[c] = (int)k;
            if (map[c] < 0) {
                sb_error("%s: unexpected channel %s (expected %s)", path, name, channel_order);
                res = SB_ERR_BAD_IMAGE;
                goto cleanup;
            }
        }
    }
    res = sb_image_init(image, (uint32_t)width, (uint32_t)height, count);
    if (res)
        goto cleanup;
    for (int c = 0; c < file_channels; c++)
        snprintf(image->channel_names[map[c]], SB_CHANNEL_NAME_MAX, "%s", chlist->entries[c].name.str);

    int32_t lines_per_chunk = 1, chunks = 0;
    SB_EXR_TRY(exr_get_scanlines_per_chunk(ctxt, 0, &lines_per_chunk), "querying chunks");
    SB_EXR_TRY(exr_get_chunk_count(ctxt, 0, &chunks), "querying chunks");
    size_t pixel_stride = (size_t)count * sizeof(float);
    for (int32_t chunk = 0; chunk < chunks; chunk++) {
        int32_t y = window.min.y + chunk * lines_per_chunk;
        exr_chunk_info_t cinfo;
        SB_EXR_TRY(exr_read_scanline_chunk_info(ctxt, 0, y, &cinfo), "reading a chunk");
        if (!decoder_live) {
            SB_EXR_TRY(exr_decoding_initialize(ctxt, 0, &cinfo, &decoder), "starting the decoder");
            decoder_live = true;
        } else {
            SB_EXR_TRY(exr_decoding_update(ctxt, 0, &cinfo, &decoder), "updating the decoder");
        }
        int64_t row = (int64_t)cinfo.start_y - window.min.y;
        if (row < 0 || row + cinfo.height > height || cinfo.width != width) {
            sb_error("%s: chunk %d lies outside the data window", path, chunk);
            res = SB_ERR_EXR;
            goto cleanup;
        }
        for (int16_t ch = 0; ch < decoder.channel_count; ch++) {
            exr_coding_channel_info_t *info = &decoder.channels[ch];
            int dst = -1;
            for (int c = 0; c < file_channels; c++)
                if (strcmp(chlist->entries[c].name.str, info->channel_name) == 0)
                    dst = map[c];
            if (dst < 0) {
                res = SB_ERR_EXR;
                goto cleanup;
            }
            info->decode_to_ptr = (uint8_t *)(image->data + (size_t)row * width * count + dst);
            info->user_pixel_stride = (int32_t)pixel_stride;
            info->user_line_stride = (int32_t)(pixel_stride * width);
            info->user_bytes_per_element = 4;
            info->user_data_type = EXR_PIXEL_FLOAT;
        }
        if (chunk == 0)
            SB_EXR_TRY(exr_decoding_choose_default_routines(ctxt, 0, &decoder), "choosing the decoder");
        SB_EXR_TRY(exr_decoding_run(ctxt, 0, &decoder), "decoding");
    }

    if (attributes && attribute_count) {
        int32_t n = 0;
        SB_EXR_TRY(exr_get_attribute_count(ctxt, 0, &n), "counting attributes");
        for (int32_t i = 0; i < n && *attribute_count < SB_FILE_MAX_ATTRIBUTES; i++) {
            const exr_attribute_t *attr = NULL;
            if (exr_get_attribute_by_index(ctxt, 0, EXR_ATTR_LIST_FILE_ORDER, i, &attr) != EXR_ERR_SUCCESS)
                continue;
            if (attr->type != EXR_ATTR_STRING || strncmp(attr->name, "skybake.", 8) != 0)
                continue;
            struct sb_attribute *out = &attributes[(*attribute_count)++];
            snprintf(out->name, sizeof(out->name), "%s", attr->name);
            snprintf(out->value, sizeof(out->value), "%.*s", attr->string->length, attr->string->str);
        }
    }

cleanup:
    if (decoder_live)
        exr_decoding_destroy(ctxt, &decoder);
    exr_finish(&ctxt);
    close(fd);
    if (res)
        sb_image_finish(image);
    return res;
}
