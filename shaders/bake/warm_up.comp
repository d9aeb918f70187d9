#version 450
/* Keeps a GPU busy so that its clocks are up when a bench times a bake or
 * a frame (sb_warm_up, vulkan/compute.h): every invocation runs `rounds` dependent FMAs and
 * writes the result, so that none of it can be optimised away. */
layout(local_size_x = 64) in;
layout(push_constant) uniform Push { uint rounds; } pc;
layout(std430, set = 0, binding = 0) writeonly buffer Output { float result[]; };

void main()
{
    float a = float(gl_GlobalInvocationID.x) * 1e-9, b = 1.0;
    for (uint i = 0u; i < pc.rounds; i++)
        b = fma(b, 0.9999999, a);
    result[gl_GlobalInvocationID.x] = b;
}
