//! Graphics pipelines. Everything that changes between the talk's light passes (cull mode, depth
//! and stencil state) is dynamic state set per draw from the model's pass state
//! ([`Recording::apply`](crate::gpu::encoder::recording::Recording::apply)); pipelines differ only
//! in shaders, attachments, blending and colour writes.

use crate::gpu::device::context::Context;
use crate::gpu::device::error::{Result, VkCall};
use ash::vk;
use std::io::Cursor;

/// Which vertex attributes a pipeline reads from binding 0.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum VertexInput {
    /// No vertex buffer (full-screen triangle).
    None,
    /// Position only (light volumes; `scene::Vertex`).
    Position,
    /// Every attribute of `scene::Vertex`: position, normal, both texture coordinate sets,
    /// tangent and colour (the textured mesh passes).
    Mesh,
    /// Position, normal and lightmap uv (alpha meshes; `scene::Vertex`).
    PositionNormalUv,
    /// `histencil_alpha::SpriteVertex`: position, corner, entity, param.
    Sprite,
}

/// How a pipeline's colour output combines with the target.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Blend {
    /// Overwrite.
    Off,
    /// Add (light accumulation).
    Additive,
    /// Premultiplied-alpha "over": `src + dst * (1 - src.a)` (translucent surfaces).
    PremultipliedOver,
}

/// A graphics pipeline's fixed parts.
pub struct PipelineDesc<'a> {
    pub name: &'a str,
    pub vertex: (&'a str, &'a [u8]),
    pub fragment: Option<(&'a str, &'a [u8])>,
    pub layout: vk::PipelineLayout,
    pub vertex_input: VertexInput,
    pub color_formats: &'a [vk::Format],
    pub color_writes: bool,
    pub blend: Blend,
    pub depth_stencil_format: vk::Format,
    /// Clamp depth instead of clipping at near/far: light volumes crossing the far plane keep
    /// their back faces (at depth 1) so the stencil/depth tests still see them.
    pub depth_clamp: bool,
    /// The fragment shader's specialisation constants, ids 0, 1, ... in order (32-bit each;
    /// booleans as 0 / 1).
    pub specialization: &'a [u32],
}

pub(crate) fn create_module(ctx: &Context, name: &str, spirv: &[u8]) -> Result<vk::ShaderModule> {
    let words = ash::util::read_spv(&mut Cursor::new(spirv)).expect("build.rs wrote valid SPIR-V");
    let info = vk::ShaderModuleCreateInfo::default().code(&words);
    // SAFETY: `info` and `words` live until the call returns; `words` is whole SPIR-V words
    // (`read_spv` checked the length and magic) compiled from histencil's shaders, by build.rs
    // with glslc or, for an engine's light shaders, by `histencil_build` as the # Safety of
    // `EngineHooks::new` promises.
    let module =
        unsafe { ctx.device.create_shader_module(&info, None) }.call("vkCreateShaderModule")?;
    if let Some(hazards) = ctx.hazards.get() {
        hazards.module(module, &words);
    }
    ctx.name(module, name);
    Ok(module)
}

/// The map entries and data of 32-bit specialisation constants 0, 1, ... set to `constants`.
fn specialization_data(constants: &[u32]) -> (Vec<vk::SpecializationMapEntry>, Vec<u8>) {
    let entries = (0..constants.len() as u32)
        .map(|id| {
            vk::SpecializationMapEntry::default()
                .constant_id(id)
                .offset(4 * id)
                .size(4)
        })
        .collect();
    let bytes = constants.iter().flat_map(|c| c.to_ne_bytes()).collect();
    (entries, bytes)
}

/// A named compute pipeline running `module` (name, SPIR-V) with `layout`, its specialisation
/// constants 0, 1, ... set to `specialization`.
pub(crate) fn create_compute_pipeline(
    ctx: &Context,
    name: &str,
    module: (&str, &[u8]),
    layout: vk::PipelineLayout,
    specialization: &[u32],
) -> Result<vk::Pipeline> {
    let shader = create_module(ctx, module.0, module.1)?;
    let (entries, bytes) = specialization_data(specialization);
    let info = vk::SpecializationInfo::default()
        .map_entries(&entries)
        .data(&bytes);
    let mut stage = vk::PipelineShaderStageCreateInfo::default()
        .stage(vk::ShaderStageFlags::COMPUTE)
        .module(shader)
        .name(c"main");
    if !specialization.is_empty() {
        stage = stage.specialization_info(&info);
    }
    let info = [vk::ComputePipelineCreateInfo::default()
        .stage(stage)
        .layout(layout)];
    // SAFETY: `info`, `stage`, the specialisation entries and bytes live until the call
    // returns; `shader` and `layout` are live objects of this device. The cache is null or the
    // context's: histencil's own, made without EXTERNALLY_SYNCHRONIZED (so Vulkan synchronises
    // it), or an engine's, used only inside histencil's calls as `BorrowedDevice` tells it.
    let created = unsafe {
        ctx.device
            .create_compute_pipelines(ctx.pipeline_cache, &info, None)
    };
    // SAFETY: the module was made above for this pipeline alone; a made pipeline no longer
    // needs it.
    unsafe { ctx.device.destroy_shader_module(shader, None) };
    let pipeline = created
        .map_err(|(_, e)| e)
        .call("vkCreateComputePipelines")?[0];
    if let Some(hazards) = ctx.hazards.get() {
        hazards.pipeline(pipeline, &[shader]);
    }
    ctx.name(pipeline, name);
    Ok(pipeline)
}

