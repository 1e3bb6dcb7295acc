#include "misuse.h"

#include <array>
#include <cstdio>
#include <cstring>
#include <string>

namespace {

struct Table {
    int cases = 0;
    int failed = 0;

    // `got` must be `want`, and histencil's message must contain `words`.
    void expect(HistencilResult got, HistencilResult want, const char *words, const char *what) {
        ++cases;
        const char *message = histencil_last_error();
        if (got != want || std::strstr(message, words) == nullptr) {
            std::fprintf(stderr, "misuse `%s`: got %d (%s), want %d saying `%s`\n", what,
                         static_cast<int>(got), message, static_cast<int>(want), words);
            ++failed;
        }
    }
};

// The engine's records of its images, gathered as histencil_lighting_record takes them.
struct CTargets {
    std::array<HistencilImage, HISTENCIL_GBUFFER_IMAGES> gbuffer;
    HistencilImage depth_stencil;
    HistencilImage hdr;
    HistencilTargets targets{};

    explicit CTargets(const Targets &t) : depth_stencil(t.depth_stencil.state), hdr(t.hdr.state) {
        for (uint32_t i = 0; i < HISTENCIL_GBUFFER_IMAGES; ++i) gbuffer[i] = t.gbuffer[i].state;
        targets.size = sizeof targets;
        targets.gbuffer_count = HISTENCIL_GBUFFER_IMAGES;
        targets.gbuffer = gbuffer.data();
        targets.depth_stencil = &depth_stencil;
        targets.hdr = &hdr;
    }
};

}  // namespace

