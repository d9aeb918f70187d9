/*
 * The frame's constants (struct sb_frame_gpu, view_gpu.h), as every view pass
 * reads them: the one declaration of the frame's buffer, and what it says
 * of the lights.
 */
#ifndef SB_FRAME_GLSL
#define SB_FRAME_GLSL

#include "view_gpu.h"

layout(std430, set = 0, binding = SB_VIEW_BINDING_FRAME) readonly buffer FrameBuffer {
    sb_frame_gpu frame;
};

/* The lights (sb_frame_gpu.lights): the sun (0) and, at night, the moon
 * (1); their colours multiply the solar irradiance. Every light in the sky
 * scatters in the atmosphere; the key light alone lights surfaces, fog and
 * clouds directly and casts shadows. */
int sky_light_count()
{
    return int(frame.lights.x);
}

/* 1 when the moon is a light in the sky, else 0: the count of a loop that
 * adds it. llvmpipe runs an if's code for every invocation, taken or not,
 * and a loop's first turn too: the heaviest kernels (the aerial perspective,
 * the sky, the clouds' march) are built twice, the day's with SB_MOONLESS, which the renderer
 * runs when the moon is not in the sky (a moon's loop that does not turn
 * cost them 40% and 12% on llvmpipe). */
int moon_lights()
{
#ifdef SB_MOONLESS
    return 0; /* a kernel for the day, the moon's code compiled out (frame.lights.x == 1) */
#else
    return int(frame.lights.x) - 1;
#endif
}

vec3 light_direction(int i)
{
    return i == 0 ? frame.sun_direction.xyz : frame.moon_direction.xyz;
}

vec3 light_color(int i)
{
    return i == 0 ? vec3(1.0) : frame.moon_light.rgb;
}

int key_light()
{
    return int(frame.lights.y);
}

vec3 key_direction()
{
    return light_direction(key_light());
}

vec3 key_color()
{
    return light_color(key_light());
}

#endif
