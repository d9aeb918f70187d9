/*
 * skyview's contracts shared between C and GLSL (config.h's rules): what
 * more than one pass reads, and the frame's constants. Each pass has its
 * own descriptor set (runtime/graph.h), of the bindings it declares; these
 * are the numbers of the resources several passes share, bindings 0 to 3
 * being the atmosphere's (config.h, in their lookup forms). A pass's own
 * bindings and GPU struct are in its header beside it (fog_gpu.h,
 * clouds_gpu.h, probes_gpu.h, reflections_gpu.h, grading_gpu.h,
 * purkinje_gpu.h, local_tonemap_gpu.h). The world frame is y up, in
 * metres, with the origin on the ground; the planet's centre is at
 * (0, -ground radius, 0). Shaders work relative to the camera.
 */
#ifndef SB_SHADERS_VIEW_GPU_H
#define SB_SHADERS_VIEW_GPU_H

#include "config.h"

#define SB_VIEW_BINDING_FRAME 4          /* struct sb_frame_gpu */
#define SB_VIEW_BINDING_VERTICES 5       /* struct sb_vertex_gpu[] */
#define SB_VIEW_BINDING_EXPOSURE 6       /* histogram bins, then struct sb_exposure_gpu */
#define SB_VIEW_BINDING_SKY_VIEW 7       /* sampler2D: the sky-view LUT */
#define SB_VIEW_BINDING_SKY_VIEW_OUT 8   /* image2D rgba16f: the same, written */
#define SB_VIEW_BINDING_AERIAL 9         /* sampler3D: in-scattered radiance (rgb) */
#define SB_VIEW_BINDING_AERIAL_T 10      /* sampler3D: transmittance (rgb) */
#define SB_VIEW_BINDING_AERIAL_OUT 11    /* image3D rgba16f */
#define SB_VIEW_BINDING_AERIAL_T_OUT 12  /* image3D rgba16f */
#define SB_VIEW_BINDING_SHADOW 13        /* sampler2DArrayShadow: the cascades */
#define SB_VIEW_BINDING_HDR 14           /* image2D rgba16f: the lit frame */
#define SB_VIEW_BINDING_DEPTH 15         /* sampler2D: the scene's depth (reverse Z, 0 = sky) */
#define SB_VIEW_BINDING_BLOOM_SRC 16     /* sampler2D: a bloom step's source (per descriptor set) */
#define SB_VIEW_BINDING_BLOOM_DST 17     /* image2D rgba16f: a bloom step's target (per set) */
#define SB_VIEW_BINDING_BLOOM 18         /* sampler2D: the finished bloom, mip 0 */
#define SB_VIEW_BINDING_LDR 19           /* image2D rgba8: the display-referred frame */
#define SB_VIEW_BINDING_BVH_NODES 43        /* the world's BVH (geometry/bvh.h) when traced: its nodes */
#define SB_VIEW_BINDING_BVH_TRIANGLES 44    /* its triangles; material 1: casts shadows, 0: does not */
#define SB_VIEW_BINDING_DEPTH_OUT 45        /* image2D r32f: the traced scene's depth, written */
#define SB_VIEW_BINDING_TEXTURES 51         /* the world's textures (vulkan/texels.h): a record an image */
#define SB_VIEW_BINDING_TEXELS 52           /* and their texels, with their mips */
#define SB_VIEW_BINDING_INSTANCES 53        /* struct sb_instance_gpu[]: an instanced world's placed copies */
#define SB_VIEW_BINDING_VISIBLE 54          /* uint[]: the instances each raster draw draws (this frame's cull) */
#define SB_VIEW_BINDING_EMISSIVE 55         /* struct sb_emissive_gpu[]: the world's materials that emit */
#define SB_VIEW_BINDING_SHADOW_DEPTH 58     /* sampler2DArray: the cascades' depths, for the soft shadows' search */
#define SB_VIEW_BINDING_SUN_HISTORY 59      /* image2D rgba16f: the traced scene's key-light visibility, last frame's */
#define SB_VIEW_BINDING_SUN_HISTORY_OUT 60  /* image2D rgba16f: the same, this frame's: x the mean of the rays of the
                                               frames kept, y how many (at most SB_SUN_RAYS), z the point's
                                               distance from the camera (m) */
