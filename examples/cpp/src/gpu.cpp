#include "gpu.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

namespace {

std::atomic<uint32_t> g_messages{0};

// Counts every warning and error the layer reports (validation and synchronisation validation
// alike) and prints it: an engine that leaks, races or misuses Vulkan hears it here, and
// histencil's own commands are held to the same standard since they run on this instance.
VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                          VkDebugUtilsMessageTypeFlagsEXT,
                                          const VkDebugUtilsMessengerCallbackDataEXT *data, void *) {
    if (severity & (VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT)) {
        g_messages.fetch_add(1);
        std::fprintf(stderr, "validation: %s\n", data && data->pMessage ? data->pMessage : "?");
    }
    return VK_FALSE;
}

std::string lowercase(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return s;
}

VkImageAspectFlags aspect_of(VkFormat format) {
    switch (format) {
    case VK_FORMAT_D32_SFLOAT_S8_UINT:
    case VK_FORMAT_D24_UNORM_S8_UINT:
        return VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT;
    case VK_FORMAT_D32_SFLOAT:
        return VK_IMAGE_ASPECT_DEPTH_BIT;
    default:
        return VK_IMAGE_ASPECT_COLOR_BIT;
    }
}

}  // namespace

void vk_check(VkResult result, const char *what) {
    if (result != VK_SUCCESS) {
        throw std::runtime_error(std::string(what) + " failed: VkResult " + std::to_string(result));
    }
}

uint32_t validation_messages() { return g_messages.load(); }

