/*
 * skyview's interactive viewer: a renderer's frames in a window (window.h),
 * a fly camera, the sun under the keys, passes switched on and off, and an
 * overlay of each pass's GPU time. The keys:
 *   W A S D       move along the view, Q E down and up (Shift: 10x faster)
 *   mouse drag    look (either button held)
 *   arrow keys    the sun: left and right turn its azimuth, up and down raise
 *                 and lower it; with a sun path, left and right move the hour
 *   1 to 7        switch fog, clouds, the Purkinje shift, local tone mapping,
 *                 scene-linear grading, bloom, the display LUT
 *   H or F1       the overlay; P a screenshot (OUT_DIR/screenshot_NNNN.png);
 *                 Escape quits.
 */
#ifndef SB_RUNTIME_VIEWER_H
#define SB_RUNTIME_VIEWER_H

#include <stdbool.h>

#include "renderer.h"
#include "sun_path.h"
#include "window.h"

struct sb_viewer_params {
    struct sb_view view;                /* where the camera and the sun start */
    const struct sb_sun_path *sun_path; /* non-NULL: the sun from the path at `hour` */
    double hour;
    bool moon;              /* with sun_path: the moon of its place too */
    int frames;             /* 0: until the window closes; N: N frames, each 1/60 s after the last, then close
                               (the headless frames' timing, so frame N is theirs) */
    const char *screenshot; /* with frames: the swapchain's last image as PNG here */
    const char *out_dir;    /* where P writes screenshots */
    bool overlay;           /* start with the timing overlay shown */
};

/* The sun of `path` at `hour` into `view`, and the moon too where the path
 * has a place and `moon` is set (otherwise view->moon is left as it is). */
void sb_view_at_hour(struct sb_view *view, const struct sb_sun_path *path, double hour, bool moon);

/* Run until the window closes (or the frames are done). */
enum sb_result sb_viewer_run(struct sb_renderer *renderer, struct sb_window *window,
                             const struct sb_viewer_params *params);

/* The overlay: each pass's GPU time (0 for those left out) and the state
 * lines, drawn into an RGBA frame of width x height, top left. */
void sb_viewer_draw_overlay(uint8_t *rgba, uint32_t width, uint32_t height, const struct sb_frame_timings *timings,
                            uint32_t disabled_passes, const char *const *lines, int line_count);

#endif
