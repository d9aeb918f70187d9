#version 450
// vulkan/compute.h's texel buffers (test_vulkan): invocation i copies the
// texel at a scattered index, (i * 7919) mod n, and the last texel, which
// every invocation fetches, into a storage buffer.
layout(local_size_x = 64) in;
layout(set = 0, binding = 0) uniform samplerBuffer texels;
layout(std430, set = 0, binding = 1) buffer Out { vec4 copies[]; };
layout(push_constant) uniform Push { uint n; } push;

void main()
{
    uint i = gl_GlobalInvocationID.x, n = push.n;
    if (i >= n)
        return;
    copies[i] = texelFetch(texels, int(i * 7919u % n));
    copies[n + i] = texelFetch(texels, int(n - 1u));
}
