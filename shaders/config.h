/*
 * Shared between C and GLSL: workgroup sizes, binding numbers, push-constant
 * layouts and the GPU image of the atmosphere parameters. Included by the
 * baker's C code and by every shader, so the two can never disagree.
 * skyview's contracts are in view/: view_gpu.h, and each pass's own beside it.
 *
 * Keep this file in the common subset of C11 and GLSL 4.50: no typedefs, no
 * pointers; vectors are declared through SB_VEC4 / SB_UVEC4.
 */
#ifndef SB_SHADERS_CONFIG_H
#define SB_SHADERS_CONFIG_H

#ifdef GL_core_profile
#define SB_VEC4(name) vec4 name
#define SB_UVEC4(name) uvec4 name
#define SB_MAT4(name) mat4 name
#define SB_UINT uint
#else
#include <stdint.h>
#define SB_VEC4(name) float name[4]
#define SB_UVEC4(name) uint32_t name[4]
#define SB_MAT4(name) float name[16] /* column-major, as GLSL's mat4 */
#define SB_UINT uint32_t
#endif

/* 2D bake shaders run 8x8 workgroups, one invocation per texel. */
#define SB_WORKGROUP_X 8
#define SB_WORKGROUP_Y 8

/* Scattering bakes (sphere.glsl) run one workgroup of SB_SPHERE_THREADS per
 * texel; each invocation sums at most SB_SPHERE_MAX_SUMS values. A GPU runs
 * the kernels built with SB_SPHERE_GPU defined, SB_SPHERE_THREADS_GPU wide:
 * at 64 an H100 holds six of these workgroups an SM (159 to 168 registers
 * an invocation), and the 1024 texels of the multiscattering LUT take two
 * uneven waves; at 128 the default multiscattering bake took 2.70 ms
 * instead of 3.43, irradiance_ground 0.66 instead of 1.13 and irradiance_sky
 * 4.71 instead of 6.02 (256: 2.55, 0.59, 4.60, but the cheap settings twice
 * as slow). llvmpipe is faster at 64 (the default bake 9.3 s, 15.7 at 128).
 * The sums' order, and so the last bits, differ between the two. */
#define SB_SPHERE_THREADS_CPU 64
#define SB_SPHERE_THREADS_GPU 128
/* A GPU may instead integrate one direction an invocation, in workgroups of
 * SB_SPHERE_RAY_GROUP (sphere.glsl's SB_SPHERE_RAYS), the last of a texel
 * summing them as a workgroup SB_SPHERE_THREADS_CPU wide would. */
#define SB_SPHERE_RAY_GROUP 32
#if defined(SB_SPHERE_RAYS)
#define SB_SPHERE_THREADS SB_SPHERE_RAY_GROUP
#elif defined(SB_SPHERE_GPU)
#define SB_SPHERE_THREADS SB_SPHERE_THREADS_GPU
#else
#define SB_SPHERE_THREADS SB_SPHERE_THREADS_CPU
#endif
#define SB_SPHERE_MAX_SUMS 9
/* The scratch buffer of a sphere bake (sphere.glsl), in 32-bit words after
 * its 4-word header: `slots` sums' slots a texel of `texels`, then, for
 * SB_SPHERE_RAYS, a counter a texel; the first counter's index. */
#define SB_SPHERE_COUNTERS(texels, slots) ((texels) * (slots) * SB_SPHERE_MAX_SUMS)
/* Directions per invocation in one dispatch (sphere.glsl): the passes keep
 * every invocation far below llvmpipe's 65535 loop iterations. */
#define SB_SPHERE_STEPS_PER_PASS 8
/* Gauss-Legendre nodes in cos(zenith) per piece, at most, and the pieces
 * (sphere.glsl): three of the ground, five of the sky, cut again at the
 * sun and at its mirror image. */
#define SB_MAX_DIRECTIONS_MU 64
#define SB_MAX_DIRECTIONS_PHI 256
#define SB_SPHERE_MAX_PIECES 10
/* Workgroup memory of the largest sphere bake with the multiscattering LUT's
 * copy (irradiance_sky: the quadrature's nodes, the partial sums and the
 * copy), in bytes: more than the 16 KiB every device offers, less than
 * llvmpipe's 32 KiB; the baker takes the copy only where the device's limit
 * allows it. */
#define SB_SPHERE_SHARED_BYTES                                                                             \
    (4 * (2 * SB_MAX_DIRECTIONS_MU + 2 * SB_MAX_DIRECTIONS_PHI + SB_SPHERE_THREADS_CPU * SB_SPHERE_MAX_SUMS) \
     + 16 * SB_MULTISCATTERING_LOOKUP_TEXELS)
/* Mie single scattering's cap around its peak (sphere.glsl): over the whole
 * sphere, for |g| >= SB_CAP_MIN_G, radius SB_CAP_THETA (radians), the
 * window falling to 0 at twice that; up to three rings' pieces times two
 * sides of the horizon. */
