/*
 * The DFG (split-sum) LUT (baker/dfg.h) on the device against its fp64
 * reference: every channel within 1e-3 absolute at sampled texels (the
 * rows and columns at both ends included); the reference's two routes
 * agreeing where both apply; the smooth-surface limit (y -> 1, x -> the
 * Fresnel term at n.v); energy bounds everywhere; two bakes identical.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dfg.h"
#include "harness_vk.h"

int main(void)
{
    struct sb_vk *vk = NULL;
    enum sb_result res = test_vulkan(false, &vk);
    if (res == SB_ERR_NO_DEVICE)
        return test_no_device();
    if (res)
        return test_finish("dfg");
    struct sb_image lut = {0}, again = {0};
    double ms = 0;
    CHECK(sb_dfg_bake(vk, &lut, &ms) == SB_OK, "bake");
    CHECK(sb_dfg_bake(vk, &again, NULL) == SB_OK, "bake again");
    if (lut.data && again.data) {
        const int n = SB_DFG_SIZE;
        CHECK(!memcmp(lut.data, again.data, sizeof(float) * 2 * n * n), "two bakes differ");
        /* bounds: finite, 0 <= x <= y <= 1 (within the quadrature) */
        int bad = 0;
        for (int i = 0; i < n * n; i++) {
            float x = lut.data[2 * i], y = lut.data[2 * i + 1];
            bad += !(isfinite(x) && isfinite(y) && x >= 0 && x <= y && y <= 1.001f);
        }
        CHECK(bad == 0, "%d texels outside 0 <= x <= y <= 1", bad);

        static const int at[] = {0, 1, 2, 5, 10, 20, 32, 48, 64, 80, 100, 120, 126, 127};
        const int count = sizeof(at) / sizeof(at[0]);
        double worst = 0, sum2 = 0, worst_nv = 0, worst_r = 0;
        int values = 0;
        for (int a = 0; a < count; a++)
            for (int b = 0; b < count; b++) {
                int i = at[a], j = at[b];
                double n_v = (i + 0.5) / n, r = (j + 0.5) / n, ref[2];
                sb_dfg_reference(n_v, r, 48, ref);
                for (int c = 0; c < 2; c++) {
                    double e = fabs(lut.data[2 * (j * n + i) + c] - ref[c]);
                    sum2 += e * e;
                    values++;
                    if (e > worst) {
                        worst = e;
                        worst_nv = n_v;
                        worst_r = r;
                    }
                }
            }
        printf("dfg %dx%d (%d x %d samples a texel, %.1f ms on the device): max abs error %.2e (n.v %.4f, roughness "
               "%.4f), rms %.2e over %d values against the fp64 reference\n",
               n, n, SB_DFG_SAMPLES_SIDE, SB_DFG_SAMPLES_SIDE, ms, worst, worst_nv, worst_r, sqrt(sum2 / values),
               values);
        CHECK(worst <= 1e-3, "dfg: %g from the fp64 reference", worst);

        /* the reference: its two routes where D is smooth, and its own convergence */
        double route = 0, converge = 0;
        for (int k = 0; k < 6; k++) {
            double n_v = 0.05 + 0.18 * k, r = 0.5 + 0.09 * k, a[2], b[2], c[2];
            sb_dfg_reference(n_v, r, 48, a);
            sb_dfg_reference_direct(n_v, r, 48, b);
            sb_dfg_reference(n_v, r, 96, c);
            for (int ch = 0; ch < 2; ch++) {
                route = fmax(route, fabs(a[ch] - b[ch]));
                converge = fmax(converge, fabs(a[ch] - c[ch]));
            }
        }
        printf("reference: the inverse-CDF and direct routes agree to %.1e (roughness >= 0.5); 384 against 768 "
               "nodes a dimension: %.1e\n",
               route, converge);
        CHECK(route < 1e-5 && converge < 1e-5, "the reference's routes %g, convergence %g", route, converge);

        /* a mirror's limit in the first row: y -> 1, x -> (1 - n.v)^5 */
        double mirror = 0;
        for (int i = 0; i < n; i++) {
            double n_v = (i + 0.5) / n;
            mirror = fmax(mirror, fmax(fabs(lut.data[2 * i + 1] - 1.0), fabs(lut.data[2 * i] - pow(1 - n_v, 5))));
        }
        printf("smoothest row (roughness %.4f): within %.1e of a mirror's y = 1, x = (1 - n.v)^5\n", 0.5 / n, mirror);
        CHECK(mirror < 1e-3, "the smoothest row: %g from a mirror's", mirror);
    }
    sb_image_finish(&lut);
    sb_image_finish(&again);
    CHECK(sb_vk_validation_messages(vk) == 0, "%u validation messages", sb_vk_validation_messages(vk));
    sb_vk_destroy(&vk);
    return test_finish("dfg");
}
