/*
 * The cloud layer's bindings and parameters (runtime/passes/clouds.c,
 * cloud_layer.glsl); the scene and the fog read its parameters and shadow
 * map too. config.h's rules.
 */
#ifndef SB_SHADERS_CLOUDS_GPU_H
#define SB_SHADERS_CLOUDS_GPU_H

#include "config.h"

#define SB_VIEW_BINDING_CLOUDS 30           /* struct sb_clouds_gpu (clouds.glsl) */
#define SB_VIEW_BINDING_CLOUD_SHAPE 31      /* sampler3D, repeating: the pack's cloud_shape (or 1 texel of 0) */
#define SB_VIEW_BINDING_CLOUD_DETAIL 32     /* sampler3D, repeating: cloud_detail */
#define SB_VIEW_BINDING_CLOUD_CURL 33       /* sampler2D, repeating: cloud_curl */
#define SB_VIEW_BINDING_CLOUD_WEATHER 34    /* sampler2D, repeating: weather */
#define SB_VIEW_BINDING_CLOUD_SHADOW 35     /* sampler2D: the clouds' optical depth toward the sun from the ground */
#define SB_VIEW_BINDING_CLOUD_SHADOW_OUT 36 /* image2D rgba16f: the same, written */
#define SB_VIEW_BINDING_CLOUD_TRACE 37      /* sampler2D: the traced pixels' in-scattering (rgb), transmittance */
#define SB_VIEW_BINDING_CLOUD_TRACE_OUT 38  /* image2D rgba16f: the same, written */
#define SB_VIEW_BINDING_CLOUD_DEPTH 39      /* sampler2D r32f: the traced pixels' cloud distance (m) */
#define SB_VIEW_BINDING_CLOUD_DEPTH_OUT 40  /* image2D r32f: the same, written */
#define SB_VIEW_BINDING_CLOUD_HISTORY 41    /* sampler2D: the last frame's clouds at full resolution */
#define SB_VIEW_BINDING_CLOUD_OUT 42        /* image2D rgba16f: this frame's, written */

/* Volumetric clouds (cloud_layer.glsl; runtime/passes/clouds.c; docs/clouds.md): a
 * layer between two altitudes over the curved planet, its density from the
 * pack's weather map, shape and detail noise and curl. cloud_shadow.comp
 * writes the shadow map (SB_WORKGROUP_X x SB_WORKGROUP_Y), cloud_trace.comp
 * marches one pixel of each scale x scale block a frame, cloud_resolve.comp
 * rebuilds the full frame from it and the last frame's. */
#define SB_CLOUD_LIGHT_DISTANCE_M 4000.0 /* the light march's reach toward the sun */
#define SB_CLOUD_MAX_LIGHT_STEPS 16
#define SB_CLOUD_SHADOW_REACH_M 60000.0 /* the shadow map's longest crossing of the layer */
#define SB_CLOUD_REACH_M 80000.0 /* the view march's longest reach inside the layer */
#define SB_CLOUD_MAX_OCTAVES 8
struct sb_clouds_gpu {
    SB_MAT4(previous_view_proj); /* the last frame's camera-relative world to clip */
    SB_VEC4(layer);      /* x: base altitude (m); y: top altitude (m); z: 1 / thickness (1/m); w: extinction at
                            density 1 (1/m) */
    SB_VEC4(albedo);     /* rgb: single-scattering albedo; w: coverage */
    SB_VEC4(scales);     /* 1 / tile (1/m) of x: the weather map, y: the shape, z: the detail, w: the curl */
    SB_VEC4(erosion);    /* x: detail erosion; y: curl distortion (m); z: 1 when the layer is drawn; w: unused */
    SB_VEC4(weather_offset); /* xz: the weather map's drift (m, wrapped to its tile); y: unused; w: unused */
    SB_VEC4(shape_offset);   /* xyz: the shape's drift (m, wrapped to its tile); w: unused */
    SB_VEC4(detail_offset);  /* xyz: the detail's drift (m, wrapped to its tile); w: unused */
    SB_VEC4(phase);      /* x: forward g; y: backward g; z: forward weight; w: multiple-scattering octaves */
    SB_VEC4(march);      /* x: view steps at most; y: light steps; z: the view march's longest reach in the
                            layer (m); w: the shortest view step (m) */
    SB_VEC4(shadow);     /* xy: the shadow map's centre (world xz, m); z: its width (m); w: steps a texel */
    SB_VEC4(temporal);   /* x: this frame's jitter offset, [0, 1); y: the history's weight (0: none);
                            z: frames since the history began (this one's index); w: this frame's
                            radiance scale over the last's (the history's rgb times it) */
    SB_VEC4(camera_motion_m); /* xyz: this frame's camera minus the last frame's (m); w: unused */
    SB_UVEC4(trace);     /* xy: traced pixels; z: scale (a block's side, pixels); w: this frame's pixel in a
                            block, y scale + x */
};

#endif