#define SB_CAP_THETA 0.5
#define SB_CAP_MIN_G 0.85
/* irradiance_sky's azimuths (sphere.glsl, sphere_azimuth_weights): the
 * dense rule for the phase functions' weights, and how far above every
 * seen point's horizontal the sun must be for a quarter of the nodes
 * (radians). */
#define SB_AZIMUTH_DENSE 48
#define SB_AZIMUTH_DAY_MARGIN 0.05
#define SB_SPHERE_CAP_PIECES 6

/* Every atmosphere bake pipeline has the same descriptor set layout: seven
 * storage buffers. Inputs a product does not read are bound to a dummy.
 * Transmittance is bound as baked; multiscattering and irradiance_ground
 * in their lookup form (physics.h): ln(max(psi, 1e-30)) per texel and
 * channel, and of the ground row ln(max(direct + sky, 1e-30)), then
 * ln(max(sky, 1e-30)). */
#define SB_BINDING_ATMOSPHERE 0
#define SB_BINDING_TRANSMITTANCE 1
#define SB_BINDING_MULTISCATTERING 2
#define SB_BINDING_IRRADIANCE_GROUND 3
#define SB_BINDING_OUTPUT 4
#define SB_BINDING_SCRATCH 5 /* sphere.glsl's partial sums between passes */
#define SB_BINDING_SUN_COLUMNS 6 /* the scattering bakes' sun table (sun_columns.comp) */
#define SB_BINDING_SUN_RINGS 7   /* multiscattering's ring table (sun_rings.comp) */
#define SB_BINDING_COUNT 8

/* The sun table of the scattering bakes (atmosphere.glsl, "The sun's optical
 * depth"): two regions of SB_SUN_COLUMNS_X x SB_SUN_COLUMNS_U nodes, each
 * with a ghost node on every side, of two floats (Rayleigh, Mie). */
#define SB_SUN_COLUMNS_X 128
#define SB_SUN_COLUMNS_U 64
#define SB_SUN_COLUMNS_FLOATS (2 * (SB_SUN_COLUMNS_X + 2) * (SB_SUN_COLUMNS_U + 2) * 2)

/* The ring table of multiscattering (sun_rings.glsl): per column of the
 * LUT, SB_RINGS_ROWS rows in altitude (two blocks of half as many where the
 * sun sets within the atmosphere) of SB_RINGS_INNER + SB_RINGS_OUTER
 * entries in the angle from the texel's zenith, then SB_RINGS_GROUND
 * entries of the ground's ring; four floats each. 256 ground entries
 * instead of 512 moved no error of the bench's sweep, on the earth or in
 * the thick atmosphere, and took the H200's ring table from 0.058 to 0.047
 * ms (docs/accuracy.md, "Levels a factor 2 apart"). */
#define SB_RINGS_ROWS 192
#define SB_RINGS_INNER 8
#define SB_RINGS_OUTER 24
#define SB_RINGS_GROUND 256
#define SB_RINGS_ANGLES (SB_RINGS_INNER + SB_RINGS_OUTER)
#define SB_RINGS_COLUMN (SB_RINGS_ROWS * SB_RINGS_ANGLES + SB_RINGS_GROUND)

/* Product sizes and channel counts of format version 1. */
#define SB_TRANSMITTANCE_WIDTH 160 /* 256 x 64 before the mapping of transmittance-subtexel-horizon-v2: 2% fewer texels */
#define SB_TRANSMITTANCE_HEIGHT 100
#define SB_TRANSMITTANCE_CHANNELS 3
#define SB_MULTISCATTERING_SIZE 32
#define SB_MULTISCATTERING_CHANNELS 3
/* The multiscattering LUT's lookup form (physics.h): its texels with a ghost
 * texel on every side, four floats each. */
#define SB_MULTISCATTERING_LOOKUP_TEXELS ((SB_MULTISCATTERING_SIZE + 2) * (SB_MULTISCATTERING_SIZE + 2))
/* skyview's form of it (physics.h): the same Catmull-Rom of its logarithm,
 * evaluated on a grid SB_MULTISCATTERING_REFINE times finer, which the
 * runtime reads bilinearly (four reads instead of sixteen). */
#define SB_MULTISCATTERING_REFINE 16
#define SB_MULTISCATTERING_REFINED_SIZE ((SB_MULTISCATTERING_SIZE - 1) * SB_MULTISCATTERING_REFINE + 1)
#define SB_IRRADIANCE_WIDTH 64
#define SB_IRRADIANCE_HEIGHT 16
#define SB_IRRADIANCE_GROUND_CHANNELS 6 /* direct.rgb, sky.rgb */
#define SB_IRRADIANCE_SKY_CHANNELS 9    /* rayleigh.rgb, mie.rgb, ground.rgb */

/* The orders product's grid (format version 14; baker/orders_ref.h):
 * nodes in r, mu (two halves), mu_s and nu. */
