/*
 * skyview's window (GLFW, a Vulkan surface and swapchain): a frame of RGBA8
 * pixels, sRGB-encoded as skyview writes its PNGs, is copied through a
 * staging buffer into a swapchain image and presented (FIFO), so the window
 * shows the headless frame's bytes. The window is the frame's size and not
 * resizable. Keys and the mouse are read into struct sb_window_input. Built
 * without GLFW (libglfw3-dev), every call fails with a message saying so.
 * One thread, the main one (GLFW's rule).
 *
 * Order: sb_window_system_init (before the Vulkan context, whose instance
 * needs the surface's extensions and whose queue must present: fill
 * sb_vk_params from it), sb_vk_create, sb_window_create; ...;
 * sb_window_destroy, sb_vk_destroy, sb_window_system_finish.
 */
#ifndef SB_RUNTIME_WINDOW_H
#define SB_RUNTIME_WINDOW_H

#include <stdbool.h>
#include <stdint.h>

#include "context.h"
#include "result.h"

/* Start the window system and set params->instance_extensions and
 * can_present for a context that presents. SB_ERR_NO_DEVICE, with a
 * message, without a display or without Vulkan presentation; SB_ERR_USAGE
 * when built without GLFW. */
enum sb_result sb_window_system_init(struct sb_vk_params *params);
void sb_window_system_finish(void);

struct sb_window;

/* A window of width x height pixels titled `title`, with its swapchain on
 * `vk` (made from the params sb_window_system_init filled). */
enum sb_result sb_window_create(struct sb_vk *vk, uint32_t width, uint32_t height, const char *title,
                                struct sb_window **window);
void sb_window_destroy(struct sb_window **window);

/* Keys and the mouse since the last sb_window_poll. */
struct sb_window_input {
    bool close;                                 /* the window was closed, or Escape */
    bool forward, back, left, right, up, down;  /* W S A D, E and Q held */
    bool fast;                                  /* Shift held */
    bool sun_left, sun_right, sun_up, sun_down; /* arrow keys held */
    double look_dx, look_dy;                    /* cursor motion while a mouse button is held, pixels */
    uint32_t pressed_digits;                    /* bit d: digit key d was pressed (0 to 9) */
    bool toggle_overlay;                        /* H or F1 pressed */
    bool screenshot;                            /* P pressed */
};

/* Handle the window system's events and fill `input`. */
void sb_window_poll(struct sb_window *window, struct sb_window_input *input);

/* Show a frame: width * height * 4 bytes, top row first. With `shot`
 * (width * height * 4 bytes, may be NULL), the swapchain image as presented
 * is read back into it, RGBA. */
enum sb_result sb_window_present(struct sb_window *window, const uint8_t *rgba, uint8_t *shot);

#endif
