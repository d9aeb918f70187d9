#include "history.h"

#include <math.h>
#include <string.h>

#include "renderer_internal.h"

void sb_history_advance(struct sb_history *h, const struct sb_renderer *r, struct sb_history_step *step)
{
    const struct sb_view *v = r->view;
    const double *sun = r->key_direction; /* the light the fog and the clouds are lit by */
    step->keep =
        h->valid && !v->snap_exposure &&
        sun[0] * h->sun[0] + sun[1] * h->sun[1] + sun[2] * h->sun[2] > cos(SB_SUN_HISTORY_LIMIT_DEG * M_PI / 180.0);
    step->previous_view_proj = h->view_proj;
    for (int k = 0; k < 3; k++)
        step->camera_motion_m[k] = v->camera_m[k] - h->camera_m[k];
    step->scale_ratio = r->frame_scale / r->previous_frame_scale;
    h->view_proj = r->view_proj;
    memcpy(h->camera_m, v->camera_m, sizeof(h->camera_m));
    memcpy(h->sun, sun, sizeof(h->sun));
    h->valid = true;
}

void sb_history_drop(struct sb_history *h)
{
    h->valid = false;
}