#define SB_VIEW_BINDING_SCENE_HISTORY 61    /* struct sb_scene_history_gpu */
#define SB_VIEW_BINDING_KEY_LIGHT 65        /* image2D rgba16f: the raster scene's key light direct share a pixel */
#define SB_VIEW_BINDING_ORDERS 66           /* sampler2DArray (linear): the orders product (config.h), its image's
                                               texels as RGBA32F, filtered in mu and nu (view.glsl); a layer for the
                                               scene's channels, and with the spectral products one a band; a 1 x 1
                                               stand-in without it */
/* The specialization constants every view kernel takes (runtime/pass.c):
 * true when the pack has the orders product, which then gives orders 2
 * and up instead of Hillaire's psi_ms (view.glsl); true when it has the
 * spectral products too, the sky then drawn at their 12 wavelengths, a
 * band of three at a time (view.glsl's sky_radiance_rgb); and the bands
 * a kernel may give lanes of its own (1, or SB_SPECTRAL_BANDS with the
 * spectral products: the aerial perspective's workgroup depth). */
#define SB_VIEW_CONSTANT_ORDERS 8
#define SB_VIEW_CONSTANT_BANDS 9
#define SB_VIEW_CONSTANT_BAND_LANES 10
/* Contact shadows (contact_shadows.comp): steps and reach of the march
 * toward the key light (a fraction of the pixel's distance, at most
 * SB_CONTACT_MAX_M), the thickness a surface is taken to have behind the
 * depth buffer, and the bias (a fraction of the distance) under which a
 * step is the pixel's own surface. */
#define SB_CONTACT_STEPS 16
#define SB_CONTACT_REACH 0.1
#define SB_CONTACT_MAX_M 1.0
#define SB_CONTACT_THICKNESS 0.01
#define SB_CONTACT_MIN_THICKNESS_M 0.05
#define SB_CONTACT_BIAS 0.002
/* The traced scene's penumbrae: a ray a frame toward a point of the key
 * light's disk, the mean of the last SB_SUN_RAYS kept (scene_trace.comp). */
#define SB_SUN_RAYS 32

/* What the traced scene's penumbrae read of the last frame. */
struct sb_scene_history_gpu {
    SB_MAT4(previous_view_proj); /* the last frame's camera-relative world to clip */
    SB_VEC4(camera_motion_m);    /* xyz: this frame's camera minus the last's (m); w: 1 when the history holds */
    SB_UVEC4(frame);             /* x: frames drawn before this one */
};

/* A shadow ray's reach: past any two points of a world (4 x SB_MESH_MAX_EXTENT_M, geometry/mesh.h). */
#define SB_TRACE_FAR_M 4.0e4

/* What the scene pass writes (sb_frame_gpu.size.w): the lit frame, or for
 * tests one term of it, in the pack's radiance units times the frame's
 * scale, without aerial perspective. */
#define SB_DEBUG_NONE 0
#define SB_DEBUG_ENV_SPECULAR 1 /* the ambient specular alone */
#define SB_DEBUG_FOG 2          /* the fog's in-scattering alone (rgb), after the fog apply pass */
#define SB_DEBUG_FOG_TRANSMITTANCE 3 /* the fog's transmittance (grey), likewise */
#define SB_DEBUG_CLOUDS 4             /* the clouds' in-scattering alone (rgb), before aerial perspective */
#define SB_DEBUG_CLOUD_TRANSMITTANCE 5 /* the clouds' transmittance (grey) */
#define SB_DEBUG_CLOUD_SHADOW 6       /* the scene: the clouds' transmittance toward the sun (grey) */
#define SB_DEBUG_SUN_VISIBILITY 7     /* the scene: the sun's visibility, its shadows (grey) */
#define SB_DEBUG_AMBIENT 8            /* the scene: the ambient irradiance on its surfaces (rgb: the probes' or the sky model's) */

