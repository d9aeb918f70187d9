/*
 * A pass's temporal history: what the frame before saw (its camera, its
 * sun, its view-projection), and the rule by which this frame may blend
 * with it. The fog and the clouds share it; their images are histories of
 * the render graph (graph.h), pairs that swap after each frame.
 */
#ifndef SB_RUNTIME_HISTORY_H
#define SB_RUNTIME_HISTORY_H

#include <stdbool.h>

#include "transform.h"

struct sb_renderer;

/* Zero-initialised: no history. */
struct sb_history {
    bool valid;
    struct sb_mat4 view_proj; /* the last frame's, camera-relative */
    double camera_m[3];
    double sun[3]; /* toward the key light (the sun, or the moon at night): unit, world axes */
};

/* What this frame reads of the history. */
struct sb_history_step {
    /* Whether to blend with it: there is one, the exposure was not snapped,
     * and the key light (the sun, or the moon at night) moved less than
     * SB_SUN_HISTORY_LIMIT_DEG since. */
    bool keep;
    struct sb_mat4 previous_view_proj; /* the last frame's (zero before the first) */
    double camera_motion_m[3];         /* this frame's camera minus the last one's */
    double scale_ratio;                /* this frame's scale over the one the history was stored at */
};

/* This frame's step from the history, then the history becomes this frame
 * (r->view, r->view_proj): call once a frame, when the pass runs. */
void sb_history_advance(struct sb_history *history, const struct sb_renderer *r, struct sb_history_step *step);

/* A frame that leaves the pass out: the history goes stale, and the next
 * frame starts anew. */
void sb_history_drop(struct sb_history *history);

#endif
