#include "viewer.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "log.h"
#include "moon.h"
#include "pngfile.h"
#include "text.h"

#define DEG (M_PI / 180.0)
#define MOVE_M_S 5.0         /* the camera's speed; Shift: 10x */
#define LOOK_DEG_PER_PX 0.15 /* the mouse's turn */
#define SUN_AZIMUTH_DEG_S 30.0
#define SUN_ELEVATION_DEG_S 10.0
#define HOURS_PER_S 1.0

static void shade_box(uint8_t *rgba, uint32_t width, uint32_t height, uint32_t w, uint32_t h)
{
    for (uint32_t y = 0; y < h && y < height; y++)
        for (uint32_t x = 0; x < w && x < width; x++) {
            uint8_t *p = rgba + ((size_t)y * width + x) * 4;
            for (int k = 0; k < 3; k++)
                p[k] = (uint8_t)(p[k] / 3);
        }
}

void sb_viewer_draw_overlay(uint8_t *rgba, uint32_t width, uint32_t height, const struct sb_frame_timings *timings,
                            uint32_t disabled_passes, const char *const *lines, int line_count)
{
    static const uint8_t ink[4] = {240, 240, 240, 255}, dim[4] = {130, 130, 130, 255};
    uint32_t scale = height >= 600 ? 2 : 1;
    uint32_t advance = (SB_TEXT_GLYPH_H + 3) * scale, margin = 4 * scale;
    char text[128];
    int rows = line_count + SB_PASS_COUNT + 1;
    uint32_t box_w = 0;
    for (int i = 0; i < line_count; i++)
        box_w = box_w > sb_text_width(lines[i], scale) ? box_w : sb_text_width(lines[i], scale);
    uint32_t table_w = 30 * SB_TEXT_ADVANCE * scale;
    box_w = (box_w > table_w ? box_w : table_w) + 2 * margin;
    shade_box(rgba, width, height, box_w, (uint32_t)rows * advance + 2 * margin);
    int y = (int)margin;
    for (int i = 0; i < line_count; i++, y += (int)advance)
        sb_text_draw(rgba, width, height, (int)margin, y, scale, lines[i], ink);
    for (int p = 0; p <= SB_PASS_COUNT; p++, y += (int)advance) {
        bool off = p < SB_PASS_COUNT && disabled_passes >> p & 1;
        double ms = !timings || !timings->valid ? 0.0 : p < SB_PASS_COUNT ? timings->ms[p] : timings->total_ms;
        snprintf(text, sizeof(text), "%-20s %8.3f ms%s", p < SB_PASS_COUNT ? sb_pass_name((enum sb_pass)p) : "frame",
                 ms, off ? "  off" : "");
        sb_text_draw(rgba, width, height, (int)margin, y, scale, text, off ? dim : ink);
    }
}

void sb_view_at_hour(struct sb_view *view, const struct sb_sun_path *path, double hour, bool moon)
{
    sb_sun_path_at(path, hour, &view->sun_elevation, &view->sun_azimuth);
    struct sb_moon_position m;
    if (moon && sb_moon_path_at(path, hour, &m)) {
        view->moon = true;
        view->moon_elevation = m.elevation;
        view->moon_azimuth = m.azimuth;
        view->moon_distance_km = SB_MOON_RADIUS_KM / sin(m.angular_radius); /* from the place */
    }
}

