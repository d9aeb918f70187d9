/*
 * Phase functions of the view passes' media.
 */
#ifndef SB_PHASE_GLSL
#define SB_PHASE_GLSL

#include "config.h"
#include "atmosphere.glsl" /* PI */

/* Henyey-Greenstein's phase function of asymmetry g at the scattering
 * angle's cosine, per steradian. */
float phase_hg(float g, float cos_theta)
{
    float d = 1.0 + g * g - 2.0 * g * cos_theta;
    return (1.0 - g * g) / (4.0 * PI * d * sqrt(d));
}

#endif
