/*
 * The frame's constants (struct sb_frame_gpu, view_gpu.h), as every view pass
 * reads them: the one declaration of the frame's buffer.
 */
#ifndef SB_FRAME_GLSL
#define SB_FRAME_GLSL

#include "view_gpu.h"

layout(std430, set = 0, binding = SB_VIEW_BINDING_FRAME) readonly buffer FrameBuffer {
    sb_frame_gpu frame;
};

#endif