#define SB_ORDERS_R 16
#define SB_ORDERS_MU 64
#define SB_ORDERS_MU_DUST 128 /* a broad dust's (sb_orders_mu_nodes): the zenith's cell */
#define SB_ORDERS_DUST_MAX_G 0.85 /* broad: |g| below it; above, as for the cap's SB_CAP_MIN_G, a peak no mu grid reads */
#define SB_ORDERS_MU_S 36      /* the air's (sb_orders_mu_s_nodes): half of them below 0.1, at twilight */
#define SB_ORDERS_MU_S_DUST 24 /* a dust's (mars's, the haze's) */
#define SB_ORDERS_NU 8         /* the sun's azimuth (the air's, a broad dust's): twilight's light falls steeply with it */
#define SB_ORDERS_NU_DUST 4    /* a peaked dust's, read log-trigonometrically through all (sb_orders_log_azimuth) */
/* Mie's phase from which the orders are computed delta-M scaled
 * (sb_orders_medium): a forward peak narrower than the density's
 * directions, which at g 0.8 (the earth) and 0.65 (mars) the scaling
 * models worse than the directions do (docs/accuracy.md). */
#define SB_ORDERS_DELTA_M_G 0.9
/* The air's azimuth nodes at pi x^p, x uniform (sb_orders_azimuth_power):
 * close about the sun, where twilight's light is (0, 3.7, 15, 33, 59, 92,
 * 132, 180 degrees). */
#define SB_ORDERS_NU_POWER 2.0
/* The orders' tail (baker/orders_ref.h): the ratio of an order to the one
 * before is taken at most this (the tail then 9 times the last order). */
#define SB_ORDERS_TAIL_MAX_RATIO 0.9
/* The product's orders stop where one adds less than this of the sum's
 * largest value, the tail standing for the rest: measured against orders
 * to 1e-5 (lavapipe), the table within 0.003% of the largest value for the
 * earth (order 6), 0.19% for mars (order 6), 0.03% for the haze (order 8). */
#define SB_ORDERS_TOLERANCE 0.02

/* The spectral products (format version 15): the sky at 12 wavelengths in
 * bands of three (physics/spectrum.h), each band a scene of three channels
 * baked and drawn by the three-channel kernels. */
#define SB_SPECTRAL_BANDS 4

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
    SB_UINT quadrature;     /* transmittance: SB_QUADRATURE_* */
    SB_UINT samples;        /* transmittance: steps of a uniform rule (a Gauss-Legendre order is compiled in) */
    SB_UINT subdivisions;   /* transmittance, Gauss-Legendre: equal sub-pieces per piece */
    SB_UINT direction_slots; /* sphere.glsl, one direction an invocation: slots a texel */
};

/* Quadratures of the transmittance bake (sb_bake_push.quadrature):
 * Gauss-Legendre of order `samples` (1 to SB_GL_MAX_ORDER) on the pieces
 * between the integrand's kinks, each cut into `subdivisions`; or a uniform
 * rule of `samples` steps over the whole ray, sampled at offset 0.3 of each
 * step (Hillaire 2020's code) or at its middle, or the trapezoidal rule
 * (Bruneton 2017's code). The uniform rules exist to measure the published
 * settings against ours (skybake bench). Each Gauss-Legendre order is its
 * own shader (transmittance_glN), so that its loops unroll with their node
 * tables: indexing them by a value known only at run time costs llvmpipe
 * 50x, and specialisation constants do not fold early enough there. */
#define SB_QUADRATURE_GAUSS_LEGENDRE 0
#define SB_QUADRATURE_UNIFORM_0_3 1
#define SB_QUADRATURE_MIDPOINT 2
#define SB_QUADRATURE_TRAPEZOID 3
#define SB_QUADRATURE_COUNT 4
#define SB_GL_MAX_ORDER 8
/* Pieces of a transmittance ray at most: three ozone corners, the fold, the
 * end, and up to 16 tail levels of a thick atmosphere (atmosphere.glsl). */
#define SB_TRANSMITTANCE_MAX_PIECES 21
#define SB_GL_MAX_SUBDIVISIONS 16
#define SB_UNIFORM_MAX_STEPS 4096
/* skybake bench's anchor for multiple scattering: Hillaire 2020's LUT
 * (multiscattering_hillaire.comp), selected by quadrature
 * SB_QUADRATURE_UNIFORM_0_3 on that product: directions_mu x directions_phi
 * directions, `samples` steps a ray, in workgroups of SB_ANCHOR_THREADS
 * an invocation walking every SB_ANCHOR_THREADS-th direction: at most
 * SB_ANCHOR_MAX_ITERATIONS steps an invocation (SB_ANCHOR_ITERATIONS), far
 * below llvmpipe's 65535 loop iterations. Never in a pack. */
#define SB_ANCHOR_THREADS 64
#define SB_ANCHOR_MAX_DIRECTIONS 4096
#define SB_ANCHOR_MAX_ITERATIONS 32768
#define SB_ANCHOR_ITERATIONS(directions, samples) \
    (((directions) + SB_ANCHOR_THREADS - 1) / SB_ANCHOR_THREADS * (samples))
/* skybake bench's anchor for ground irradiance: Bruneton 2017's quadrature
 * (irradiance_ground_bruneton.comp), selected by SB_QUADRATURE_TRAPEZOID on
 * that product: directions_mu zenith angles by directions_phi azimuths over
 * the upper hemisphere, `samples` trapezoid intervals a ray. The bounds keep
 * an invocation's loops far below llvmpipe's 65535 iterations. */
