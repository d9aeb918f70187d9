/*
 * The GPU tests' Vulkan context: validation on unless SKYBAKE_VALIDATE=0
 * says otherwise (for devices without the layers, e.g. accuracy runs on the
 * lent GPU); CI keeps it on. A failure other than "no device" is a failed
 * check; with no device at all the test skips (TEST_SKIP).
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

#endif