#define SB_SKY_VIEW_WIDTH 192 /* azimuth from the sun, 0 to pi */
#define SB_SKY_VIEW_HEIGHT 108 /* zenith angle, the horizon between rows 53 and 54 */
#define SB_SKY_LIGHTS 2        /* the sun and the moon: the sky-view LUT's layers */
#define SB_AERIAL_SIZE 32      /* x, y: screen; z: distance slices */
#define SB_CASCADES 4
/* The margins of a cascade's casters' box (renderer.c, passes/shadows.c, shadows.glsl): the
 * lookups are made within SB_SHADOW_RECT_MARGIN_TEXELS of the box
 * (frame.cascade_rect), and the raster's filter (3 x 3 taps a texel apart,
 * each a bilinear compare) reads SB_SHADOW_FILTER_REACH_HALF_TEXELS / 2
 * texels further; SB_SHADOW_CLEAR_MARGIN_TEXELS are cleared and drawn past
 * the box, so every texel a lookup reads holds what a whole map would. */
#define SB_SHADOW_RECT_MARGIN_TEXELS 2
#define SB_SHADOW_FILTER_REACH_HALF_TEXELS 5
#define SB_SHADOW_CLEAR_MARGIN_TEXELS 5
#ifndef GL_core_profile
_Static_assert(2 * SB_SHADOW_CLEAR_MARGIN_TEXELS >= 2 * SB_SHADOW_RECT_MARGIN_TEXELS + SB_SHADOW_FILTER_REACH_HALF_TEXELS,
               "the cleared margin covers what the filter reads past the lookups' box");
#endif
/* The scene's soft shadows (shadows.glsl, SB_SOFT_SHADOWS): gathers of the
 * blocker search and taps of the filter, and the widest either reaches (texels;
 * a tap outside the casters' box, where the map was neither cleared nor
 * drawn, reads no caster, as the lookups do). */
#define SB_SHADOW_SEARCH_TAPS 6
#define SB_SHADOW_FILTER_TAPS 8
#define SB_SHADOW_SEARCH_TEXELS 24
#define SB_HISTOGRAM_BINS 256
#define SB_BLOOM_MAX_LEVELS 6

/* Tone mappers: sb_renderer_params.tonemap, the tonemap pass's kernel (tonemap.comp's SB_TONEMAP_OP). */
#define SB_TONEMAP_AGX 0
#define SB_TONEMAP_ACES 1
#define SB_TONEMAP_GT 2

/* One vertex of the world: a triangle list, each vertex carrying its material. */
struct sb_vertex_gpu {
    SB_VEC4(position); /* xyz: m, world; w: metallic */
    SB_VEC4(normal);   /* xyz: unit normal; w: perceptual roughness */
    SB_VEC4(albedo);   /* rgb: base colour, linear; w: its material's emission + 1 (0: none;
                          SB_VIEW_BINDING_EMISSIVE) */
    SB_VEC4(uv);       /* xy: texture coordinates (u right, v up); z: the base colour's texture + 1,
                          w: the metallic-roughness's (0: none; SB_VIEW_BINDING_TEXTURES) */
    SB_VEC4(tangent);  /* xyz: unit, along u, world; w: +-(the normal map's texture + 1), the sign
                          the bitangent's handedness (0: none) */
};

/* What a material emits: glTF's emissive factor (linear radiance, in the
 * frame's units: 1 shines as a white surface lit by a sun of irradiance
 * pi), times its emissive texture's rgb (sRGB) where it has one. */
struct sb_emissive_gpu {
    SB_VEC4(radiance); /* rgb: the factor; w: the emissive texture + 1 (0: none) */
};

/* A placed copy of one of an instanced world's meshes (runtime/world.h):
 * rows of the affine map from the mesh's space to the world's (m), and of
 * its normals' (the inverse transpose of its linear part). The raster path
 * draws instance visible[gl_InstanceIndex] (the frame's cull writes the
 * list); the traced path reads the one its BVH record names (bvh.h:
 * instances in this order). */
struct sb_instance_gpu {
    SB_VEC4(to_world[3]);
    SB_VEC4(normal[3]);
};

