/*
 * vulkan/: the context's layouts and pipelines, each made once for what
 * defines it and kept by the context (pipeline.h); and the validation the
 * other GPU tests rely on. With validation on,
 * synchronisation validation is part of it: two writes of one buffer with
 * no barrier between them are a message (on lavapipe too, whose queue runs
 * in order and would never show the race), the same writes with a barrier
 * are none. Without this, a pass or a dispatch missing its barrier would
 * pass every test here and flicker on a GPU. And texel buffers
 * (sb_buffer_create_texels): a kernel's fetches give back the bits the
 * host wrote.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "clouds.h"
#include "compute.h"
#include "dfg.h"
#include "harness_vk.h"
#include "log.h"
#include "pipeline.h"
#include "texels_probe.spv.h"

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

/* Made once for what defines them: the same definition gives the same
 * handles, without a compile; a different one, others. */
static void test_context_pipelines(struct sb_vk *vk)
{
    const struct sb_pipeline_params kernel = sb_dfg_kernel();
    const VkDescriptorSetLayoutBinding binding = {
        .binding = 0,
        .descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
        .descriptorCount = 1,
        .stageFlags = VK_SHADER_STAGE_COMPUTE_BIT,
    };
    VkDescriptorSetLayout sets[3];
    VkPipelineLayout layouts[3];
    CHECK(sb_vk_layout(vk, &binding, 1, VK_SHADER_STAGE_COMPUTE_BIT, 16, &sets[0], &layouts[0]) == SB_OK &&
              sb_vk_layout(vk, &binding, 1, VK_SHADER_STAGE_COMPUTE_BIT, 16, &sets[1], &layouts[1]) == SB_OK &&
              sb_vk_layout(vk, &binding, 1, VK_SHADER_STAGE_COMPUTE_BIT, 32, &sets[2], &layouts[2]) == SB_OK,
          "three layouts");
    CHECK(sets[0] == sets[1] && layouts[0] == layouts[1], "a layout asked for twice is one");
    CHECK(layouts[2] != layouts[0], "push constants of another size: another layout");

    /* the DFG kernel on a layout of its own, its constant 0 specialised or not */
    struct sb_pipeline p[2];
    CHECK(sb_pipeline_create(vk, &kernel, &p[0]) == SB_OK, "the DFG kernel");
    uint32_t held = sb_vk_pipeline_count(vk);
    CHECK(sb_pipeline_create(vk, &kernel, &p[1]) == SB_OK, "the DFG kernel again");
    CHECK(p[1].pipeline == p[0].pipeline && p[1].layout == p[0].layout && p[1].set != p[0].set,
          "the same kernel again: its pipeline and layouts, a set of its own");
    CHECK(sb_vk_pipeline_count(vk) == held, "and no compile: %u pipelines held, %u before", sb_vk_pipeline_count(vk),
          held);
    sb_pipeline_destroy(vk, &p[1]);
    uint32_t values[2] = {1, 2};
    const VkSpecializationMapEntry entry = {.constantID = 0, .offset = 0, .size = sizeof(uint32_t)};
    VkPipeline special[3] = {VK_NULL_HANDLE};
    for (int i = 0; i < 3; i++) {
        const VkSpecializationInfo info = {
            .mapEntryCount = 1, .pMapEntries = &entry, .dataSize = sizeof(uint32_t), .pData = &values[i & 1]};
        CHECK(sb_compute_pipeline_create(vk, p[0].layout, kernel.spirv, kernel.spirv_size, &info, "specialised",
                                         &special[i]) == SB_OK,
              "specialised %d", i);
    }
    CHECK(special[0] != p[0].pipeline && special[1] != special[0], "another specialisation: another pipeline");
    CHECK(special[2] == special[0], "the same one again: the same pipeline");
    CHECK(sb_vk_pipeline_count(vk) == held + 2, "two compiles for three specialised: %u held, %u before",
          sb_vk_pipeline_count(vk), held);

    /* compiled ahead: found, not compiled again; listed twice, compiled once */
    const struct sb_pipeline_params ahead[2] = {sb_cloud_kernel(SB_PRODUCT_CLOUD_SHAPE),
                                                sb_cloud_kernel(SB_PRODUCT_CLOUD_SHAPE)};
    held = sb_vk_pipeline_count(vk);
    sb_pipelines_prepare(vk, ahead, 2, 2);
    CHECK(sb_vk_pipeline_count(vk) == held + 1, "a kernel listed twice compiles once ahead: %u held, %u before",
          sb_vk_pipeline_count(vk), held);
    struct sb_pipeline taken;
    CHECK(sb_pipeline_create(vk, &ahead[0], &taken) == SB_OK, "the kernel compiled ahead");
    CHECK(sb_vk_pipeline_count(vk) == held + 1, "found where it was compiled ahead: %u held, %u before",
          sb_vk_pipeline_count(vk), held);
    sb_pipeline_destroy(vk, &taken);
    sb_pipeline_destroy(vk, &p[0]);
}