#define SB_BRUNETON_MAX_DIRECTIONS 8192
#define SB_BRUNETON_MAX_STEPS 200

/* Cloud noise (noise.glsl, clouds.comp, baker/clouds.h): one invocation
 * per texel in workgroups of one 8x8 tile of one slice (a 2D texture has
 * one slice), up to SB_NOISE_MAX_CHANNELS channels, each
 * a recipe: kind (SB_NOISE_*), integers a, b, c and a seed.
 * - PERLIN_WORLEY: a Perlin period, b octaves, c Worley cells;
 * - WORLEY_FBM: a cells;
 * - PERLIN_FBM: a period, b octaves, c: stretched by 2^c about 1/2;
 * - CURL: a period, b octaves, c the component (0 to 2).
 * Texel (i, j, k) sits at ((i, j, k) + 0.5) * inv; 2D textures (size_z 1)
 * at z = slice_z. */
#define SB_NOISE_MAX_CHANNELS 4
#define SB_NOISE_MAX_OCTAVES 8
#define SB_NOISE_PERLIN_WORLEY 0
#define SB_NOISE_WORLEY_FBM 1
#define SB_NOISE_PERLIN_FBM 2
#define SB_NOISE_CURL 3

struct sb_noise_push {
    SB_UINT size_x;
    SB_UINT size_y;
    SB_UINT size_z;
    SB_UINT channel_count;
    float inv_x;
    float inv_y;
    float inv_z;
    float slice_z;
    SB_UVEC4(kind);
    SB_UVEC4(a);
    SB_UVEC4(b);
    SB_UVEC4(c);
    SB_UVEC4(seed);
};

/* Ray casts against a BVH (geometry/bvh.h, bvh.glsl, raycast.comp): leaves
 * of at most SB_BVH_MAX_LEAF triangles, a tree at most SB_BVH_MAX_DEPTH
 * deep (the root at 0), so that the traversal's stack of that many
 * entries never overflows. */
#define SB_BVH_MAX_LEAF 4
#define SB_BVH_MAX_DEPTH 40
#define SB_BVH_MISS 0xffffffffu
#define SB_BVH_BACK_FACE 0x80000000u /* set in a hit's triangle when the ray met its back */
/* Two levels (a world of instances): a top-level leaf whose count is
 * SB_BVH_INSTANCE_LEAF holds one instance, its record at node `first`: two
 * nodes, the world-to-object rows (three vec4s), then its mesh's root node,
 * the instance's index, its flags and a zero (as uints). */
#define SB_BVH_INSTANCE_LEAF 0x80000000u
/* An instance's flags: met at any distance, past a tiled bake's reach
 * (bvh.glsl's bvh_reach; baker/probe_tiles.h) */
#define SB_BVH_INSTANCE_WIDE 1u
#define SB_BVH_NO_INSTANCE 0xffffffffu
#define SB_RAYCAST_BINDING_NODES 0
#define SB_RAYCAST_BINDING_TRIANGLES 1
#define SB_RAYCAST_BINDING_RAYS 2 /* two vec4s a ray: origin, tmin; direction, tmax */
#define SB_RAYCAST_BINDING_HITS 3 /* one vec4 a ray: t, triangle | SB_BVH_BACK_FACE, instance (bits), 0 */
#define SB_RAYCAST_BINDING_COUNT 4
#define SB_RAYCAST_WORKGROUP 64

struct sb_raycast_push {
    SB_UINT ray_count; /* rays in the buffer */
    SB_UINT any_hit;   /* 1: stop at the first hit found (visibility) */
    SB_UINT first;     /* the dispatch's first ray (dispatches are at most 65535 workgroups) */
    SB_UINT pad;
};

/* Sky-visibility probes (sky_visibility.comp, baker/sky_visibility.h): one
 * workgroup a probe, each invocation a share of the probe's rays, in the
 * raycast kernel's bindings (nodes, triangles; probes: one vec4 a probe,
 * its position in m; out: SB_VISIBILITY_FLOATS a probe). Ray i of n leaves along
 * the spherical Fibonacci direction y = 1 - (2 i + 1) / n, azimuth 2 pi
 * frac(i x 0x9E3779B9 / 2^32) (y up). SH: the real basis of order 2 in
 * Sloan's order over world (x, y, z), z the polar axis of the formulas. */
#define SB_PROBE_THREADS 64
#define SB_PROBE_BINDING_ORDER 4 /* the order the rays are cast in: one uint a ray (sky_visibility.h) */
#define SB_PROBE_BINDING_COUNT 5
#define SB_PROBE_MAX_RAYS 65536
#define SB_PROBE_SH 9
/* The band l of each SH coefficient k (Y_lm in the order sh.glsl and
 * physics/sh.c write them), and the clamped cosine's zonal factor of each
 * band (pi, 2 pi / 3, pi / 4: Ramamoorthi and Hanrahan 2001): lists for C
 * and GLSL tables, {SB_SH_BANDS} and int[](SB_SH_BANDS). */
