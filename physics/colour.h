/*
 * Colour science in fp64, for the runtime's grading and the baker's colour
 * measurements: 3 x 3 matrices, RGB spaces from their primaries, Bradford's
 * chromatic adaptation, CIELAB and the CIEDE2000 colour difference. Pure
 * functions, thread safe.
 */
#ifndef SB_PHYSICS_COLOUR_H
#define SB_PHYSICS_COLOUR_H

/* Rec.709 / sRGB primaries r, g, b and white D65 (CIE 1931 xy), for a
 * `const double p[4][2]` initialiser. */
#define SB_REC709_PRIMARIES                                                                                            \
    {0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06},                                                                          \
    {                                                                                                                  \
        0.3127, 0.3290                                                                                                 \
    }

void sb_mat3_mul(const double a[3][3], const double b[3][3], double out[3][3]); /* out may be a or b */
void sb_mat3_apply(const double m[3][3], const double v[3], double out[3]);     /* out may be v */
void sb_mat3_invert(const double m[3][3], double out[3][3]);

/* xy to XYZ at Y = 1. */
void sb_xy_to_xyz(const double xy[2], double xyz[3]);

/* RGB to XYZ for primaries r, g, b and white w (xy, p[3]): RGB (1, 1, 1) is
 * w at Y = 1. */
void sb_primaries_to_xyz(const double p[4][2], double out[3][3]);

/* Bradford's von Kries adaptation of XYZ from white `from` to `to` (xy). */
void sb_bradford(const double from[2], const double to[2], double out[3][3]);

/* Linear Rec.709 to XYZ (D65); to ACES AP1 (its white, Bradford-adapted). */
void sb_rec709_to_xyz(double m[3][3]);
void sb_rec709_to_ap1(double m[3][3]);

/* CIELAB of XYZ against the reference white `white` (XYZ, its Y the
 * luminance that is L* = 100). */
void sb_xyz_to_lab(const double xyz[3], const double white[3], double lab[3]);

/* The CIEDE2000 difference between two CIELAB colours (Sharma, Wu and
 * Dalal 2005, with k_L = k_C = k_H = 1). */
double sb_ciede2000(const double lab1[3], const double lab2[3]);

#endif
