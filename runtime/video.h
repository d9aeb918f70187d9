/*
 * A video of skyview's frames through ffmpeg, the encoder Debian packages:
 * frames go to an ffmpeg child process on a pipe as raw RGBA and come out
 * H.264 (yuv420p, CRF 18, the rate players expect) in an MP4. The file is
 * written under a temporary name beside the target and renamed into place
 * only when ffmpeg exits cleanly, so a failed encode leaves nothing. One
 * thread at a time.
 */
#ifndef SB_RUNTIME_VIDEO_H
#define SB_RUNTIME_VIDEO_H

#include <stdbool.h>
#include <stdint.h>

#include "result.h"

/* Whether an `ffmpeg` program is on PATH (executable). */
bool sb_video_encoder_found(void);

struct sb_video;

/*
 * Start encoding `path` (.mp4): width x height frames (an odd size is
 * padded by one black row or column: H.264's 4:2:0 needs even sizes) at
 * `fps` frames a second. SB_ERR_IO, with a message naming the file, when
 * ffmpeg cannot be started.
 */
enum sb_result sb_video_create(const char *path, uint32_t width, uint32_t height, double fps, struct sb_video **video);

/* Send one frame: width * height * 4 bytes, sRGB RGBA, top row first. */
enum sb_result sb_video_write(struct sb_video *video, const uint8_t *rgba);

/* Finish: close the pipe, wait for ffmpeg, rename the file into place when
 * `keep` and all went well (the result says), else remove it. Accepts a
 * pointer to NULL; sets *video to NULL. */
enum sb_result sb_video_destroy(struct sb_video **video, bool keep);

#endif
