/*
 * physics/colour.c against published values: CIEDE2000 on the 34 pairs of
 * Sharma, Wu and Dalal's test data (2005, table 1, to the 4 decimals they
 * give, in both orders: the difference is symmetric), and CIELAB of the
 * sRGB primaries and white (linear Rec.709 through XYZ, D65), as Lindbloom's
 * calculator gives them from the standard's matrix. No Vulkan.
 */
#include <math.h>

#include "colour.h"
#include "harness.h"

static const struct {
    double lab1[3], lab2[3], de;
} sharma[] = {
    {{50.0000, 2.6772, -79.7751}, {50.0000, 0.0000, -82.7485}, 2.0425},
    {{50.0000, 3.1571, -77.2803}, {50.0000, 0.0000, -82.7485}, 2.8615},
    {{50.0000, 2.8361, -74.0200}, {50.0000, 0.0000, -82.7485}, 3.4412},
    {{50.0000, -1.3802, -84.2814}, {50.0000, 0.0000, -82.7485}, 1.0000},
    {{50.0000, -1.1848, -84.8006}, {50.0000, 0.0000, -82.7485}, 1.0000},
    {{50.0000, -0.9009, -85.5211}, {50.0000, 0.0000, -82.7485}, 1.0000},
    {{50.0000, 0.0000, 0.0000}, {50.0000, -1.0000, 2.0000}, 2.3669},
    {{50.0000, -1.0000, 2.0000}, {50.0000, 0.0000, 0.0000}, 2.3669},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0009}, 7.1792},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0010}, 7.1792},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0011}, 7.2195},
    {{50.0000, 2.4900, -0.0010}, {50.0000, -2.4900, 0.0012}, 7.2195},
    {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0009, -2.4900}, 4.8045},
    {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0010, -2.4900}, 4.8045},
    {{50.0000, -0.0010, 2.4900}, {50.0000, 0.0011, -2.4900}, 4.7461},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 0.0000, -2.5000}, 4.3065},
    {{50.0000, 2.5000, 0.0000}, {73.0000, 25.0000, -18.0000}, 27.1492},
    {{50.0000, 2.5000, 0.0000}, {61.0000, -5.0000, 29.0000}, 22.8977},
    {{50.0000, 2.5000, 0.0000}, {56.0000, -27.0000, -3.0000}, 31.9030},
    {{50.0000, 2.5000, 0.0000}, {58.0000, 24.0000, 15.0000}, 19.4535},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 3.1736, 0.5854}, 1.0000},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 3.2972, 0.0000}, 1.0000},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 1.8634, 0.5757}, 1.0000},
    {{50.0000, 2.5000, 0.0000}, {50.0000, 3.2592, 0.3350}, 1.0000},
    {{60.2574, -34.0099, 36.2677}, {60.4626, -34.1751, 39.4387}, 1.2644},
    {{63.0109, -31.0961, -5.8663}, {62.8187, -29.7946, -4.0864}, 1.2630},
    {{61.2901, 3.7196, -5.3901}, {61.4292, 2.2480, -4.9620}, 1.8731},
    {{35.0831, -44.1164, 3.7933}, {35.0232, -40.0716, 1.5901}, 1.8645},
    {{22.7233, 20.0904, -46.6940}, {23.0331, 14.9730, -42.5619}, 2.0373},
    {{36.4612, 47.8580, 18.3852}, {36.2715, 50.5065, 21.2231}, 1.4146},
    {{90.8027, -2.0831, 1.4410}, {91.1528, -1.6435, 0.0447}, 1.4441},
    {{90.9257, -0.5406, -0.9208}, {88.6381, -0.8985, -0.7239}, 1.5381},
    {{6.7747, -0.2908, -2.4247}, {5.8714, -0.0985, -2.2286}, 0.6377},
    {{2.0776, 0.0795, -1.1350}, {0.9033, -0.0636, -0.5514}, 0.9082},
};

static void test_ciede2000(void)
{
    int n = (int)(sizeof(sharma) / sizeof(sharma[0]));
    double worst = 0.0;
    for (int i = 0; i < n; i++) {
        double a = sb_ciede2000(sharma[i].lab1, sharma[i].lab2), b = sb_ciede2000(sharma[i].lab2, sharma[i].lab1);
        double e = fmax(fabs(a - sharma[i].de), fabs(b - sharma[i].de));
        worst = fmax(worst, e);
        /* the table's 4 decimals */
        CHECK(e <= 5e-5, "pair %d: CIEDE2000 %.5f and %.5f, published %.4f", i + 1, a, b, sharma[i].de);
    }
    printf("CIEDE2000: %d pairs of Sharma, Wu and Dalal's data within %.2g of the published values, both orders\n", n,
           worst);
    CHECK(sb_ciede2000(sharma[16].lab2, sharma[16].lab2) == 0.0, "a colour against itself: 0");
}

static void test_lab(void)
{
    static const struct {
        double rgb[3], lab[3];
    } cases[] = {
        {{1, 1, 1}, {100.0, 0.0, 0.0}},
        {{1, 0, 0}, {53.2408, 80.0925, 67.2032}},
        {{0, 1, 0}, {87.7347, -86.1827, 83.1793}},
        {{0, 0, 1}, {32.2970, 79.1875, -107.8602}},
    };
    double m[3][3], white[3];
    sb_rec709_to_xyz(m);
    sb_mat3_apply(m, (const double[3]){1, 1, 1}, white);
    double worst = 0.0, worst_de = 0.0;
    for (size_t i = 0; i < sizeof(cases) / sizeof(cases[0]); i++) {
        double xyz[3], lab[3];
        sb_mat3_apply(m, cases[i].rgb, xyz);
        sb_xyz_to_lab(xyz, white, lab);
        for (int c = 0; c < 3; c++)
            worst = fmax(worst, fabs(lab[c] - cases[i].lab[c]));
        /* the published values take IEC 61966-2-1's matrix, rounded to 4
         * decimals (5e-5 of coefficients near 0.4: 1e-4 relative), where
         * ours comes from the primaries exactly: 1e-2 of a CIEDE2000 unit */
        double de = sb_ciede2000(lab, cases[i].lab);
        worst_de = fmax(worst_de, de);
        CHECK(de < 1e-2, "sRGB (%g, %g, %g): Lab (%.4f, %.4f, %.4f), published (%.4f, %.4f, %.4f)", cases[i].rgb[0],
              cases[i].rgb[1], cases[i].rgb[2], lab[0], lab[1], lab[2], cases[i].lab[0], cases[i].lab[1],
              cases[i].lab[2]);
    }
    printf("CIELAB of the sRGB primaries and white: within %.2g of the published values (CIEDE2000 %.2g)\n", worst,
           worst_de);
    /* below (6/29)^3 the line: Y = 0.001 of white is L* = 903.3 * 0.001 */
    double dark[3] = {0.001 * white[0], 0.001 * white[1], 0.001 * white[2]}, lab[3];
    sb_xyz_to_lab(dark, white, lab);
    CHECK(fabs(lab[0] - 0.9033) < 1e-3 && fabs(lab[1]) < 1e-9 && fabs(lab[2]) < 1e-9, "a dark grey: L* %.5f", lab[0]);
}

int main(void)
{
    test_ciede2000();
    test_lab();
    return test_finish("colour");
}
