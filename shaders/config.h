/*
 * Shared between C and GLSL: workgroup sizes, binding numbers, push-constant
 * layouts and the GPU image of the atmosphere parameters. Included by the
 * baker's C code and by every compute shader, so the two can never disagree.
 *
 * Keep this file in the common subset of C11 and GLSL 4.50: no typedefs, no
 * pointers; vectors are declared through SB_VEC4 / SB_UVEC4.
 */
#ifndef SB_SHADERS_CONFIG_H
#define SB_SHADERS_CONFIG_H

#ifdef GL_core_profile
#define SB_VEC4(name) vec4 name
#define SB_UVEC4(name) uvec4 name
#define SB_UINT uint
#else
#include <stdint.h>
#define SB_VEC4(name) float name[4]
#define SB_UVEC4(name) uint32_t name[4]
#define SB_UINT uint32_t
#endif

/* 2D bake shaders run 8x8 workgroups, one invocation per texel. */
#define SB_WORKGROUP_X 8
#define SB_WORKGROUP_Y 8

/* Scattering bakes (sphere.glsl) run one workgroup of SB_SPHERE_THREADS per
 * texel; each invocation sums at most SB_SPHERE_MAX_SUMS values. */
#define SB_SPHERE_THREADS 64
#define SB_SPHERE_MAX_SUMS 9
/* Directions per invocation in one dispatch (sphere.glsl): the passes keep
 * every invocation far below llvmpipe's 65535 loop iterations. */
#define SB_SPHERE_STEPS_PER_PASS 8
/* Gauss-Legendre nodes in cos(zenith) per piece, at most, and the pieces
 * (sphere.glsl): three of the ground, four of the sky, cut again at the
 * sun and at its mirror image. */
#define SB_MAX_DIRECTIONS_MU 64
#define SB_SPHERE_MAX_PIECES 9

/* Every atmosphere bake pipeline has the same descriptor set layout: six
 * storage buffers. Inputs a product does not read are bound to a dummy.
 * Transmittance is bound as baked; multiscattering and irradiance_ground
 * in their lookup form (see atmosphere.glsl): ln(max(psi, 1e-30)) per texel
 * and channel, and ln(max(direct + sky, 1e-30)) of the ground row. */
#define SB_BINDING_ATMOSPHERE 0
#define SB_BINDING_TRANSMITTANCE 1
#define SB_BINDING_MULTISCATTERING 2
#define SB_BINDING_IRRADIANCE_GROUND 3
#define SB_BINDING_OUTPUT 4
#define SB_BINDING_SCRATCH 5 /* sphere.glsl's partial sums between passes */
#define SB_BINDING_COUNT 6

/* Product sizes and channel counts of format version 1. */
#define SB_TRANSMITTANCE_WIDTH 256
#define SB_TRANSMITTANCE_HEIGHT 64
#define SB_TRANSMITTANCE_CHANNELS 3
#define SB_MULTISCATTERING_SIZE 32
#define SB_MULTISCATTERING_CHANNELS 3
#define SB_IRRADIANCE_WIDTH 64
#define SB_IRRADIANCE_HEIGHT 16
#define SB_IRRADIANCE_GROUND_CHANNELS 6 /* direct.rgb, sky.rgb */
#define SB_IRRADIANCE_SKY_CHANNELS 9    /* rayleigh.rgb, mie.rgb, ground.rgb */

/* Gauss-Legendre order of one segment of a ray integral (see atmosphere.glsl). */
#define SB_RAY_GL_ORDER 4
/* Upper bound on the altitude levels that cut a ray into segments. */
#define SB_MAX_LEVELS 16

/*
 * The atmosphere as the shaders see it (std430, all lengths in km, all
 * coefficients in 1/km). Filled by sb_atmosphere_gpu_pack() in baker/.
 */
struct sb_atmosphere_gpu {
    SB_VEC4(rayleigh_scattering);  /* rgb; w: Rayleigh scale height */
    SB_VEC4(mie_scattering);       /* rgb; w: Mie scale height */
    SB_VEC4(mie_extinction);       /* rgb; w: Mie asymmetry g */
    SB_VEC4(ozone_absorption);     /* rgb; w: ozone tent centre altitude */
    SB_VEC4(ground_albedo);        /* rgb; w: ozone tent half width */
    SB_VEC4(solar_irradiance);     /* rgb; w: unused */
    SB_VEC4(radii);                /* ground radius, top radius, H = sqrt(top^2 - ground^2), top - ground */
    SB_VEC4(levels_a);             /* altitudes that cut rays into segments, ascending, */
    SB_VEC4(levels_b);             /* padded with values above the top; count in */
    SB_VEC4(levels_c);             /* level_count */
    SB_VEC4(levels_d);
    SB_UVEC4(level_count);         /* x: number of levels used */
};

/* Push constants of the atmosphere bakes. */
struct sb_bake_push {
    SB_UINT width;
    SB_UINT height;
    SB_UINT directions_mu;  /* Gauss-Legendre nodes in cos(zenith), per interval */
    SB_UINT directions_phi; /* midpoint nodes in azimuth over [0, pi] */
    SB_UINT step_begin;     /* sphere.glsl: this pass's steps, [begin, end) of */
    SB_UINT step_end;       /* SB_SPHERE_THREADS directions each */
    SB_UINT step_count;     /* steps of the whole integral */
    SB_UINT pad;
};

#endif