pub const DYNAMIC_STATES: [vk::DynamicState; 11] = [
    vk::DynamicState::VIEWPORT,
    vk::DynamicState::SCISSOR,
    vk::DynamicState::CULL_MODE,
    vk::DynamicState::DEPTH_TEST_ENABLE,
    vk::DynamicState::DEPTH_WRITE_ENABLE,
    vk::DynamicState::DEPTH_COMPARE_OP,
    vk::DynamicState::STENCIL_TEST_ENABLE,
    vk::DynamicState::STENCIL_OP,
    vk::DynamicState::STENCIL_COMPARE_MASK,
    vk::DynamicState::STENCIL_WRITE_MASK,
    vk::DynamicState::STENCIL_REFERENCE,
];

// The offsets `VertexInput::Mesh` reads `scene::Vertex` at.
const _: () = {
    use histencil_scene::Vertex;
    assert!(std::mem::offset_of!(Vertex, uv1) == 32);
    assert!(std::mem::offset_of!(Vertex, tangent) == 40);
    assert!(std::mem::offset_of!(Vertex, color) == 56);
    assert!(size_of::<Vertex>() == 72);
};

/// The vertex stride and attributes (locations 0, 1, ...) of `input`.
fn vertex_attributes(input: VertexInput) -> (u32, Vec<vk::VertexInputAttributeDescription>) {
    use vk::Format as F;
    let (stride, formats): (usize, &[(vk::Format, u32)]) = match input {
        VertexInput::None => (0, &[]),
        VertexInput::Position => (
            size_of::<histencil_scene::Vertex>(),
            &[(F::R32G32B32_SFLOAT, 0)],
        ),
        VertexInput::Mesh => (
            size_of::<histencil_scene::Vertex>(),
            &[
                (F::R32G32B32_SFLOAT, 0),
                (F::R32G32B32_SFLOAT, 12),
                (F::R32G32_SFLOAT, 24),
                (F::R32G32_SFLOAT, 32),
                (F::R32G32B32A32_SFLOAT, 40),
                (F::R32G32B32A32_SFLOAT, 56),
            ],
        ),
        VertexInput::PositionNormalUv => (
            size_of::<histencil_scene::Vertex>(),
            &[
                (F::R32G32B32_SFLOAT, 0),
                (F::R32G32B32_SFLOAT, 12),
                (F::R32G32_SFLOAT, 24),
            ],
        ),
        VertexInput::Sprite => (
            size_of::<histencil_alpha::SpriteVertex>(),
            &[
                (F::R32G32B32_SFLOAT, 0),
                (F::R32G32_SFLOAT, 12),
                (F::R32_UINT, 20),
                (F::R32_SFLOAT, 24),
            ],
        ),
    };
    let attributes = formats
        .iter()
        .enumerate()
        .map(|(location, (format, offset))| {
            vk::VertexInputAttributeDescription::default()
                .location(location as u32)
                .binding(0)
                .format(*format)
                .offset(*offset)
        })
        .collect();
    (stride as u32, attributes)
}

