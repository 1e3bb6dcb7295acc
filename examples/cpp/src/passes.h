// The engine's two passes over its world: the G-buffer pass that feeds histencil (its own
// shaders writing histencil's G-buffer contract, each BRDF's slot into the stencil) and the
// forward reference that shades the same world with every light through histencil's
// light.glsl. Both read set 0 as histencil lays it out (histencil_shading_inputs): the frame
// block (whose view and projection are the engine's camera) and the light buffer.
#pragma once

#include "gpu.h"
#include "world.h"

#include <array>
#include <vector>

// The images histencil lights: its G-buffer layout, the depth-stencil with each pixel's BRDF
// slot, and the HDR image the light is added to.
struct Targets {
    std::array<Image, HISTENCIL_GBUFFER_IMAGES> gbuffer;
    Image depth_stencil;
    Image hdr;
};

// The stencil a BRDF's surfaces are drawn with (histencil_lighting_stencil_reference).
struct StencilWrite {
    uint8_t reference;
    uint8_t write_mask;
};

class Passes {
public:
    // `slots` frames in flight, each with its own frame block and light buffer (the host
    // writes one slot's while the GPU reads the other's); `max_lights` lights a frame.
    Passes(Gpu &gpu, const World &world, const VkFormat (&gbuffer_formats)[HISTENCIL_GBUFFER_IMAGES],
           VkFormat depth_stencil_format, VkFormat hdr_format, uint32_t width, uint32_t height,
           uint32_t slots, uint32_t max_lights);
    ~Passes();
    Passes(const Passes &) = delete;
    Passes &operator=(const Passes &) = delete;

    // Writes slot `slot`'s frame block and lights. The GPU must be done with the slot.
    void upload(uint32_t slot, const HistencilView &view, const std::vector<HistencilLight> &lights);
    // The G-buffer pass into `targets`, each object's stencil from `stencil[its BRDF slot]`.
    void record_gbuffer(VkCommandBuffer cmd, uint32_t slot, Targets &targets,
                        const std::vector<StencilWrite> &stencil);
    // The forward reference into `forward_hdr`.
    void record_forward(VkCommandBuffer cmd, uint32_t slot);

    Image forward_hdr;

private:
    void draw_objects(VkCommandBuffer cmd, uint32_t slot, VkPipeline pipeline,
                      const std::vector<StencilWrite> *stencil);
    void destroy_all() noexcept;

    Gpu &gpu_;
    const World &world_;
    uint32_t width_, height_;
    uint32_t index_count_ = 0;
    Buffer vertices_, indices_;
    std::vector<Buffer> frame_blocks_, light_buffers_;
    Image forward_depth_;
    VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    VkDescriptorPool pool_ = VK_NULL_HANDLE;
    std::vector<VkDescriptorSet> sets_;
    VkPipeline gbuffer_pipeline_ = VK_NULL_HANDLE;
    VkPipeline forward_pipeline_ = VK_NULL_HANDLE;
};