/* A texel binding beside a storage one: tests/texels_probe.comp copies
 * texels fetched at scattered indices, and one that every invocation
 * fetches, into the storage buffer; each must be the host's bits. */
static void test_texels(struct sb_vk *vk)
{
    enum { N = 1000 };
    const struct sb_pipeline_params kernel = {
        .spirv = sb_spv_texels_probe,
        .spirv_size = sizeof(sb_spv_texels_probe),
        .binding_count = 2,
        .texel_bindings = 1u << 0,
        .push_size = sizeof(uint32_t),
        .name = "texels probe",
    };
    struct sb_buffer texels = {0}, copies = {0};
    struct sb_pipeline p = {0};
    float *got = malloc(2 * N * 4 * sizeof(float));
    bool ok = got && sb_buffer_create_texels(vk, N * 4 * sizeof(float), "texels", &texels) == SB_OK &&
              sb_buffer_create(vk, 2 * N * 4 * sizeof(float), "copies", &copies) == SB_OK &&
              sb_pipeline_create(vk, &kernel, &p) == SB_OK;
    CHECK(ok, "a texel buffer and its kernel");
    if (!ok)
        goto done;
    float *in = texels.mapped;
    for (int i = 0; i < 4 * N; i++) /* every value another, some far from 1 */
        in[i] = ldexpf(1.0f + (float)i / (4 * N), i % 61 - 30) * (i % 3 == 1 ? -1.0f : 1.0f);
    const struct sb_buffer *bound[2] = {&texels, &copies};
    sb_pipeline_bind(vk, &p, bound);
    uint32_t n = N;
    double ms;
    ok = sb_dispatch(vk, &p, &n, (N + 63) / 64, 1, 1, &ms) == SB_OK && sb_buffer_read(vk, &copies, got) == SB_OK;
    CHECK(ok, "the texels copied");
    if (!ok)
        goto done;
    int wrong = 0;
    for (int i = 0; i < N; i++)
        for (int c = 0; c < 4; c++) {
            wrong += memcmp(&got[4 * i + c], &in[4 * (i * 7919 % N) + c], sizeof(float)) != 0;
            wrong += memcmp(&got[4 * (N + i) + c], &in[4 * (N - 1) + c], sizeof(float)) != 0;
        }
    CHECK(wrong == 0, "texels fetched at scattered and at one index: %d of %d values not the host's", wrong, 8 * N);
done:
    free(got);
    sb_pipeline_destroy(vk, &p);
    sb_buffer_destroy(vk, &texels);
    sb_buffer_destroy(vk, &copies);
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
    unsigned messages = sb_vk_validation_messages(vk);
    test_context_pipelines(vk);
    CHECK(sb_vk_validation_messages(vk) == messages, "the context's pipelines: %u validation messages",
          sb_vk_validation_messages(vk) - messages);
    messages = sb_vk_validation_messages(vk);
    test_texels(vk);
    CHECK(sb_vk_validation_messages(vk) == messages, "texel buffers: %u validation messages",
          sb_vk_validation_messages(vk) - messages);
    sb_vk_destroy(&vk);
    return test_finish("vulkan");
}