int run_misuse_table(HistencilContext *context, VkDevice device, uint32_t queue_family,
                     const HistencilLightingDesc &desc, Targets &targets, const MisuseFrame &frame,
                     int &failed) {
    Table t;
    // The description: a wrong size, a BRDF histencil does not know, too many frames in flight.
    HistencilLightingDesc bad = desc;
    bad.size = 3;
    HistencilLighting *never = nullptr;
    t.expect(histencil_lighting_create(context, &bad, &never), HISTENCIL_RESULT_INVALID_ARGUMENT,
             "HistencilLightingDesc.size is 3", "a wrong struct size");
    bad = desc;
    bad.frames_in_flight = 99;
    t.expect(histencil_lighting_create(context, &bad, &never), HISTENCIL_RESULT_INVALID_ARGUMENT,
             "frames_in_flight is 99", "frames in flight out of range");
    const char *velvet[] = {"lambert", "velvet"};
    bad = desc;
    bad.brdf_count = 2;
    bad.brdf_names = velvet;
    t.expect(histencil_lighting_create(context, &bad, &never), HISTENCIL_RESULT_BAD_SETUP,
             "no BRDF named `velvet`", "a BRDF name histencil lacks");
    t.expect(histencil_lighting_create(nullptr, &desc, &never), HISTENCIL_RESULT_INVALID_ARGUMENT,
             "context is null", "a null context");

    HistencilLighting *lighting = nullptr;
    const HistencilResult made = histencil_lighting_create(context, &desc, &lighting);
    if (made != HISTENCIL_RESULT_SUCCESS) {
        std::fprintf(stderr, "misuse table: its lighting: %s\n", histencil_last_error());
        failed += t.failed + 1;
        return t.cases;
    }
    uint8_t reference = 0, mask = 0;
    t.expect(histencil_lighting_stencil_reference(lighting, "velvet", &reference, &mask),
             HISTENCIL_RESULT_BAD_SETUP, "velvet", "a BRDF the lighting lacks");

    // A command buffer that is recorded into and never submitted.
    VkCommandPool pool = VK_NULL_HANDLE;
    VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool_info.queueFamilyIndex = queue_family;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    bool recording = vkCreateCommandPool(device, &pool_info, nullptr, &pool) == VK_SUCCESS;
    if (recording) {
        VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
        alloc.commandPool = pool;
        alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
        alloc.commandBufferCount = 1;
        VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        recording = vkAllocateCommandBuffers(device, &alloc, &cmd) == VK_SUCCESS &&
                    vkBeginCommandBuffer(cmd, &begin) == VK_SUCCESS;
    }
    if (recording) {
        HistencilFrame f{};
        f.size = sizeof f;
        f.technique = HISTENCIL_TECHNIQUE_STENCIL;
        f.platform = HISTENCIL_PLATFORM_NATIVE;
        f.view = frame.view;
        f.light_count = static_cast<uint32_t>(frame.lights->size());
        f.lights = frame.lights->data();
        f.brdf_bounds_count = static_cast<uint32_t>(frame.bounds->size());
        f.brdf_bounds = frame.bounds->data();
        f.clear_hdr = 1;
        CTargets c(targets);
        t.expect(histencil_lighting_record(lighting, cmd, nullptr, &c.targets),
                 HISTENCIL_RESULT_INVALID_ARGUMENT, "frame is null", "a null frame");
        HistencilFrame w = f;
        w.technique = 99;
        t.expect(histencil_lighting_record(lighting, cmd, &w, &c.targets),
                 HISTENCIL_RESULT_INVALID_ARGUMENT, "technique is 99", "an unknown technique");
        w = f;
        w.platform = 7;
        t.expect(histencil_lighting_record(lighting, cmd, &w, &c.targets),
                 HISTENCIL_RESULT_INVALID_ARGUMENT, "platform is 7", "an unknown platform");
        w = f;
        w.slot = desc.frames_in_flight;
        t.expect(histencil_lighting_record(lighting, cmd, &w, &c.targets), HISTENCIL_RESULT_BAD_FRAME,
                 "slot", "a slot past the frames in flight");
        w = f;
        w.lights = nullptr;
        t.expect(histencil_lighting_record(lighting, cmd, &w, &c.targets),
                 HISTENCIL_RESULT_INVALID_ARGUMENT, "lights", "null lights with a count");
        w = f;
        w.brdf_bounds_count = f.brdf_bounds_count + 1;
        t.expect(histencil_lighting_record(lighting, cmd, &w, &c.targets),
                 HISTENCIL_RESULT_INVALID_ARGUMENT, "brdf_bounds_count", "boxes for BRDFs it lacks");
        HistencilTargets wrong = c.targets;
        wrong.size = 1;
        t.expect(histencil_lighting_record(lighting, cmd, &f, &wrong),
                 HISTENCIL_RESULT_INVALID_ARGUMENT, "HistencilTargets.size is 1",
                 "a wrong targets size");
        // A slot recorded and not declared finished: recording it again, resizing and destroying
        // are refused, and the lighting stays whole.
        CTargets first(targets);
        const HistencilResult recorded = histencil_lighting_record(lighting, cmd, &f, &first.targets);
        t.expect(recorded, HISTENCIL_RESULT_SUCCESS, "", "a frame as it should be");
        CTargets again(targets);
        t.expect(histencil_lighting_record(lighting, cmd, &f, &again.targets),
                 HISTENCIL_RESULT_IN_FLIGHT, "", "a slot still in flight");
        t.expect(histencil_lighting_resize(lighting, 64, 64), HISTENCIL_RESULT_IN_FLIGHT, "",
                 "resize while in flight");
        t.expect(histencil_lighting_destroy(lighting), HISTENCIL_RESULT_IN_FLIGHT, "frames in flight",
                 "destroy while in flight");
        vkEndCommandBuffer(cmd);
        // Never submitted: finished at once, as the engine's word says.
        t.expect(histencil_lighting_slot_finished(lighting, 0), HISTENCIL_RESULT_SUCCESS, "",
                 "declared finished");
        t.expect(histencil_lighting_resize(lighting, 1u << 20, 1u << 20),
                 HISTENCIL_RESULT_DEVICE_LIMIT, "maxImageDimension2D", "resize past the device");
        t.expect(histencil_lighting_resize(lighting, 0, 64), HISTENCIL_RESULT_BAD_SETUP, "",
                 "resize to nothing");
    } else {
        std::fprintf(stderr, "misuse table: no command buffer\n");
        ++t.failed;
    }
    if (pool != VK_NULL_HANDLE) vkDestroyCommandPool(device, pool, nullptr);
    t.expect(histencil_lighting_destroy(lighting), HISTENCIL_RESULT_SUCCESS, "", "destroy");
    t.expect(histencil_lighting_destroy(lighting), HISTENCIL_RESULT_INVALID_ARGUMENT,
             "not a live Lighting handle", "destroy twice");
    failed += t.failed;
    return t.cases;
}