#define SB_SH_BANDS 0, 1, 1, 1, 2, 2, 2, 2, 2
#define SB_SH_COSINE_FACTORS 3.141592653589793, 2.0943951023931953, 0.7853981633974483
#define SB_VISIBILITY_FLOATS 12 /* sh[9], back-face fraction, hit fraction, mean hit distance (m) */

/* What the baker's rays see of the surfaces they hit (surface.glsl,
 * baker/surfaces.h): four bindings from a kernel's first, in this order:
 * one (albedo, base-colour texture + 1) a material, three vec2 a triangle
 * (its vertices' texture coordinates), one uvec4 a texture, and every
 * texture's mips (one RGBA8 uint a texel). Wrap modes as
 * geometry/mesh_texture.h's enum sb_texture_wrap. */
#define SB_SURFACE_MATERIALS 0
#define SB_SURFACE_UVS 1
#define SB_SURFACE_TEXTURES 2
#define SB_SURFACE_TEXELS 3
#define SB_SURFACE_BINDING_COUNT 4
#define SB_SURFACE_WRAP_REPEAT 0
#define SB_SURFACE_WRAP_CLAMP 1
#define SB_SURFACE_WRAP_MIRROR 2

/* The textures' mips (texture_mips.comp): one dispatch a level, z the
 * texture; level `level` from level - 1. */
#define SB_TEXTURE_MIPS_BINDING_TEXTURES 0
#define SB_TEXTURE_MIPS_BINDING_TEXELS 1
#define SB_TEXTURE_MIPS_BINDING_COUNT 2

struct sb_texture_mips_push {
    SB_UINT level;
    SB_UINT texture_count;
};

/* The one-bounce transfer at probes (probe_bounce.comp, baker/sky_bounce.h):
 * one workgroup a probe; each of ray_count rays (spherical Fibonacci) that
 * hits a surface casts, from the hit, the directions of a 2 x secondary
 * spherical Fibonacci set that leave the surface's side toward the probe,
 * and projects (n.l) V(l) on order-2 SH; the hit's albedo / pi times that,
 * times the order-1 SH of the ray's direction, 4 pi / ray_count, is summed
 * into SB_BOUNCE_FLOATS a probe (m < 4, k < 9, rgb). Bindings: the raycast
 * kernel's nodes and triangles; rays: one vec4 a probe (position m, 1 when
 * valid); hits: the output; from SB_BOUNCE_BINDING_SURFACE the surfaces'
 * four (surface.glsl). */
#define SB_BOUNCE_BINDING_SURFACE 4
#define SB_BOUNCE_BINDING_COUNT (SB_BOUNCE_BINDING_SURFACE + SB_SURFACE_BINDING_COUNT)
#define SB_BOUNCE_SH 4 /* order 1 at the probe */
#define SB_BOUNCE_FLOATS (SB_BOUNCE_SH * SB_PROBE_SH * 3)
/* After each probe's SB_BOUNCE_FLOATS the kernel writes the bounce's
 * operator on the probe's own light, M[m][j] rgb (m, j < 4): the radiance
 * the surfaces its rays hit send back toward it in the order-1 SH of w,
 * lit by a radiance b_j (order-1 SH) arriving at them as it arrives at the
 * probe; baker/sky_bounce.c sums the bounces B + M B + M M B + ... */
#define SB_BOUNCE_OPERATOR_FLOATS (SB_BOUNCE_SH * SB_BOUNCE_SH * 3)
#define SB_BOUNCE_KERNEL_FLOATS (SB_BOUNCE_FLOATS + SB_BOUNCE_OPERATOR_FLOATS)
/* The sun's table (sun_bounce; docs/probes.md, "The sun"): the sun's
 * bounce at SB_SUN_DIRECTIONS directions s_j of the upper hemisphere, the
 * corners of an SB_SUN_SIDE x SB_SUN_SIDE grid over its octahedral map
 * (physics/sh.h, sb_sun_table_direction), read bilinearly between them. A sun run
 * of the kernel (its sphere set empty: secondary 0) writes after M, sun
 * direction by sun direction, the radiance the surfaces send toward the
 * probe (order-1 SH of w, rgb) when a sun of unit irradiance shines from
 * about s_j: each hit's rho / pi (n.s) V(s), s drawn about s_j
 * (sun_table_sample), V from a ray toward s. */
#define SB_SUN_SIDE 12
#define SB_SUN_DIRECTIONS (SB_SUN_SIDE * SB_SUN_SIDE)
#define SB_BOUNCE_SUN_FLOATS (SB_SUN_DIRECTIONS * SB_BOUNCE_SH * 3)
#define SB_BOUNCE_SUN_KERNEL_FLOATS (SB_BOUNCE_KERNEL_FLOATS + SB_BOUNCE_SUN_FLOATS)
/* The kernel's sun rays, this many directions at a time (the workgroup's
 * memory holds their visibility for each ray), and a pass's */
