// The engine's Vulkan: its instance (validation and synchronisation validation on, every warning
// and error counted), its device (with the features histencil asks for), and the few helpers its
// passes share: images and buffers with their memory, barriers, pipelines, SPIR-V from disk.
#pragma once

#include <histencil.h>
#include <vulkan/vulkan.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

// A failed Vulkan call, as an exception: the engine's passes then unwind through the
// destructors that free what was made.
void vk_check(VkResult result, const char *what);

// How many validation messages of warning or error severity the debug messenger has seen.
uint32_t validation_messages();

// An image the engine owns. `state` is the image as histencil describes it (handle, view,
// format, extent, usage) with its tracked layout, stages and accesses: the engine's own barriers
// and histencil's recording both start from it and leave it where their commands do.
struct Image {
    HistencilImage state{};
    VkImageAspectFlags aspect = 0;
    VkDeviceMemory memory = VK_NULL_HANDLE;
};

// A host-visible, coherent buffer, mapped for its whole life.
struct Buffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize size = 0;
    void *mapped = nullptr;
};

// Where an image is left and what touched it last: a layout, stages and accesses.
struct ImageUse {
    VkImageLayout layout;
    VkPipelineStageFlags2 stage;
    VkAccessFlags2 access;
};

// The uses the engine's own commands put images to.
namespace use {
constexpr ImageUse color_attachment{VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                    VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                                    VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT |
                                        VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT};
constexpr ImageUse depth_attachment{VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
                                    VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                                        VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                                    VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                                        VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT};
constexpr ImageUse transfer_source{VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                   VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT};
}  // namespace use

// The engine's instance, device and queue. Made whole or not at all; destroyed in reverse.
class Gpu {
public:
    // `device_filter`: the first device whose name contains it (lowercase) is taken; empty
    // takes the first that fits.
    explicit Gpu(const std::string &device_filter);
    ~Gpu();
    Gpu(const Gpu &) = delete;
    Gpu &operator=(const Gpu &) = delete;

    VkInstance instance = VK_NULL_HANDLE;
    VkPhysicalDevice physical_device = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    uint32_t queue_family = 0;
    VkQueue queue = VK_NULL_HANDLE;
    std::string device_name;

    Image image(VkFormat format, uint32_t width, uint32_t height, VkImageUsageFlags usage);
    void destroy(Image &image);
    Buffer buffer(VkDeviceSize size, VkBufferUsageFlags usage);
    void destroy(Buffer &buffer);
    // A shader module from the engine's build folder (CPP_ENGINE_SHADER_DIR).
    VkShaderModule shader(const char *name);

private:
    VkDeviceMemory allocate(VkMemoryRequirements needs, VkMemoryPropertyFlags properties);
    void destroy_all() noexcept;

    VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
    VkPhysicalDeviceMemoryProperties memory_{};
};

// Moves `image` from its tracked state to `next` with one barrier, and tracks `next`.
void barrier(VkCommandBuffer cmd, Image &image, const ImageUse &next);

// What differs between the engine's two graphics pipelines.
struct PipelineSpec {
    VkShaderModule vertex;
    VkShaderModule fragment;
    VkPipelineLayout layout;
    std::vector<VkFormat> color_formats;
    VkFormat depth_format;
    VkFormat stencil_format;  // VK_FORMAT_UNDEFINED for none
    VkPipelineDepthStencilStateCreateInfo depth_stencil;
    std::vector<VkDynamicState> dynamic;  // besides viewport and scissor
};

// A dynamic-rendering graphics pipeline of the engine's mesh vertex layout (position, normal).
VkPipeline graphics_pipeline(VkDevice device, const PipelineSpec &spec);