/* Per-frame constants (std430). */
struct sb_frame_gpu {
    SB_MAT4(view_proj);        /* camera-relative world (m) to clip, reverse Z, infinite far */
    SB_MAT4(inv_view_proj);
    SB_MAT4(shadow_view_proj[SB_CASCADES]); /* camera-relative world (m) to each cascade's clip */
    SB_VEC4(camera_m);         /* the camera in the world (m); w: the near plane's distance (m) */
    SB_VEC4(camera_km);        /* planet-centred camera (km); w: its altitude (km) */
    SB_VEC4(camera_forward);   /* unit view direction, world; w: cos of the sun's angular radius */
    SB_VEC4(sun_direction);    /* unit vector toward the sun, world; w: sun's angular radius (rad) */
    SB_VEC4(moon_direction);   /* unit vector toward the moon, world; w: its angular radius (rad), 0: no moon */
    SB_VEC4(moon_light);       /* rgb: the moon's irradiance over the sun's, per channel, above the
                                  atmosphere; w: 1 / the solid-angle integral of its disk's shading
                                  (view.glsl's moon_disk) */
    SB_VEC4(lights);           /* x: the lights that scatter in the sky (1: the sun; 2: the sun and the
                                  moon); y: the key light, which lights the world, the fog and the clouds
                                  directly and casts the shadows (0: the sun; 1: the moon, the sun being
                                  down); zw: unused. frame.glsl reads them */
    SB_VEC4(cascade_ends);     /* view depth (m) where each cascade ends */
    SB_VEC4(cascade_texel);    /* a shadow texel's width (m) in each cascade */
    SB_VEC4(cascade_depth_m);  /* the depth each cascade's map spans, 0 to 1 (m) */
    SB_VEC4(cascade_rect[SB_CASCADES]); /* uv box (min xy, max xy) outside which a cascade has no caster:
                                           lookups there see the sun without reading the map */
    SB_MAT4(far_view_proj);    /* camera-relative world (m) to the far map's clip (layer SB_CASCADES of
                                  the cascades' image), fixed in the world: past the last cascade */
    SB_VEC4(far_shadow);       /* x: the far map's texel (m), y: the depth it spans (m), w: 1 when drawn */
    SB_VEC4(shadow);           /* x: blend band (fraction of a cascade), y: normal offset (texels),
                                  z: shadow map size (texels), w: 1 to use shadows */
    SB_VEC4(aerial);           /* x: the volume's far distance (km); y: radiance scale (what the frame's
                                  radiance is multiplied by before storage); zw: unused */
    SB_VEC4(exposure);         /* x: log2 luminance at bin 1, y: log2 range of bins 1..255,
                                  z, w: low and high percentile of the metering window */
    SB_VEC4(meter);            /* x, y: the adapted log2 luminance's range (the EV range's, in the pack's
                                  units); z: stops of exposure taken off a stop under w, the log2
                                  luminance below which the eye no longer sees a mid grey */
    SB_VEC4(adaptation);       /* x: speed to brighter (1/s), y: to darker (1/s), z: dt (s), w: 1 to snap */
    SB_VEC4(post);             /* x: bloom threshold (exposed), y: bloom strength, z: exposure
                                  compensation (EV), w: 0 (the tone curve is the kernel's) */
    SB_UVEC4(size);            /* xy: frame size; z: bloom levels; w: SB_DEBUG_* */
    SB_UVEC4(orders_size);     /* the orders product's grid (config.h's sb_orders_push: size, heights, */
    SB_VEC4(orders_heights);   /* mu_s); zeros when the pack has none */
    SB_VEC4(orders_mu_s);
    /* rgb: wavelength i of the spectral products' 12 to linear Rec.709 under the scene's sun
     * (physics/spectrum.h's sb_spectral_to_rec709); zeros without them */
    SB_VEC4(spectral_rgb[3 * SB_SPECTRAL_BANDS]);
};

/* What exposure.comp keeps between frames, after the histogram's bins. */
struct sb_exposure_gpu {
    SB_VEC4(state); /* x: adapted log2 luminance; y: exposure (multiplier); z: metered log2 luminance
                       of this frame; w: pixels in the metering window */
};

/* Rec.709's luminance weights (linear R, G, B), for C ({SB_LUMINANCE_RGB})
 * and GLSL (vec3(SB_LUMINANCE_RGB)) alike. */
#define SB_LUMINANCE_RGB 0.2126, 0.7152, 0.0722

/* Push constants of skyview's passes. */
struct sb_view_push {
    SB_UINT cascade;     /* shadow.vert: the cascade drawn */
    SB_UINT level;       /* bloom: the mip level written */
    SB_UINT first_level; /* bloom_down: 1 when reading the frame (threshold and Karis average) */
    SB_UINT item;        /* reflection relight: the cube relit */
};

#endif