#define SB_BOUNCE_SUN_GROUP 16
#define SB_BOUNCE_SUN_PASS 32
/* The product keeps the table as each direction's grey (the mean of r, g,
 * b) constant band T_j, and one shape a probe, S[m] rgb: the table's
 * order-1 rgb summed over the directions over its T_j summed, so that a
 * sun from s gives sum_j w_j(s) T_j S[m] (baker/sky_bounce.h). */
#define SB_BOUNCE_SUN_TABLE (SB_SUN_DIRECTIONS + SB_BOUNCE_SH * 3)

/* skyview's probes buffer (probes.glsl, SB_VIEW_BINDING_PROBES): after
 * struct sb_probes_gpu, SB_PROBE_VEC4S vec4s a probe: (position m, valid),
 * the visibility's SB_PROBE_SH coefficients in the next 3 (x, y, z, w, ...),
 * then from vec4 SB_PROBE_BOUNCE_VEC4 the bounce transfer's SB_BOUNCE_FLOATS;
 * with the sun's bounce SB_PROBE_SUN_VEC4S vec4s a probe, from
 * SB_PROBE_SUN_VEC4 its table's SB_BOUNCE_SUN_TABLE. */
#define SB_PROBE_BOUNCE_VEC4 4
#define SB_PROBE_VEC4S (SB_PROBE_BOUNCE_VEC4 + SB_BOUNCE_FLOATS / 4)
#define SB_PROBE_SUN_VEC4 SB_PROBE_VEC4S /* with sun_bounce: its table */
#define SB_PROBE_SUN_VEC4S (SB_PROBE_SUN_VEC4 + SB_BOUNCE_SUN_TABLE / 4)
#ifndef GL_core_profile
_Static_assert(SB_BOUNCE_FLOATS % 4 == 0 && SB_BOUNCE_SUN_TABLE % 4 == 0 && 4 + SB_PROBE_SH <= 4 * SB_PROBE_BOUNCE_VEC4,
               "the probes buffer's record holds the visibility's SH and whole vec4s of the bounce");
#endif

struct sb_bounce_push {
    SB_UINT probe_count;
    SB_UINT ray_count; /* a multiple of SB_PROBE_THREADS */
    SB_UINT secondary; /* half the sphere set's size: about this many rays from each hit */
    float tmin_m;
    /* one pass: rays [first_ray, first_ray + SB_PROBE_THREADS), one a
     * thread, each casting the sphere set's directions [first_direction,
     * first_direction + SB_BOUNCE_PASS_DIRECTIONS), or past the sphere
     * set (2 secondary) the sun table's SB_BOUNCE_SUN_PASS from
     * first_direction - 2 secondary; added to what the passes before
     * wrote when `accumulate` (baker/sky_bounce.c); M and B (zero in a
     * sun run) in the pass of first_direction 0 */
    SB_UINT first_ray;
    SB_UINT first_direction;
    SB_UINT accumulate;
    float tmax_m; /* a ray, from the probe or from a surface, reaching this far sees the sky */
    SB_UINT stride; /* the output's floats a probe: SB_BOUNCE_KERNEL_FLOATS; a sun run's SB_BOUNCE_SUN_KERNEL_FLOATS */
};
/* Mesa's lavapipe ends every loop of a kernel invocation once the
 * invocation has run 65535 loop iterations in all (gallivm's
 * LP_MAX_TGSI_LOOP_ITERATIONS), silently: a probe's whole bounce in one
 * invocation (4 rays x 64 of 128 directions at the defaults, each cast a
 * BVH traversal of tens to hundreds of steps) came back cut short in the
 * IFC house from 144 secondary rays. A pass keeps an invocation to one ray
 * and this many directions (half of them cast). */
#define SB_BOUNCE_PASS_DIRECTIONS 64

/* The DFG (split-sum) LUT of GGX specular (dfg.comp, baker/dfg.h): texel
 * (i, j) at n.v = (i + 0.5) / SB_DFG_SIZE and perceptual roughness
 * (j + 0.5) / SB_DFG_SIZE (alpha its square); x = the integral of
 * Fc D Vis (n.l), y = that of D Vis (n.l) (Fc = (1 - v.h)^5, Vis the
 * height-correlated Smith visibility), each over a midpoint grid of
 * SB_DFG_SAMPLES_SIDE^2 points of GGX's (cos theta_h, phi) inverse CDF. */
#define SB_DFG_SIZE 128
#define SB_DFG_SAMPLES_SIDE 128
#define SB_DFG_BINDING_OUT 0 /* two floats a texel, row by row */
#define SB_DFG_BINDING_COUNT 1

struct sb_dfg_push {
    SB_UINT size;
    SB_UINT samples_side;
    SB_UINT pad0, pad1;
};

