/*
 * skyview's passes, in the order a frame records them (enum sb_pass,
 * renderer.h): a pass is a file of this folder defining its class, an
 * entry in that enum and one in this table.
 */
#include "renderer_internal.h"

extern const struct sb_pass_class sb_pass_sky_view, sb_pass_probes, sb_pass_reflections, sb_pass_aerial_perspective, sb_pass_shadows,
    sb_pass_cloud_shadow, sb_pass_fog, sb_pass_scene, sb_pass_contact_shadows, sb_pass_sky, sb_pass_clouds, sb_pass_fog_apply, sb_pass_purkinje,
    sb_pass_exposure, sb_pass_local_tonemap, sb_pass_grade_linear, sb_pass_bloom, sb_pass_tonemap, sb_pass_grade;

const struct sb_pass_class *const sb_pass_classes[SB_PASS_COUNT] = {
    [SB_PASS_SKY_VIEW] = &sb_pass_sky_view,
    [SB_PASS_PROBES] = &sb_pass_probes,
    [SB_PASS_REFLECTIONS] = &sb_pass_reflections,
    [SB_PASS_AERIAL_PERSPECTIVE] = &sb_pass_aerial_perspective,
    [SB_PASS_SHADOWS] = &sb_pass_shadows,
    [SB_PASS_CLOUD_SHADOW] = &sb_pass_cloud_shadow,
    [SB_PASS_FOG] = &sb_pass_fog,
    [SB_PASS_SCENE] = &sb_pass_scene,
    [SB_PASS_CONTACT_SHADOWS] = &sb_pass_contact_shadows,
    [SB_PASS_SKY] = &sb_pass_sky,
    [SB_PASS_CLOUDS] = &sb_pass_clouds,
    [SB_PASS_FOG_APPLY] = &sb_pass_fog_apply,
    [SB_PASS_PURKINJE] = &sb_pass_purkinje,
    [SB_PASS_EXPOSURE] = &sb_pass_exposure,
    [SB_PASS_LOCAL_TONEMAP] = &sb_pass_local_tonemap,
    [SB_PASS_GRADE_LINEAR] = &sb_pass_grade_linear,
    [SB_PASS_BLOOM] = &sb_pass_bloom,
    [SB_PASS_TONEMAP] = &sb_pass_tonemap,
    [SB_PASS_GRADE] = &sb_pass_grade,
};

const char *sb_pass_name(enum sb_pass pass)
{
    return pass < SB_PASS_COUNT ? sb_pass_classes[pass]->name : "?";
}

int sb_pass_toggles(uint32_t toggles[SB_PASS_COUNT])
{
    int n = 0;
    for (int p = 0; p < SB_PASS_COUNT; p++) {
        if (!sb_pass_classes[p]->optional || sb_pass_classes[p]->needs)
            continue;
        uint32_t mask = 1u << p;
        for (int q = 0; q < SB_PASS_COUNT; q++)
            if (sb_pass_classes[q]->optional && (sb_pass_classes[q]->needs >> p & 1))
                mask |= 1u << q;
        toggles[n++] = mask;
    }
    return n;
}