pub fn create_pipeline(ctx: &Context, desc: &PipelineDesc) -> Result<vk::Pipeline> {
    ctx.need(
        crate::gpu::device::limits::Limit::ColorAttachments,
        desc.color_formats.len() as u32,
        &format!("pipeline `{}`", desc.name),
    )?;
    let vertex_module = create_module(ctx, desc.vertex.0, desc.vertex.1)?;
    let fragment_module = match desc.fragment {
        Some((name, spirv)) => match create_module(ctx, name, spirv) {
            Ok(m) => Some(m),
            Err(e) => {
                // SAFETY: the vertex module was made above and nothing uses it yet.
                unsafe { ctx.device.destroy_shader_module(vertex_module, None) };
                return Err(e);
            }
        },
        None => None,
    };
    let mut stages = vec![vk::PipelineShaderStageCreateInfo::default()
        .stage(vk::ShaderStageFlags::VERTEX)
        .module(vertex_module)
        .name(c"main")];
    let (entries, constant_bytes) = specialization_data(desc.specialization);
    let specialization = (!entries.is_empty()).then(|| {
        vk::SpecializationInfo::default()
            .map_entries(&entries)
            .data(&constant_bytes)
    });
    if let Some(m) = fragment_module {
        let mut stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::FRAGMENT)
            .module(m)
            .name(c"main");
        if let Some(info) = specialization.as_ref() {
            stage = stage.specialization_info(info);
        }
        stages.push(stage);
    }
    let (stride, attributes) = vertex_attributes(desc.vertex_input);
    let vertex_bindings = [vk::VertexInputBindingDescription::default()
        .binding(0)
        .stride(stride)
        .input_rate(vk::VertexInputRate::VERTEX)];
    let bindings: &[_] = if attributes.is_empty() {
        &[]
    } else {
        &vertex_bindings
    };
    let vertex_input = vk::PipelineVertexInputStateCreateInfo::default()
        .vertex_binding_descriptions(bindings)
        .vertex_attribute_descriptions(&attributes);
    let input_assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
        .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
    let viewport = vk::PipelineViewportStateCreateInfo::default()
        .viewport_count(1)
        .scissor_count(1);
    let raster = vk::PipelineRasterizationStateCreateInfo::default()
        .depth_clamp_enable(desc.depth_clamp)
        .polygon_mode(vk::PolygonMode::FILL)
        .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
        .line_width(1.0);
    let multisample = vk::PipelineMultisampleStateCreateInfo::default()
        .rasterization_samples(vk::SampleCountFlags::TYPE_1);
    let depth_stencil = vk::PipelineDepthStencilStateCreateInfo::default();
    let write_mask = if desc.color_writes {
        vk::ColorComponentFlags::RGBA
    } else {
        vk::ColorComponentFlags::empty()
    };
    let dst_factor = match desc.blend {
        Blend::PremultipliedOver => vk::BlendFactor::ONE_MINUS_SRC_ALPHA,
        Blend::Off | Blend::Additive => vk::BlendFactor::ONE,
    };
    let blend_attachment = vk::PipelineColorBlendAttachmentState::default()
        .blend_enable(desc.blend != Blend::Off)
        .src_color_blend_factor(vk::BlendFactor::ONE)
        .dst_color_blend_factor(dst_factor)
        .color_blend_op(vk::BlendOp::ADD)
        .src_alpha_blend_factor(vk::BlendFactor::ONE)
        .dst_alpha_blend_factor(dst_factor)
        .alpha_blend_op(vk::BlendOp::ADD)
        .color_write_mask(write_mask);
    let blend_attachments = vec![blend_attachment; desc.color_formats.len()];
    let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachments);
    // With the depth bounds test enabled, every pipeline takes it as dynamic state, so one
    // pipeline serves a light's passes with and without it (`Recording::apply_bounded` sets it per draw).
    let mut dynamic_states = DYNAMIC_STATES.to_vec();
    if ctx.depth_bounds {
        dynamic_states.extend([
            vk::DynamicState::DEPTH_BOUNDS_TEST_ENABLE,
            vk::DynamicState::DEPTH_BOUNDS,
        ]);
    }
    let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
    let has_depth = desc.depth_stencil_format != vk::Format::UNDEFINED;
    // A depth-only format (the hi-stencil touch image) has no stencil attachment.
    let has_stencil = crate::gpu::access::aspect_of(desc.depth_stencil_format)
        .contains(vk::ImageAspectFlags::STENCIL);
    let stencil_format = if has_stencil {
        desc.depth_stencil_format
    } else {
        vk::Format::UNDEFINED
    };
    let mut rendering = vk::PipelineRenderingCreateInfo::default()
        .color_attachment_formats(desc.color_formats)
        .depth_attachment_format(desc.depth_stencil_format)
        .stencil_attachment_format(stencil_format);
    let mut info = vk::GraphicsPipelineCreateInfo::default()
        .stages(&stages)
        .vertex_input_state(&vertex_input)
        .input_assembly_state(&input_assembly)
        .viewport_state(&viewport)
        .rasterization_state(&raster)
        .multisample_state(&multisample)
        .color_blend_state(&blend)
        .dynamic_state(&dynamic)
        .layout(desc.layout)
        .push_next(&mut rendering);
    if has_depth {
        info = info.depth_stencil_state(&depth_stencil);
    }
    // SAFETY: `info` and every struct it points at (stages, specialisation, vertex input,
    // fixed state, blend attachments, dynamic states, the rendering formats) live until the
    // call returns. The modules and `desc.layout` are live objects of this device; dynamic
    // rendering is enabled (`REQUIREMENTS`), as is the depth bounds test when its dynamic
    // states are named (`ctx.depth_bounds`). The cache is synchronised as for compute.
    let result = unsafe {
        ctx.device
            .create_graphics_pipelines(ctx.pipeline_cache, &[info], None)
    };
    // SAFETY: the modules were made above for this pipeline alone; a made pipeline no longer
    // needs them.
    unsafe {
        ctx.device.destroy_shader_module(vertex_module, None);
        if let Some(m) = fragment_module {
            ctx.device.destroy_shader_module(m, None);
        }
    }
    let pipeline = result
        .map_err(|(_, e)| e)
        .call("vkCreateGraphicsPipelines")?[0];
    if let Some(hazards) = ctx.hazards.get() {
        let modules: Vec<_> = [Some(vertex_module), fragment_module]
            .into_iter()
            .flatten()
            .collect();
        hazards.pipeline(pipeline, &modules);
    }
    ctx.name(pipeline, desc.name);
    Ok(pipeline)
}