struct sb_probe_push {
    SB_UINT probe_count;
    SB_UINT ray_count; /* a multiple of SB_PROBE_THREADS */
    float tmin_m;      /* rays start this far out */
    float tmax_m;      /* and see the sky past this distance */
    /* one pass: rays [first_ray, first_ray + SB_VISIBILITY_PASS_RAYS),
     * their sums added to the passes' before when `accumulate`; the last
     * pass turns the sums into the record (baker/sky_visibility.c) */
    SB_UINT first_ray;
    SB_UINT accumulate;
    SB_UINT last;
    SB_UINT pad;
};
/* 16 rays a thread a pass: lavapipe's 65535 loop iterations an invocation
 * (SB_BOUNCE_PASS_DIRECTIONS) hold about 200 casts */
#define SB_VISIBILITY_PASS_RAYS (16 * SB_PROBE_THREADS)

/* The detail probes' sight masks (probe_sight.comp, baker/probe_sight.h):
 * which points of the 8 lattice cells around a detail probe it sees in a
 * straight line. The cells' cube, 2 spacings across about the probe's
 * lattice point, holds SB_PROBE_SIGHT_SIDE^3 sample points, sample (i, j,
 * k) at the lattice point plus ((i, j, k) + 0.5) 2 / SIDE - 1 spacings
 * (a quarter spacing apart, none on the lattice's planes or halfway
 * between);
 * bit (k 8 + j) 8 + i of the probe's SB_PROBE_SIGHT_WORDS words is set
 * when the segment from the probe (where the push out of geometry left
 * it) to that point meets nothing. One workgroup a probe, an invocation
 * SB_PROBE_SIGHT_SAMPLES / SB_PROBE_THREADS points. Bindings: the raycast
 * kernel's nodes and triangles; rays: two vec4 a probe (its position, its
 * lattice point, m); hits: the words. */
#define SB_PROBE_SIGHT_SIDE 8
#define SB_PROBE_SIGHT_SAMPLES (SB_PROBE_SIGHT_SIDE * SB_PROBE_SIGHT_SIDE * SB_PROBE_SIGHT_SIDE)
#define SB_PROBE_SIGHT_WORDS (SB_PROBE_SIGHT_SAMPLES / 32)
#define SB_PROBE_SIGHT_BINDING_COUNT 4

struct sb_probe_sight_push {
    SB_UINT probe_count;
    SB_UINT pad;
    float tmin_m;    /* segments start this far out */
    float spacing_m; /* the lattice's */
};

/* Reflection probes (baker/reflection.h, docs/reflections.md). Cube
 * texels are stored as OpenEXR's cube layout has them (cube.glsl): face f
 * of an N x 6N image is rows [f N, (f + 1) N), the faces +x, -x, +y, -y,
 * +z, -z. Buffers hold one vec4 a texel (rgb, then a flag), level by
 * level of one cube. */
/* Capture (reflection_capture.comp): one invocation a texel of level 0;
 * the atmosphere's bindings 0 to 3 (atmosphere.glsl). */
#define SB_CAPTURE_BINDING_OUT 4       /* rgb radiance; w: 1 where the ray met a back face */
#define SB_CAPTURE_BINDING_NODES 5     /* the BVH (bvh.glsl) */
#define SB_CAPTURE_BINDING_TRIANGLES 6
#define SB_CAPTURE_BINDING_SKY_SH 7    /* 9 vec4: the sky's radiance in order-2 SH, rgb */
#define SB_CAPTURE_BINDING_SURFACE 8   /* the surfaces' four (surface.glsl) */
/* What relighting needs, SB_RELIGHT_VEC4S a texel: (albedo rgb, distance
 * m, 0 where the ray leaves the world), (the normal toward the probe,
 * transfer 0), (transfer 1-4), (transfer 5-8); the transfer T_k is the
 * order-2 SH of the sky's visibility from the surface point times the
 * clamped cosine, so that the sky's irradiance there is sum_k T_k L_k */
#define SB_CAPTURE_BINDING_SURFACES_OUT (SB_CAPTURE_BINDING_SURFACE + SB_SURFACE_BINDING_COUNT)
#define SB_CAPTURE_BINDING_COUNT (SB_CAPTURE_BINDING_SURFACES_OUT + 1)
#define SB_RELIGHT_VEC4S 4

struct sb_capture_push {
    SB_VEC4(origin_m);      /* the probe; w: its altitude, km */
    SB_VEC4(sun_direction); /* world space, y up */
    SB_UINT face_size;
    SB_UINT has_world;      /* 0: the sky alone */
    SB_UINT ambient_rays;   /* from each hit: a sphere set of 2x this, the surface's side cast */
    float tmin_m;
    /* one pass: the sphere set's directions [first_direction,
     * first_direction + SB_CAPTURE_PASS_DIRECTIONS), added to the passes'
     * before when `accumulate` (lavapipe's loop limit: config.h,
     * SB_BOUNCE_PASS_DIRECTIONS); the sun in the first, the sky's light
     * through the accumulated transfer in the last */
    SB_UINT first_direction;
    SB_UINT accumulate;
};
#define SB_CAPTURE_PASS_DIRECTIONS 128

/* GGX prefiltering (reflection_prefilter.comp): threads_per_texel
 * invocations a texel of level `level`, SB_PREFILTER_THREADS a workgroup,
 * reading the source cube's box-filtered mip chain. */
