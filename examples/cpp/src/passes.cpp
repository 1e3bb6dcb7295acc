#include "passes.h"

#include <cstring>
#include <string>

namespace {

constexpr VkFormat kForwardDepth = VK_FORMAT_D32_SFLOAT;
constexpr VkShaderStageFlags kBothStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;

VkRenderingAttachmentInfo cleared(const Image &image, VkClearValue value) {
    VkRenderingAttachmentInfo a{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    a.imageView = image.state.view;
    a.imageLayout = image.state.layout;
    a.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    a.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    a.clearValue = value;
    return a;
}

VkClearValue color(float r, float g, float b, float a) {
    VkClearValue v{};
    v.color.float32[0] = r;
    v.color.float32[1] = g;
    v.color.float32[2] = b;
    v.color.float32[3] = a;
    return v;
}

VkClearValue depth_stencil(float depth, uint32_t stencil) {
    VkClearValue v{};
    v.depthStencil = {depth, stencil};
    return v;
}

// Standard depth: nearer is smaller, cleared to 1 (the far plane).
VkPipelineDepthStencilStateCreateInfo depth_test() {
    VkPipelineDepthStencilStateCreateInfo d{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    d.depthTestEnable = VK_TRUE;
    d.depthWriteEnable = VK_TRUE;
    d.depthCompareOp = VK_COMPARE_OP_LESS;
    return d;
}

void begin_rendering(VkCommandBuffer cmd, uint32_t width, uint32_t height,
                     const std::vector<VkRenderingAttachmentInfo> &colors,
                     const VkRenderingAttachmentInfo &depth, bool with_stencil) {
    VkRenderingInfo info{VK_STRUCTURE_TYPE_RENDERING_INFO};
    info.renderArea = {{0, 0}, {width, height}};
    info.layerCount = 1;
    info.colorAttachmentCount = static_cast<uint32_t>(colors.size());
    info.pColorAttachments = colors.data();
    info.pDepthAttachment = &depth;
    info.pStencilAttachment = with_stencil ? &depth : nullptr;
    vkCmdBeginRendering(cmd, &info);
    VkViewport viewport{0, 0, float(width), float(height), 0, 1};
    VkRect2D scissor{{0, 0}, {width, height}};
    vkCmdSetViewport(cmd, 0, 1, &viewport);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
}

}  // namespace

Passes::Passes(Gpu &gpu, const World &world,
               const VkFormat (&gbuffer_formats)[HISTENCIL_GBUFFER_IMAGES],
               VkFormat depth_stencil_format, VkFormat hdr_format, uint32_t width,
               uint32_t height, uint32_t slots, uint32_t max_lights)
    : gpu_(gpu), world_(world), width_(width), height_(height) {
    VkDevice d = gpu.device;
    VkShaderModule modules[3] = {};
    try {
        // The world's one mesh, in host-visible memory: a few hundred bytes, read in place.
        const Mesh mesh = unit_box();
        index_count_ = static_cast<uint32_t>(mesh.indices.size());
        vertices_ = gpu.buffer(mesh.vertices.size() * sizeof(float), VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
        std::memcpy(vertices_.mapped, mesh.vertices.data(), mesh.vertices.size() * sizeof(float));
        indices_ = gpu.buffer(mesh.indices.size() * sizeof(uint16_t), VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
        std::memcpy(indices_.mapped, mesh.indices.data(), mesh.indices.size() * sizeof(uint16_t));

        // Set 0, histencil's frame.glsl layout: binding 0 the frame block (the vertex stage
        // reads its camera from it), binding 1 the lights.
        VkDescriptorSetLayoutBinding bindings[2] = {
            {0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, kBothStages, nullptr},
            {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr},
        };
        VkDescriptorSetLayoutCreateInfo set_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
        set_info.bindingCount = 2;
        set_info.pBindings = bindings;
        vk_check(vkCreateDescriptorSetLayout(d, &set_info, nullptr, &set_layout_),
                 "vkCreateDescriptorSetLayout");
        VkPushConstantRange push{kBothStages, 0, sizeof(DrawPush)};
        VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
        layout_info.setLayoutCount = 1;
        layout_info.pSetLayouts = &set_layout_;
        layout_info.pushConstantRangeCount = 1;
        layout_info.pPushConstantRanges = &push;
        vk_check(vkCreatePipelineLayout(d, &layout_info, nullptr, &layout_), "vkCreatePipelineLayout");

        // One set per slot, over that slot's frame block and light buffer.
        VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, slots},
                                         {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, slots}};
        VkDescriptorPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
        pool_info.maxSets = slots;
        pool_info.poolSizeCount = 2;
        pool_info.pPoolSizes = sizes;
        vk_check(vkCreateDescriptorPool(d, &pool_info, nullptr, &pool_), "vkCreateDescriptorPool");
        std::vector<VkDescriptorSetLayout> layouts(slots, set_layout_);
        VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
        alloc.descriptorPool = pool_;
        alloc.descriptorSetCount = slots;
        alloc.pSetLayouts = layouts.data();
        sets_.resize(slots);
        vk_check(vkAllocateDescriptorSets(d, &alloc, sets_.data()), "vkAllocateDescriptorSets");
        for (uint32_t s = 0; s < slots; ++s) {
            frame_blocks_.push_back(gpu.buffer(HISTENCIL_FRAME_UNIFORMS_BYTES,
                                               VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT));
            light_buffers_.push_back(gpu.buffer(VkDeviceSize(max_lights) * HISTENCIL_GPU_LIGHT_BYTES,
                                                VK_BUFFER_USAGE_STORAGE_BUFFER_BIT));
            VkDescriptorBufferInfo ubo{frame_blocks_[s].buffer, 0, VK_WHOLE_SIZE};
            VkDescriptorBufferInfo ssbo{light_buffers_[s].buffer, 0, VK_WHOLE_SIZE};
            VkWriteDescriptorSet writes[2]{};
            for (int b = 0; b < 2; ++b) {
                writes[b].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
                writes[b].dstSet = sets_[s];
                writes[b].dstBinding = static_cast<uint32_t>(b);
                writes[b].descriptorCount = 1;
                writes[b].descriptorType = bindings[b].descriptorType;
            }
            writes[0].pBufferInfo = &ubo;
            writes[1].pBufferInfo = &ssbo;
            vkUpdateDescriptorSets(d, 2, writes, 0, nullptr);
        }

        modules[0] = gpu.shader("scene.vert");
        modules[1] = gpu.shader("gbuffer.frag");
        modules[2] = gpu.shader("forward.frag");

        // The G-buffer pipeline: histencil's three colour targets, and the stencil replaced
        // wherever a surface wins the depth test, with each draw's BRDF reference and mask
        // (dynamic: they come from histencil per BRDF).
        PipelineSpec gbuffer{};
        gbuffer.vertex = modules[0];
        gbuffer.fragment = modules[1];
        gbuffer.layout = layout_;
        gbuffer.color_formats.assign(gbuffer_formats, gbuffer_formats + HISTENCIL_GBUFFER_IMAGES);
        gbuffer.depth_format = depth_stencil_format;
        gbuffer.stencil_format = depth_stencil_format;
        gbuffer.depth_stencil = depth_test();
        gbuffer.depth_stencil.stencilTestEnable = VK_TRUE;
        VkStencilOpState replace{};
        replace.failOp = VK_STENCIL_OP_KEEP;
        replace.passOp = VK_STENCIL_OP_REPLACE;
        replace.depthFailOp = VK_STENCIL_OP_KEEP;
        replace.compareOp = VK_COMPARE_OP_ALWAYS;
        replace.compareMask = 0xff;
        gbuffer.depth_stencil.front = gbuffer.depth_stencil.back = replace;
        gbuffer.dynamic = {VK_DYNAMIC_STATE_STENCIL_REFERENCE, VK_DYNAMIC_STATE_STENCIL_WRITE_MASK};
        gbuffer_pipeline_ = graphics_pipeline(d, gbuffer);

        // The forward reference: one HDR target, its own depth buffer, no stencil.
        PipelineSpec forward{};
        forward.vertex = modules[0];
        forward.fragment = modules[2];
        forward.layout = layout_;
        forward.color_formats = {hdr_format};
        forward.depth_format = kForwardDepth;
        forward.stencil_format = VK_FORMAT_UNDEFINED;
        forward.depth_stencil = depth_test();
        forward_pipeline_ = graphics_pipeline(d, forward);

        forward_hdr = gpu.image(hdr_format, width, height,
                                VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
        forward_depth_ = gpu.image(kForwardDepth, width, height,
                                   VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT);
    } catch (...) {
        for (VkShaderModule m : modules) {
            if (m) vkDestroyShaderModule(d, m, nullptr);
        }
        destroy_all();
        throw;
    }
    // The pipelines hold what they need of the modules.
    for (VkShaderModule m : modules) vkDestroyShaderModule(d, m, nullptr);
}

Passes::~Passes() { destroy_all(); }

void Passes::destroy_all() noexcept {
    VkDevice d = gpu_.device;
    gpu_.destroy(forward_depth_);
    gpu_.destroy(forward_hdr);
    if (forward_pipeline_) vkDestroyPipeline(d, forward_pipeline_, nullptr);
    if (gbuffer_pipeline_) vkDestroyPipeline(d, gbuffer_pipeline_, nullptr);
    if (pool_) vkDestroyDescriptorPool(d, pool_, nullptr);  // frees the sets
    if (layout_) vkDestroyPipelineLayout(d, layout_, nullptr);
    if (set_layout_) vkDestroyDescriptorSetLayout(d, set_layout_, nullptr);
    for (Buffer &b : frame_blocks_) gpu_.destroy(b);
    for (Buffer &b : light_buffers_) gpu_.destroy(b);
    gpu_.destroy(indices_);
    gpu_.destroy(vertices_);
    forward_pipeline_ = gbuffer_pipeline_ = VK_NULL_HANDLE;
    pool_ = VK_NULL_HANDLE;
    layout_ = VK_NULL_HANDLE;
    set_layout_ = VK_NULL_HANDLE;
    frame_blocks_.clear();
    light_buffers_.clear();
}

void Passes::upload(uint32_t slot, const HistencilView &view,
                    const std::vector<HistencilLight> &lights) {
    // histencil writes both in its own layout: the engine needs no mirror of frame.glsl.
    const HistencilResult r = histencil_shading_inputs(
        &view, width_, height_, lights.data(), static_cast<uint32_t>(lights.size()),
        static_cast<uint8_t *>(frame_blocks_[slot].mapped),
        static_cast<uint8_t *>(light_buffers_[slot].mapped));
    if (r != HISTENCIL_RESULT_SUCCESS) {
        throw std::runtime_error(std::string("histencil_shading_inputs: ") + histencil_last_error());
    }
}

void Passes::draw_objects(VkCommandBuffer cmd, uint32_t slot, VkPipeline pipeline,
                          const std::vector<StencilWrite> *stencil) {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, layout_, 0, 1, &sets_[slot], 0,
                            nullptr);
    VkDeviceSize offset = 0;
    vkCmdBindVertexBuffers(cmd, 0, 1, &vertices_.buffer, &offset);
    vkCmdBindIndexBuffer(cmd, indices_.buffer, 0, VK_INDEX_TYPE_UINT16);
    for (const Object &object : world_.objects) {
        const DrawPush push = world_.push(object);
        vkCmdPushConstants(cmd, layout_, kBothStages, 0, sizeof push, &push);
        if (stencil) {
            const StencilWrite &s = (*stencil)[world_.materials[object.material].brdf_slot];
            vkCmdSetStencilReference(cmd, VK_STENCIL_FACE_FRONT_AND_BACK, s.reference);
            vkCmdSetStencilWriteMask(cmd, VK_STENCIL_FACE_FRONT_AND_BACK, s.write_mask);
        }
        vkCmdDrawIndexed(cmd, index_count_, 1, 0, 0, 0);
    }
}

void Passes::record_gbuffer(VkCommandBuffer cmd, uint32_t slot, Targets &targets,
                            const std::vector<StencilWrite> &stencil) {
    for (Image &g : targets.gbuffer) barrier(cmd, g, use::color_attachment);
    barrier(cmd, targets.depth_stencil, use::depth_attachment);
    // gbuffer_write.glsl's clear values: 0, 0 (depth 0: nothing drawn) and (0, 0, 0, -1); the
    // stencil's BRDF bits to 0, as histencil asks before the G-buffer pass.
    std::vector<VkRenderingAttachmentInfo> colors = {
        cleared(targets.gbuffer[0], color(0, 0, 0, 0)),
        cleared(targets.gbuffer[1], color(0, 0, 0, 0)),
        cleared(targets.gbuffer[2], color(0, 0, 0, -1)),
    };
    const VkRenderingAttachmentInfo ds = cleared(targets.depth_stencil, depth_stencil(1.0f, 0));
    begin_rendering(cmd, width_, height_, colors, ds, true);
    draw_objects(cmd, slot, gbuffer_pipeline_, &stencil);
    vkCmdEndRendering(cmd);
}

void Passes::record_forward(VkCommandBuffer cmd, uint32_t slot) {
    barrier(cmd, forward_hdr, use::color_attachment);
    barrier(cmd, forward_depth_, use::depth_attachment);
    const std::vector<VkRenderingAttachmentInfo> colors = {cleared(forward_hdr, color(0, 0, 0, 0))};
    const VkRenderingAttachmentInfo ds = cleared(forward_depth_, depth_stencil(1.0f, 0));
    begin_rendering(cmd, width_, height_, colors, ds, false);
    draw_objects(cmd, slot, forward_pipeline_, nullptr);
    vkCmdEndRendering(cmd);
}
