/*
 * vulkan/: the validation the other GPU tests rely on. With validation on,
 * synchronisation validation is part of it: two writes of one buffer with
 * no barrier between them are a message (on lavapipe too, whose queue runs
 * in order and would never show the race), the same writes with a barrier
 * are none. Without this, a pass or a dispatch missing its barrier would
 * pass every test here and flicker on a GPU.
 */
#include <stdlib.h>
#include <string.h>

#include "compute.h"
#include "harness_vk.h"
#include "log.h"

static void quiet(void *user, enum sb_log_level level, const char *message)
{
    (void)user, (void)level, (void)message;
}

/* Two fills of `buffer`, with or without a barrier between them; returns
 * the validation messages they caused. */
static unsigned two_writes(struct sb_vk *vk, struct sb_buffer *buffer, bool barrier)
{
    unsigned before = sb_vk_validation_messages(vk);
    VkCommandBuffer cmd;
    enum sb_result res = sb_vk_begin_once(vk, &cmd);
    CHECK(res == SB_OK, "a command buffer");
    if (res)
        return 0;
    vkCmdFillBuffer(cmd, buffer->buffer, 0, VK_WHOLE_SIZE, 1u);
    if (barrier) {
        VkMemoryBarrier b = {
            .sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER,
            .srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT,
            .dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT,
        };
        vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &b, 0, NULL, 0,
                             NULL);
    }
    vkCmdFillBuffer(cmd, buffer->buffer, 0, VK_WHOLE_SIZE, 2u);
    CHECK(sb_vk_end_once(vk, cmd) == SB_OK, "submitted");
    return sb_vk_validation_messages(vk) - before;
}

int main(void)
{
    const char *env = getenv("SKYBAKE_VALIDATE");
    bool validating = !(env && !strcmp(env, "0"));
    struct sb_vk *vk = NULL;
    enum sb_result res = test_vulkan(false, &vk);
    if (res == SB_ERR_NO_DEVICE)
        return test_no_device();
    if (res)
        return test_finish("vulkan");
    struct sb_buffer buffer = {0};
    CHECK(sb_buffer_create(vk, 4096, "hazard", &buffer) == SB_OK, "a buffer");
    if (validating && buffer.buffer) {
        CHECK(two_writes(vk, &buffer, true) == 0, "two writes with a barrier between them: silent");
        sb_log_set_sink(quiet, NULL); /* the message below is the point */
        unsigned hazards = two_writes(vk, &buffer, false);
        sb_log_set_sink(NULL, NULL);
        CHECK(hazards > 0, "two writes with no barrier: %u messages (synchronisation validation is off?)", hazards);
    }
    sb_buffer_destroy(vk, &buffer);
    sb_vk_destroy(&vk);
    return test_finish("vulkan");
}