Gpu::Gpu(const std::string &device_filter) {
    try {
        // The instance: Vulkan 1.3 as histencil asks, validation with synchronisation
        // validation, and debug utils for the messenger (and for histencil's object names).
        VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
        app.pApplicationName = "histencil cpp engine";
        app.apiVersion = HISTENCIL_API_VERSION;
        const char *layers[] = {"VK_LAYER_KHRONOS_validation"};
        const char *extensions[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME,
                                    VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME};
        VkValidationFeatureEnableEXT sync = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
        VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
        features.enabledValidationFeatureCount = 1;
        features.pEnabledValidationFeatures = &sync;
        // Chained into the instance too, so that what instance creation itself says is counted.
        VkDebugUtilsMessengerCreateInfoEXT messenger_info{
            VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
        messenger_info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                                         VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
        messenger_info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                                     VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
        messenger_info.pfnUserCallback = on_message;
        features.pNext = &messenger_info;
        VkInstanceCreateInfo instance_info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
        instance_info.pNext = &features;
        instance_info.pApplicationInfo = &app;
        instance_info.enabledLayerCount = 1;
        instance_info.ppEnabledLayerNames = layers;
        instance_info.enabledExtensionCount = 2;
        instance_info.ppEnabledExtensionNames = extensions;
        vk_check(vkCreateInstance(&instance_info, nullptr, &instance),
                 "vkCreateInstance (with VK_LAYER_KHRONOS_validation)");
        auto create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
        if (!create_messenger) throw std::runtime_error("no vkCreateDebugUtilsMessengerEXT");
        vk_check(create_messenger(instance, &messenger_info, nullptr, &messenger_),
                 "vkCreateDebugUtilsMessengerEXT");

        // The device: the first named like the filter, of Vulkan 1.3, with a queue family
        // that does graphics and compute (histencil records both into the engine's buffers).
        uint32_t count = 0;
        vk_check(vkEnumeratePhysicalDevices(instance, &count, nullptr), "vkEnumeratePhysicalDevices");
        std::vector<VkPhysicalDevice> devices(count);
        vk_check(vkEnumeratePhysicalDevices(instance, &count, devices.data()),
                 "vkEnumeratePhysicalDevices");
        const std::string filter = lowercase(device_filter);
        for (VkPhysicalDevice candidate : devices) {
            VkPhysicalDeviceProperties props;
            vkGetPhysicalDeviceProperties(candidate, &props);
            if (props.apiVersion < HISTENCIL_API_VERSION ||
                lowercase(props.deviceName).find(filter) == std::string::npos) {
                continue;
            }
            uint32_t families = 0;
            vkGetPhysicalDeviceQueueFamilyProperties(candidate, &families, nullptr);
            std::vector<VkQueueFamilyProperties> family_props(families);
            vkGetPhysicalDeviceQueueFamilyProperties(candidate, &families, family_props.data());
            const VkQueueFlags needed = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
            for (uint32_t f = 0; f < families; ++f) {
                if ((family_props[f].queueFlags & needed) == needed) {
                    physical_device = candidate;
                    queue_family = f;
                    device_name = props.deviceName;
                    break;
                }
            }
            if (physical_device) break;
        }
        if (!physical_device) {
            throw std::runtime_error("no Vulkan 1.3 device with a graphics and compute queue named "
                                     "like HISTENCIL_DEVICE=\"" + device_filter + "\"");
        }
        vkGetPhysicalDeviceMemoryProperties(physical_device, &memory_);

        // The engine's own features (none beyond core) plus histencil's, chained as 1.3 wants.
        VkPhysicalDeviceVulkan13Features features13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
        VkPhysicalDeviceFeatures2 features2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
        features2.pNext = &features13;
        if (histencil_device_features(&features2.features, &features13) != HISTENCIL_RESULT_SUCCESS) {
            throw std::runtime_error(std::string("histencil_device_features: ") +
                                     histencil_last_error());
        }
        const float priority = 1.0f;
        VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
        queue_info.queueFamilyIndex = queue_family;
        queue_info.queueCount = 1;
        queue_info.pQueuePriorities = &priority;
        VkDeviceCreateInfo device_info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
        device_info.pNext = &features2;
        device_info.queueCreateInfoCount = 1;
        device_info.pQueueCreateInfos = &queue_info;
        vk_check(vkCreateDevice(physical_device, &device_info, nullptr, &device), "vkCreateDevice");
        vkGetDeviceQueue(device, queue_family, 0, &queue);
    } catch (...) {
        destroy_all();
        throw;
    }
}

Gpu::~Gpu() { destroy_all(); }

void Gpu::destroy_all() noexcept {
    if (device) {
        vkDestroyDevice(device, nullptr);
        device = VK_NULL_HANDLE;
    }
    // The layer reports leaked device objects as the device goes: the messenger outlives it.
    if (messenger_) {
        auto destroy_messenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
        if (destroy_messenger) destroy_messenger(instance, messenger_, nullptr);
        messenger_ = VK_NULL_HANDLE;
    }
    if (instance) {
        vkDestroyInstance(instance, nullptr);
        instance = VK_NULL_HANDLE;
    }
}

VkDeviceMemory Gpu::allocate(VkMemoryRequirements needs, VkMemoryPropertyFlags properties) {
    // One allocation per resource: the engine has a dozen, far below any allocation limit.
    for (uint32_t i = 0; i < memory_.memoryTypeCount; ++i) {
        if ((needs.memoryTypeBits & (1u << i)) &&
            (memory_.memoryTypes[i].propertyFlags & properties) == properties) {
            VkMemoryAllocateInfo info{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
            info.allocationSize = needs.size;
            info.memoryTypeIndex = i;
            VkDeviceMemory memory = VK_NULL_HANDLE;
            vk_check(vkAllocateMemory(device, &info, nullptr, &memory), "vkAllocateMemory");
            return memory;
        }
    }
    throw std::runtime_error("no memory type with the properties asked");
}

Image Gpu::image(VkFormat format, uint32_t width, uint32_t height, VkImageUsageFlags usage) {
    Image out;
    out.aspect = aspect_of(format);
    HistencilImage &s = out.state;
    s.format = format;
    s.width = width;
    s.height = height;
    s.usage = usage;
    // Nothing has touched it: undefined contents, no earlier stage or access to wait for.
    s.layout = VK_IMAGE_LAYOUT_UNDEFINED;
    s.stage = VK_PIPELINE_STAGE_2_NONE;
    s.access = VK_ACCESS_2_NONE;
    VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {width, height, 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    try {
        vk_check(vkCreateImage(device, &info, nullptr, &s.image), "vkCreateImage");
        VkMemoryRequirements needs;
        vkGetImageMemoryRequirements(device, s.image, &needs);
        out.memory = allocate(needs, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        vk_check(vkBindImageMemory(device, s.image, out.memory, 0), "vkBindImageMemory");
        VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
        view.image = s.image;
        view.viewType = VK_IMAGE_VIEW_TYPE_2D;
        view.format = format;
        // Every aspect: histencil takes one view of the whole depth-stencil image.
        view.subresourceRange = {out.aspect, 0, 1, 0, 1};
        vk_check(vkCreateImageView(device, &view, nullptr, &s.view), "vkCreateImageView");
    } catch (...) {
        destroy(out);
        throw;
    }
    return out;
}

void Gpu::destroy(Image &image) {
    if (image.state.view) vkDestroyImageView(device, image.state.view, nullptr);
    if (image.state.image) vkDestroyImage(device, image.state.image, nullptr);
    if (image.memory) vkFreeMemory(device, image.memory, nullptr);
    image = Image{};
}

Buffer Gpu::buffer(VkDeviceSize size, VkBufferUsageFlags usage) {
    Buffer out;
    out.size = size;
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = size;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    try {
        vk_check(vkCreateBuffer(device, &info, nullptr, &out.buffer), "vkCreateBuffer");
        VkMemoryRequirements needs;
        vkGetBufferMemoryRequirements(device, out.buffer, &needs);
        // Coherent: host writes before a submit and host reads after a fence need no flushes.
        out.memory = allocate(needs, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                         VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
        vk_check(vkBindBufferMemory(device, out.buffer, out.memory, 0), "vkBindBufferMemory");
        vk_check(vkMapMemory(device, out.memory, 0, VK_WHOLE_SIZE, 0, &out.mapped), "vkMapMemory");
    } catch (...) {
        destroy(out);
        throw;
    }
    return out;
}

void Gpu::destroy(Buffer &buffer) {
    if (buffer.buffer) vkDestroyBuffer(device, buffer.buffer, nullptr);
    if (buffer.memory) vkFreeMemory(device, buffer.memory, nullptr);  // unmaps too
    buffer = Buffer{};
}

VkShaderModule Gpu::shader(const char *name) {
    const std::string path = std::string(CPP_ENGINE_SHADER_DIR) + "/" + name + ".spv";
    std::ifstream file(path, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    if (!file.good() && !file.eof()) throw std::runtime_error("cannot read " + path);
    if (bytes.empty() || bytes.size() % 4 != 0) {
        throw std::runtime_error(path + " is not SPIR-V (build the engine's shaders first)");
    }
    // SPIR-V is words: copied into a uint32_t buffer for its alignment.
    std::vector<uint32_t> words(bytes.size() / 4);
    std::memcpy(words.data(), bytes.data(), bytes.size());
    VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    info.codeSize = bytes.size();
    info.pCode = words.data();
    VkShaderModule module = VK_NULL_HANDLE;
    vk_check(vkCreateShaderModule(device, &info, nullptr, &module), path.c_str());
    return module;
}

void barrier(VkCommandBuffer cmd, Image &image, const ImageUse &next) {
    HistencilImage &s = image.state;
    VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
    b.srcStageMask = s.stage;
    b.srcAccessMask = s.access;
    b.dstStageMask = next.stage;
    b.dstAccessMask = next.access;
    b.oldLayout = s.layout;
    b.newLayout = next.layout;
    b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = s.image;
    b.subresourceRange = {image.aspect, 0, 1, 0, 1};
    VkDependencyInfo dependency{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dependency.imageMemoryBarrierCount = 1;
    dependency.pImageMemoryBarriers = &b;
    vkCmdPipelineBarrier2(cmd, &dependency);
    s.layout = next.layout;
    s.stage = next.stage;
    s.access = next.access;
}

VkPipeline graphics_pipeline(VkDevice device, const PipelineSpec &spec) {
    VkPipelineShaderStageCreateInfo stages[2]{};
    stages[0].sType = stages[1].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = spec.vertex;
    stages[0].pName = "main";
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = spec.fragment;
    stages[1].pName = "main";

    // The mesh layout: position and normal, 3 floats each.
    VkVertexInputBindingDescription binding{0, 6 * sizeof(float), VK_VERTEX_INPUT_RATE_VERTEX};
    VkVertexInputAttributeDescription attributes[2] = {
        {0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0},
        {1, 0, VK_FORMAT_R32G32B32_SFLOAT, 3 * sizeof(float)},
    };
    VkPipelineVertexInputStateCreateInfo vertex_input{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    vertex_input.vertexBindingDescriptionCount = 1;
    vertex_input.pVertexBindingDescriptions = &binding;
    vertex_input.vertexAttributeDescriptionCount = 2;
    vertex_input.pVertexAttributeDescriptions = attributes;
    VkPipelineInputAssemblyStateCreateInfo assembly{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkPipelineViewportStateCreateInfo viewport{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    viewport.viewportCount = 1;
    viewport.scissorCount = 1;
    // No culling: the boxes are closed, so back faces lose the depth test in both passes alike,
    // and the projection's Y flip cannot turn the winding against the engine.
    VkPipelineRasterizationStateCreateInfo raster{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.cullMode = VK_CULL_MODE_NONE;
    raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    raster.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo multisample{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    std::vector<VkPipelineColorBlendAttachmentState> blends(spec.color_formats.size());
    for (auto &b : blends) b.colorWriteMask = 0xf;
    VkPipelineColorBlendStateCreateInfo blend{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    blend.attachmentCount = static_cast<uint32_t>(blends.size());
    blend.pAttachments = blends.data();
    std::vector<VkDynamicState> dynamic{VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    dynamic.insert(dynamic.end(), spec.dynamic.begin(), spec.dynamic.end());
    VkPipelineDynamicStateCreateInfo dynamic_info{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dynamic_info.dynamicStateCount = static_cast<uint32_t>(dynamic.size());
    dynamic_info.pDynamicStates = dynamic.data();
    // Dynamic rendering: the attachments' formats instead of a render pass.
    VkPipelineRenderingCreateInfo rendering{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
    rendering.colorAttachmentCount = static_cast<uint32_t>(spec.color_formats.size());
    rendering.pColorAttachmentFormats = spec.color_formats.data();
    rendering.depthAttachmentFormat = spec.depth_format;
    rendering.stencilAttachmentFormat = spec.stencil_format;

    VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    info.pNext = &rendering;
    info.stageCount = 2;
    info.pStages = stages;
    info.pVertexInputState = &vertex_input;
    info.pInputAssemblyState = &assembly;
    info.pViewportState = &viewport;
    info.pRasterizationState = &raster;
    info.pMultisampleState = &multisample;
    info.pDepthStencilState = &spec.depth_stencil;
    info.pColorBlendState = &blend;
    info.pDynamicState = &dynamic_info;
    info.layout = spec.layout;
    VkPipeline pipeline = VK_NULL_HANDLE;
    vk_check(vkCreateGraphicsPipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline),
             "vkCreateGraphicsPipelines");
    return pipeline;
}
