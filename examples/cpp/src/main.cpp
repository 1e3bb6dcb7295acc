// A C++ engine lighting its own G-buffer with histencil through the C API (histencil.h).
//
// The engine owns everything Vulkan: the instance (validation and synchronisation validation,
// every warning and error counted), the device, the images, the command buffers and fences. It
// lends the device to histencil (a HistencilContext), makes one lighting for its three BRDFs,
// and renders frames two in flight: its G-buffer pass, histencil's lighting recorded into the
// same command buffer, and its own forward reference of the same world. Frames cycle through
// the talk's stencil technique on the PS3-like platform (hi-stencil emulated) and natively, and
// histencil's tiled technique; each is read back and held against the forward reference, both
// converted to 8 bits per channel. The last line printed is the verdict; the exit status is 0
// only when every frame is within 1/255, the layer said nothing and every histencil call
// succeeded.
#include "gpu.h"
#include "misuse.h"
#include "passes.h"
#include "world.h"

#include <histencil.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

namespace {

constexpr uint32_t kWidth = 96;
constexpr uint32_t kHeight = 64;
constexpr uint32_t kSlots = 2;   // frames in flight
constexpr uint32_t kFrames = 9;  // three of each technique, each technique in both slots
constexpr VkFormat kDepthStencil = VK_FORMAT_D32_SFLOAT_S8_UINT;
constexpr VkFormat kHdr = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr uint8_t kTolerance = 1;  // in 8-bit steps, as histencil's Rust example engine holds

// The techniques frames cycle through, as the verdict names them.
struct Technique {
    const char *name;
    uint32_t technique;
    uint32_t platform;
};
constexpr Technique kTechniques[] = {
    {"stencil PS3-like", HISTENCIL_TECHNIQUE_STENCIL, HISTENCIL_PLATFORM_PS3},
    {"stencil native", HISTENCIL_TECHNIQUE_STENCIL, HISTENCIL_PLATFORM_NATIVE},
    {"tiled", HISTENCIL_TECHNIQUE_TILED, HISTENCIL_PLATFORM_NATIVE},
};
constexpr size_t kTechniqueCount = sizeof kTechniques / sizeof kTechniques[0];

// histencil calls that failed where no exception could carry them (destructors).
int g_histencil_failures = 0;

const char *result_name(HistencilResult r) {
    switch (r) {
    case HISTENCIL_RESULT_SUCCESS: return "SUCCESS";
    case HISTENCIL_RESULT_INVALID_ARGUMENT: return "INVALID_ARGUMENT";
    case HISTENCIL_RESULT_BAD_SETUP: return "BAD_SETUP";
    case HISTENCIL_RESULT_BAD_FRAME: return "BAD_FRAME";
    case HISTENCIL_RESULT_IN_FLIGHT: return "IN_FLIGHT";
    case HISTENCIL_RESULT_DEVICE_LIMIT: return "DEVICE_LIMIT";
    case HISTENCIL_RESULT_UNSUPPORTED: return "UNSUPPORTED";
    case HISTENCIL_RESULT_VULKAN: return "VULKAN";
    case HISTENCIL_RESULT_INTERNAL: return "INTERNAL";
    }
    return "an unknown result";
}

std::string describe(HistencilResult r, const char *call) {
    return std::string(call) + ": " + result_name(r) + ": " + histencil_last_error();
}

// A histencil call that must succeed: anything else unwinds with histencil's message.
void hcheck(HistencilResult r, const char *call) {
    if (r != HISTENCIL_RESULT_SUCCESS) throw std::runtime_error(describe(r, call));
}

// For a histencil call in a destructor: reports, counts, goes on.
void hreport(HistencilResult r, const char *call) {
    if (r != HISTENCIL_RESULT_SUCCESS) {
        std::fprintf(stderr, "cpp engine: %s\n", describe(r, call).c_str());
        ++g_histencil_failures;
    }
}

// Runs `f` when the scope ends: how the engine frees its plain Vulkan objects on every path.
template <class F>
class OnExit {
public:
    explicit OnExit(F f) : f_(std::move(f)) {}
    ~OnExit() { f_(); }
    OnExit(const OnExit &) = delete;
    OnExit &operator=(const OnExit &) = delete;

private:
    F f_;
};

// The lent device. Destroyed after every lighting made on it, before the device itself.
class Context {
public:
    explicit Context(const Gpu &gpu) {
        HistencilDeviceDesc desc{};
        desc.size = sizeof desc;
        desc.queue_family = gpu.queue_family;
        desc.get_instance_proc_addr = vkGetInstanceProcAddr;
        desc.instance = gpu.instance;
        desc.physical_device = gpu.physical_device;
        desc.device = gpu.device;
        desc.queue = gpu.queue;
        desc.depth_stencil_format = kDepthStencil;
        desc.debug_utils = 1;  // the instance has VK_EXT_debug_utils: histencil names its objects
        desc.memory_budget = 0;
        hcheck(histencil_context_create(&desc, &handle), "histencil_context_create");
    }
    ~Context() {
        if (handle) hreport(histencil_context_destroy(handle), "histencil_context_destroy");
    }
    Context(const Context &) = delete;
    Context &operator=(const Context &) = delete;
    HistencilContext *handle = nullptr;
};

// histencil's shaders for the engine's BRDF set, from the file this engine's build wrote with
// `histencil shaders` (CMakeLists.txt): no glslc needed here.
class Shaders {
public:
    Shaders(Context &context, const char *file) {
        hcheck(histencil_shaders_load(context.handle, file, &handle), "histencil_shaders_load");
    }
    ~Shaders() {
        if (handle) hreport(histencil_shaders_destroy(handle), "histencil_shaders_destroy");
    }
    Shaders(const Shaders &) = delete;
    Shaders &operator=(const Shaders &) = delete;
    HistencilShaders *handle = nullptr;
};

// The lighting. Its destructor waits for the device and declares every slot finished first,
// so that it frees on the error paths too (histencil refuses to free a lighting in flight).
class Lighting {
public:
    Lighting(VkDevice device, Context &context, const HistencilLightingDesc &desc)
        : device_(device), slots_(desc.frames_in_flight) {
        hcheck(histencil_lighting_create(context.handle, &desc, &handle), "histencil_lighting_create");
    }
    ~Lighting() {
        if (!handle) return;
        vkDeviceWaitIdle(device_);
        for (uint32_t s = 0; s < slots_; ++s) {
            hreport(histencil_lighting_slot_finished(handle, s), "histencil_lighting_slot_finished");
        }
        hreport(histencil_lighting_destroy(handle), "histencil_lighting_destroy");
    }
    Lighting(const Lighting &) = delete;
    Lighting &operator=(const Lighting &) = delete;
    HistencilLighting *handle = nullptr;

private:
    VkDevice device_;
    uint32_t slots_;
};

float half_to_float(uint16_t h) {
    const int exponent = (h >> 10) & 0x1f;
    const int mantissa = h & 0x3ff;
    float v;
    if (exponent == 0) {
        v = std::ldexp(static_cast<float>(mantissa), -24);
    } else if (exponent == 31) {
        v = mantissa ? NAN : INFINITY;
    } else {
        v = std::ldexp(static_cast<float>(mantissa | 0x400), exponent - 25);
    }
    return (h & 0x8000) ? -v : v;
}

// An HDR value to 8 bits: clamped to [0, 1], times 255, rounded.
int to_8bit(float x) {
    return static_cast<int>(std::lround(std::clamp(x, 0.0f, 1.0f) * 255.0f));
}

struct Comparison {
    int max_difference = 0;
    uint32_t lit_pixels = 0;  // pixels of the forward reference with a channel above 0 in 8 bits
};

// The lit frame against the forward reference, two R16G16B16A16_SFLOAT images as read back:
// the largest difference over the colour channels (alpha carries no light).
Comparison compare(const uint16_t *lit, const uint16_t *forward, uint32_t pixels) {
    Comparison c;
    for (uint32_t p = 0; p < pixels; ++p) {
        bool any = false;
        for (uint32_t ch = 0; ch < 3; ++ch) {
            const float a = half_to_float(lit[p * 4 + ch]);
            const float b = half_to_float(forward[p * 4 + ch]);
            // NaN is as far from anything as a channel can be, not clamped to a match.
            const int d = (std::isnan(a) || std::isnan(b)) ? 255 : std::abs(to_8bit(a) - to_8bit(b));
            c.max_difference = std::max(c.max_difference, d);
            any = any || to_8bit(b) > 0;
        }
        c.lit_pixels += any ? 1 : 0;
    }
    return c;
}

// `image` copied into `buffer` at `offset`, leaving it a transfer source.
void copy_to_buffer(VkCommandBuffer cmd, Image &image, VkBuffer buffer, VkDeviceSize offset) {
    barrier(cmd, image, use::transfer_source);
    VkBufferImageCopy region{};
    region.bufferOffset = offset;
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {image.state.width, image.state.height, 1};
    vkCmdCopyImageToBuffer(cmd, image.state.image, image.state.layout, buffer, 1, &region);
}

// histencil's lighting of the frame, recorded after the engine's G-buffer pass: histencil starts
// from the images' states as the engine left them and says where it leaves them, which the
// engine tracks on (its next barriers start there).
void record_lighting(HistencilLighting *lighting, VkCommandBuffer cmd, uint32_t slot,
                     const Technique &technique, const HistencilView &view,
                     const std::vector<HistencilLight> &lights,
                     const std::vector<HistencilBrdfBounds> &bounds, Targets &targets) {
    // Each image's HistencilImage is the engine's own record of it, which histencil reads and
    // updates in place; the G-buffer's three are gathered into one array for the call.
    std::array<HistencilImage, HISTENCIL_GBUFFER_IMAGES> gbuffer;
    for (uint32_t i = 0; i < HISTENCIL_GBUFFER_IMAGES; ++i) gbuffer[i] = targets.gbuffer[i].state;
    HistencilTargets lit{};
    lit.size = sizeof lit;
    lit.gbuffer_count = HISTENCIL_GBUFFER_IMAGES;
    lit.gbuffer = gbuffer.data();
    lit.depth_stencil = &targets.depth_stencil.state;
    lit.hdr = &targets.hdr.state;
    HistencilFrame f{};
    f.size = sizeof f;
    f.slot = slot;
    f.technique = technique.technique;
    f.platform = technique.platform;
    f.view = view;
    f.light_count = static_cast<uint32_t>(lights.size());
    f.lights = lights.data();
    f.brdf_bounds_count = static_cast<uint32_t>(bounds.size());
    f.brdf_bounds = bounds.data();
    f.clear_hdr = 1;
    hcheck(histencil_lighting_record(lighting, cmd, &f, &lit), "histencil_lighting_record");
    for (uint32_t i = 0; i < HISTENCIL_GBUFFER_IMAGES; ++i) targets.gbuffer[i].state = gbuffer[i];
}

struct Results {
    int misuse_failed = 0;  // misuse cases not refused as the header says
    uint32_t hazards = 0;  // histencil's hazard check's findings over the engine's frames
    uint32_t frames = 0;  // frames rendered and compared
    int worst[kTechniqueCount] = {};
    uint32_t compared[kTechniqueCount] = {};
    bool dark_frame = false;  // a forward reference with too little lit to compare
};

// One frame in flight: its command buffer, fence, readback buffer and what it holds.
struct Slot {
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    Buffer readback;  // the lit HDR image, then the forward reference's
    bool pending = false;
    uint32_t frame = 0;
    size_t technique = 0;
};

void run(Results &results) {
    const char *filter = std::getenv("HISTENCIL_DEVICE");
    Gpu gpu(filter ? filter : "");
    const uint32_t version = histencil_version();
    std::printf("cpp engine: %s, histencil %u.%u.%u (header %d.%d.%d)\n", gpu.device_name.c_str(),
                version >> 22, (version >> 12) & 0x3ff, version & 0xfff, HISTENCIL_VERSION_MAJOR,
                HISTENCIL_VERSION_MINOR, HISTENCIL_VERSION_PATCH);
    if ((version >> 22) != HISTENCIL_VERSION_MAJOR || ((version >> 12) & 0x3ff) != HISTENCIL_VERSION_MINOR) {
        throw std::runtime_error("the histencil library is not the version of the header");
    }
    // histencil: the context on the engine's device, and its shaders for the engine's BRDFs.
    Context context(gpu);
    // histencil's hazard check, as an engine's debug build turns it on: every buffer histencil's
    // commands use, held to Vulkan's synchronisation rule across this engine's frames in flight
    // (told of each begin, submit and wait below). Before the lighting is made.
    hcheck(histencil_context_check_hazards(context.handle), "histencil_context_check_hazards");
    const Shaders shaders(context, CPP_ENGINE_HISTENCIL_SHADERS);
    const World world(kWidth, kHeight, shaders.handle);

    // The targets histencil lights, in its G-buffer formats.
    VkFormat gbuffer_formats[HISTENCIL_GBUFFER_IMAGES];
    hcheck(histencil_gbuffer_formats(gbuffer_formats), "histencil_gbuffer_formats");
    Targets targets;
    OnExit free_targets([&] {
        for (Image &g : targets.gbuffer) gpu.destroy(g);
        gpu.destroy(targets.depth_stencil);
        gpu.destroy(targets.hdr);
    });
    for (uint32_t i = 0; i < HISTENCIL_GBUFFER_IMAGES; ++i) {
        targets.gbuffer[i] = gpu.image(gbuffer_formats[i], kWidth, kHeight,
                                       VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT);
    }
    targets.depth_stencil = gpu.image(kDepthStencil, kWidth, kHeight,
                                      VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT |
                                          VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    // STORAGE for the tiled technique, which writes the HDR image from compute.
    targets.hdr = gpu.image(kHdr, kWidth, kHeight,
                            VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT |
                                VK_IMAGE_USAGE_TRANSFER_SRC_BIT);

    Passes passes(gpu, world, gbuffer_formats, kDepthStencil, kHdr, kWidth, kHeight, kSlots, kLights);

    // The frames in flight.
    VkCommandPool pool = VK_NULL_HANDLE;
    std::array<Slot, kSlots> slots;
    OnExit free_slots([&] {
        // The lighting's destructor (which runs first) waited for the device.
        for (Slot &s : slots) {
            if (s.fence) vkDestroyFence(gpu.device, s.fence, nullptr);
            gpu.destroy(s.readback);
        }
        if (pool) vkDestroyCommandPool(gpu.device, pool, nullptr);
    });
    VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool_info.queueFamilyIndex = gpu.queue_family;
    vk_check(vkCreateCommandPool(gpu.device, &pool_info, nullptr, &pool), "vkCreateCommandPool");
    const VkDeviceSize image_bytes = VkDeviceSize(kWidth) * kHeight * 8;
    for (Slot &s : slots) {
        VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
        alloc.commandPool = pool;
        alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
        alloc.commandBufferCount = 1;
        vk_check(vkAllocateCommandBuffers(gpu.device, &alloc, &s.cmd), "vkAllocateCommandBuffers");
        VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
        vk_check(vkCreateFence(gpu.device, &fence_info, nullptr, &s.fence), "vkCreateFence");
        s.readback = gpu.buffer(2 * image_bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    }

    // One lighting for the world's BRDFs (made with hi-stencil, which the PS3-like platform
    // needs; the native and tiled frames ignore it).
    HistencilLightingDesc desc{};
    desc.size = sizeof desc;
    desc.brdf_count = static_cast<uint32_t>(world.brdf_names.size());
    desc.brdf_names = world.brdf_names.data();
    desc.shaders = shaders.handle;  // the engine's BRDF set; histencil's G-buffer, no shadows
    desc.hooks = nullptr;
    desc.engine_stencil_bits = 0;
    desc.width = kWidth;
    desc.height = kHeight;
    desc.depth_stencil_format = kDepthStencil;
    desc.hdr_format = kHdr;
    desc.frames_in_flight = kSlots;
    desc.max_lights = kLights;
    desc.hi_stencil = 1;
    Lighting lighting(gpu.device, context, desc);
    std::vector<StencilWrite> stencil(world.brdf_names.size());
    for (size_t b = 0; b < stencil.size(); ++b) {
        hcheck(histencil_lighting_stencil_reference(lighting.handle, world.brdf_names[b],
                                                    &stencil[b].reference, &stencil[b].write_mask),
               "histencil_lighting_stencil_reference");
    }
    // Each BRDF's boxes: the objects never move, so one list serves every frame.
    const auto boxes = world.brdf_boxes();
    std::vector<HistencilBrdfBounds> bounds;
    for (const auto &list : boxes) {
        bounds.push_back({list.data(), static_cast<uint32_t>(list.size())});
    }

    // What the engine can get wrong, on its own device: each misuse refused with its result and
    // message, on a lighting of the table's own whose command buffer is never submitted.
    const std::vector<HistencilLight> first_lights = world.lights(0);
    int misuse_failed = 0;
    const int misuse_cases =
        run_misuse_table(context.handle, gpu.device, gpu.queue_family, desc, targets,
                         MisuseFrame{world.view, &first_lights, &bounds}, misuse_failed);
    std::printf("misuse: %d cases, %d not answered as the header says\n", misuse_cases,
                misuse_failed);
    results.misuse_failed = misuse_failed;

    // Waits for a slot's frame, tells histencil, and holds the frame to its reference.
    auto finish = [&](Slot &s, uint32_t index) {
        if (!s.pending) return;
        vk_check(vkWaitForFences(gpu.device, 1, &s.fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
        hcheck(histencil_note_wait(context.handle, s.fence), "histencil_note_wait");
        s.pending = false;
        hcheck(histencil_lighting_slot_finished(lighting.handle, index), "histencil_lighting_slot_finished");
        const auto *bytes = static_cast<const uint16_t *>(s.readback.mapped);
        const Comparison c = compare(bytes, bytes + image_bytes / 2, kWidth * kHeight);
        std::printf("frame %u (slot %u, %s): max %d/255 vs forward, %u of %u pixels lit\n", s.frame,
                    index, kTechniques[s.technique].name, c.max_difference, c.lit_pixels,
                    kWidth * kHeight);
        results.worst[s.technique] = std::max(results.worst[s.technique], c.max_difference);
        results.compared[s.technique] += 1;
        results.frames += 1;
        // A frame mostly black would match any lighting: the world must be well lit.
        results.dark_frame = results.dark_frame || c.lit_pixels < kWidth * kHeight / 4;
    };

    for (uint32_t frame = 0; frame < kFrames; ++frame) {
        const uint32_t index = frame % kSlots;
        Slot &s = slots[index];
        finish(s, index);
        const size_t technique = frame % kTechniqueCount;
        const std::vector<HistencilLight> lights = world.lights(frame);
        passes.upload(index, world.view, lights);

        vk_check(vkResetCommandBuffer(s.cmd, 0), "vkResetCommandBuffer");
        VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        vk_check(vkBeginCommandBuffer(s.cmd, &begin), "vkBeginCommandBuffer");
        hcheck(histencil_note_begin(context.handle, s.cmd), "histencil_note_begin");
        passes.record_gbuffer(s.cmd, index, targets, stencil);

        record_lighting(lighting.handle, s.cmd, index, kTechniques[technique], world.view, lights,
                        bounds, targets);
        copy_to_buffer(s.cmd, targets.hdr, s.readback.buffer, 0);
        passes.record_forward(s.cmd, index);
        copy_to_buffer(s.cmd, passes.forward_hdr, s.readback.buffer, image_bytes);
        VkMemoryBarrier2 to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
        to_host.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
        to_host.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
        to_host.dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT;
        to_host.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT;
        VkDependencyInfo dependency{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
        dependency.memoryBarrierCount = 1;
        dependency.pMemoryBarriers = &to_host;
        vkCmdPipelineBarrier2(s.cmd, &dependency);
        vk_check(vkEndCommandBuffer(s.cmd), "vkEndCommandBuffer");

        vk_check(vkResetFences(gpu.device, 1, &s.fence), "vkResetFences");
        VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
        submit.commandBufferCount = 1;
        submit.pCommandBuffers = &s.cmd;
        vk_check(vkQueueSubmit(gpu.queue, 1, &submit, s.fence), "vkQueueSubmit");
        hcheck(histencil_note_submit(context.handle, &s.cmd, 1, s.fence), "histencil_note_submit");
        s.pending = true;
        s.frame = frame;
        s.technique = technique;
    }
    for (uint32_t i = 0; i < kSlots; ++i) finish(slots[(kFrames + i) % kSlots], (kFrames + i) % kSlots);
    // What the hazard check found, each finding a line naming the buffer and both passes.
    size_t needed = 0;
    hcheck(histencil_context_hazards(context.handle, &results.hazards, nullptr, 0, &needed),
           "histencil_context_hazards");
    if (results.hazards > 0) {
        std::string text(needed, '\0');
        hcheck(histencil_context_hazards(context.handle, &results.hazards, text.data(), needed,
                                         nullptr),
               "histencil_context_hazards");
        std::fprintf(stderr, "%s\n", text.c_str());
    }
    // Leaving the scope frees, in order: the lighting, the engine's own objects, histencil's shaders
    // and context, then the device and the instance.
}

}  // namespace

int main() {
    // Line-buffered even into a pipe: the layer's messages and errors (stderr) then interleave
    // with the frames' lines, and the verdict stays the last line of a combined log.
    std::setvbuf(stdout, nullptr, _IOLBF, 0);
    Results results;
    bool failed = false;
    try {
        run(results);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "cpp engine failed: %s\n", e.what());
        failed = true;
    }
    // Counted after the device and instance are gone: the layer reports leaks as they go.
    const uint32_t messages = validation_messages();
    int worst = 0;
    for (int w : results.worst) worst = std::max(worst, w);
    bool every_technique = true;
    for (uint32_t n : results.compared) every_technique = every_technique && n > 0;
    if (results.dark_frame) std::fprintf(stderr, "cpp engine: a forward reference was mostly dark\n");
    std::printf("cpp engine: lighting max %d/255 vs forward over %u frames (stencil PS3-like: %d/255; "
                "stencil native: %d/255; tiled: %d/255), %u validation messages, %u hazards\n",
                worst, results.frames, results.worst[0], results.worst[1], results.worst[2], messages,
                results.hazards);
    const bool pass = !failed && g_histencil_failures == 0 && results.misuse_failed == 0 &&
                      every_technique && !results.dark_frame && worst <= kTolerance && messages == 0 &&
                      results.hazards == 0;
    return pass ? EXIT_SUCCESS : EXIT_FAILURE;
}