enum sb_result sb_viewer_run(struct sb_renderer *r, struct sb_window *window, const struct sb_viewer_params *params)
{
    uint32_t width, height;
    sb_renderer_size(r, &width, &height);
    size_t bytes = (size_t)width * height * 4;
    uint8_t *frame = malloc(bytes), *shot = malloc(bytes);
    if (!frame || !shot) {
        free(frame);
        free(shot);
        return SB_ERR_NOMEM;
    }
    struct sb_view view = params->view;
    double hour = params->hour;
    bool overlay = params->overlay, want_shot = false;
    uint32_t disabled = 0, toggles[SB_PASS_COUNT];
    int shots = 0, toggle_count = sb_pass_toggles(toggles);
    struct sb_frame_timings timings = {0};
    double last = sb_now_s(), fps = 0.0;
    enum sb_result res = SB_OK;
    for (int i = 0; !res && (params->frames <= 0 || i < params->frames); i++) {
        struct sb_window_input in;
        sb_window_poll(window, &in);
        if (in.close)
            break;
        double now = sb_now_s();
        double dt = params->frames > 0 ? 1.0 / 60.0 : fmin(now - last, 0.25);
        fps = i == 0 ? 0.0 : 0.9 * fps + 0.1 / fmax(now - last, 1e-6);
        last = now;

        /* The camera: along the view's heading, and up. */
        double speed = MOVE_M_S * (in.fast ? 10.0 : 1.0) * dt;
        double f = (in.forward - in.back) * speed, s = (in.right - in.left) * speed;
        view.camera_m[0] += sin(view.yaw) * f + cos(view.yaw) * s;
        view.camera_m[2] += -cos(view.yaw) * f + sin(view.yaw) * s;
        view.camera_m[1] = fmax(-SB_CAMERA_LOWEST_M, view.camera_m[1] + (in.up - in.down) * speed);
        view.yaw += in.look_dx * LOOK_DEG_PER_PX * DEG;
        view.pitch = fmin(fmax(view.pitch - in.look_dy * LOOK_DEG_PER_PX * DEG, -89.0 * DEG), 89.0 * DEG);
        /* The sun: by hand, or along the path. */
        if (params->sun_path) {
            hour = fmin(fmax(hour + (in.sun_right - in.sun_left) * HOURS_PER_S * dt, 0.0), 48.0);
            sb_view_at_hour(&view, params->sun_path, hour, params->moon);
        } else {
            view.sun_azimuth += (in.sun_right - in.sun_left) * SUN_AZIMUTH_DEG_S * DEG * dt;
            view.sun_elevation =
                fmin(fmax(view.sun_elevation + (in.sun_up - in.sun_down) * SUN_ELEVATION_DEG_S * DEG * dt, -90.0 * DEG),
                     90.0 * DEG);
        }
        for (int k = 1; k <= toggle_count && k <= 9; k++) /* keys 1 to 9 switch the passes' toggles */
            if (in.pressed_digits >> k & 1)
                disabled ^= toggles[k - 1];
        overlay ^= in.toggle_overlay;
        want_shot |= in.screenshot;

        view.disabled_passes = disabled;
        view.isolate_passes = overlay; /* its times, each pass's own */
        view.snap_exposure = i == 0;
        view.dt_s = dt;
        view.time_s = params->frames > 0 ? i / 60.0 : view.time_s + dt;
        if ((res = sb_renderer_render(r, &view, true, &timings)))
            break;
        memcpy(frame, sb_renderer_ldr(r), bytes);
        if (overlay) {
            char state[3][160];
            snprintf(state[0], sizeof(state[0]), "skyview  %.1f fps  %ux%u", fps, width, height);
            int n = snprintf(state[1], sizeof(state[1]), "sun %.1f\xc2\xb0 az %.1f\xc2\xb0", view.sun_elevation / DEG,
                             fmod(fmod(view.sun_azimuth / DEG, 360.0) + 360.0, 360.0));
            if (params->sun_path && n > 0 && (size_t)n < sizeof(state[1]))
                snprintf(state[1] + n, sizeof(state[1]) - (size_t)n, "  %02d:%02d", (int)hour % 24,
                         (int)(fmod(hour, 1.0) * 60.0));
            snprintf(state[2], sizeof(state[2]), "camera %.1f %.1f %.1f  yaw %.1f\xc2\xb0 pitch %.1f\xc2\xb0",
                     view.camera_m[0], view.camera_m[1], view.camera_m[2], view.yaw / DEG, view.pitch / DEG);
            const char *lines[4] = {state[0], state[1], state[2], "1-7 passes  wasd qe  arrows: sun  h  p  esc"};
            sb_viewer_draw_overlay(frame, width, height, &timings, disabled, lines, 4);
        }
        bool last_frame = params->frames > 0 && i == params->frames - 1;
        bool shoot = want_shot || (last_frame && params->screenshot);
        if ((res = sb_window_present(window, frame, shoot ? shot : NULL)))
            break;
        if (shoot) {
            char path[4200];
            if (last_frame && params->screenshot)
                snprintf(path, sizeof(path), "%s", params->screenshot);
            else
                snprintf(path, sizeof(path), "%s/screenshot_%04d.png", params->out_dir, shots++);
            if ((res = sb_png_write(path, width, height, shot)))
                break;
            sb_info("screenshot: %s", path);
            want_shot = false;
        }
    }
    free(frame);
    free(shot);
    return res;
}
