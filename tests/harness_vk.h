/*
 * The GPU tests' Vulkan context: validation on unless SKYBAKE_VALIDATE=0
 * says otherwise (for devices without the layers, e.g. accuracy runs on the
 * lent GPU); CI keeps it on. A failure other than "no device" is a failed
 * check; with no device at all the test skips (TEST_SKIP), unless
 * SKYBAKE_REQUIRE_DEVICE=1 (CI sets it: a suite that skips every GPU test
 * must not pass).
 */
#ifndef SB_TEST_HARNESS_VK_H
#define SB_TEST_HARNESS_VK_H

#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "context.h"
#include "harness.h"

static inline enum sb_result test_vulkan(bool graphics, struct sb_vk **vk)
{
    const char *env = getenv("SKYBAKE_VALIDATE");
    struct sb_vk_params params = {.validate = !(env && !strcmp(env, "0")), .graphics = graphics};
    *vk = NULL;
    enum sb_result res = sb_vk_create(&params, vk);
    if (res != SB_ERR_NO_DEVICE)
        CHECK(res == SB_OK, "creating the Vulkan context: %s", sb_result_name(res));
    return res;
}

/* What main returns when test_vulkan found no device: a failure when one
 * is required or a check before it failed, else a skip. */
static inline int test_no_device(void)
{
    const char *required = getenv("SKYBAKE_REQUIRE_DEVICE");
    if (required && !strcmp(required, "1")) {
        fprintf(stderr, "no Vulkan device, and SKYBAKE_REQUIRE_DEVICE=1: the GPU checks cannot be skipped\n");
        return 1;
    }
    return test_failures ? 1 : TEST_SKIP;
}

#endif