#define SB_PREFILTER_THREADS 64
#define SB_PREFILTER_BINDING_SOURCE 0 /* the source's levels, vec4 a texel */
#define SB_PREFILTER_BINDING_OUT 1    /* the output's levels, vec4 a texel */
#define SB_PREFILTER_BINDING_COUNT 2
#define SB_PREFILTER_MAX_LEVELS 12

struct sb_prefilter_push {
    SB_UINT face_size;   /* level 0's */
    SB_UINT levels;      /* log2 face_size + 1 */
    SB_UINT level;       /* written by this dispatch */
    SB_UINT samples;     /* GGX samples a texel (a Hammersley set) */
    float roughness;     /* perceptual; alpha = roughness^2 */
    SB_UINT out_offset;  /* the level's first texel in the output */
    float lod_bias;      /* added to filtered importance sampling's lod */
    float max_lod;       /* samples read no coarser source level than this */
    SB_UINT threads_per_texel; /* a power of two up to SB_PREFILTER_THREADS */
    SB_UINT groups_x;          /* workgroups along x; the workgroup's index is y groups_x + x */
    SB_UINT pad0, pad1;
    SB_UVEC4(source_offsets[SB_PREFILTER_MAX_LEVELS / 4]); /* each source level's first texel */
};


/* Multiple scattering by orders (bake/orders.comp, baker/orders.h): orders
 * 2 and up on the grid of baker/orders_ref.h, nodes indexed
 * ((ir * nmu + imu) * nmus + imus) * nnu + inu, one vec4 (rgb) a node.
 * The orders' kernels bind the atmosphere's parameters and transmittance
 * LUT as the atmosphere bakes do (SB_BINDING_ATMOSPHERE,
 * SB_BINDING_TRANSMITTANCE; 2 to 7 unused), then their tables. */
#define SB_ORDERS_BINDING_SINGLE 8   /* single scattering without its phase: Rayleigh's n nodes, then Mie's */
#define SB_ORDERS_BINDING_PREVIOUS 9 /* the last order computed */
#define SB_ORDERS_BINDING_DENSITY 10 /* this order's scattering density */
#define SB_ORDERS_BINDING_SUM 11     /* orders 2 to k: the product */
#define SB_ORDERS_BINDING_GROUND 12  /* the ground's irradiance of order j at mu_s node i: vec4 [j * nmus + i] */
#define SB_ORDERS_BINDING_STATS 13   /* uint: the largest value of this order, of the sum (float bits) */
#define SB_ORDERS_BINDING_DIRECTIONS 14 /* the directions about each point, at four suns (orders.comp) */
#define SB_ORDERS_BINDING_VIEWS 15      /* each view's samples (orders.comp) */
/* A view's samples at most: Gauss-Legendre 4 on each segment between its
 * level cuts, at most one segment more than the cuts (two a level). */
#define SB_ORDERS_VIEW_SAMPLES (4 * (2 * SB_MAX_LEVELS + 1))
/* Nodes in all at most: the views keep a node's index as a float, exact to 2^24. */
#define SB_ORDERS_MAX_GRID_NODES (1 << 24)
#define SB_ORDERS_BINDING_COUNT 16
/* The density's directions at a node (orders.comp): Gauss-Legendre in
 * cos(zenith) below and above the horizon, midpoints in azimuth from the
 * sun's over [0, pi] (each standing for its mirror image too). */
#define SB_ORDERS_DIRECTIONS_GROUND 8
#define SB_ORDERS_DIRECTIONS_SKY 16
#define SB_ORDERS_DIRECTIONS_PHI 8
#define SB_ORDERS_DIRECTIONS \
    ((SB_ORDERS_DIRECTIONS_GROUND + SB_ORDERS_DIRECTIONS_SKY) * SB_ORDERS_DIRECTIONS_PHI)
#define SB_ORDERS_THREADS 64
/* The directions' and the density's mu_s nodes a workgroup: the
 * components of a vec4 (orders.comp). The phase functions do not depend on
 * the sun, so the density weighs each once for them all. */
#define SB_ORDERS_DENSITY_SUNS 4
/* The most orders a bake computes, and the most nodes in each dimension. */
#define SB_ORDERS_MAX_ORDER 32
#define SB_ORDERS_MAX_NODES 256

struct sb_orders_push {
    SB_UVEC4(size);    /* nodes in r, mu (even: two halves), mu_s, nu */
    SB_VEC4(heights);  /* the altitudes' progression: q, ln q, q^n - 1 (n = size.x - 1), thickness */
    SB_VEC4(mu_s);     /* the lowest mu_s node, the split (SB_ORDERS_MU_S_SPLIT), 1 where views read the
                          sun's azimuth log-trigonometrically (sb_orders_log_azimuth) else 0, the azimuth
                          nodes' power (sb_orders_azimuth_power) */
    SB_UINT order;     /* k, the order being computed (2 and up) */
    SB_UINT pad0, pad1, pad2;
};
/* mu_s nodes: half of them from the lowest to this, the rest on to 1. */
#define SB_ORDERS_MU_S_SPLIT 0.1

#endif
