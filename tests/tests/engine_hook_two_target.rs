//! The book's two-target hooks (`examples/hooks/two_target`: an RG16 octahedral normal, RGBA8
//! tint with the material index in alpha, a row of BRDF id and parameters per material, depth from the depth attachment, one shadow map in set 1)
//! compile with histencil's light shaders as `histencil_build` compiles an engine's, fit the set
//! layout the book describes (and are refused, naming the binding, by one that lacks a binding),
//! and make a lighting whose light pipelines the validation layer accepts. The engine chapter
//! includes those files, so what it shows is what this compiles.

use ash::vk;
use histencil_tests::engine::{lighting_desc, stencil_plan, Engine};
use histencil_vk::{
    Backend, Context, DeferredLighting, EngineHooks, Error, HookSetLayout, LightHooks,
    LightModules, LightingDesc, Renderer,
};

/// The images the decode reads, in `LightingTargets::gbuffer` order: target 0 the normal,
/// target 1 the tint and material index (the header of `surface_decode.glsl`).
const SURFACE_FORMATS: [vk::Format; 2] = [vk::Format::R16G16_UNORM, vk::Format::R8G8B8A8_UNORM];

const ALL_LIGHT_STAGES: vk::ShaderStageFlags = vk::ShaderStageFlags::from_raw(
    vk::ShaderStageFlags::FRAGMENT.as_raw() | vk::ShaderStageFlags::COMPUTE.as_raw(),
);

/// The one hook layout (set 1) the two hooks' headers declare: the decode's normal,
/// tint-and-material and depth images and its material rows, then the visibility's shadow map
/// and block.
fn two_target_bindings() -> Vec<vk::DescriptorSetLayoutBinding<'static>> {
    use vk::DescriptorType as T;
    [
        T::SAMPLED_IMAGE,          // 0 two_target_normal
        T::SAMPLED_IMAGE,          // 1 two_target_tint_material
        T::SAMPLED_IMAGE,          // 2 two_target_depth
        T::UNIFORM_BUFFER,         // 3 two_target_materials
        T::COMBINED_IMAGE_SAMPLER, // 4 two_target_shadow_map
        T::UNIFORM_BUFFER,         // 5 two_target_shadow
    ]
    .into_iter()
    .enumerate()
    .map(|(binding, ty)| {
        vk::DescriptorSetLayoutBinding::default()
            .binding(binding as u32)
            .descriptor_type(ty)
            .descriptor_count(1)
            .stage_flags(ALL_LIGHT_STAGES)
    })
    .collect()
}

/// histencil's light shaders compiled with `examples/hooks/two_target` by this crate's build
/// script, as an engine's build script compiles its hooks (`histencil_build`).
const TWO_TARGET: LightModules = include!(concat!(env!("OUT_DIR"), "/histencil_light_modules.rs"));

/// `EngineHooks::new` with a null decode layout of `bindings` and no visibility layout (the
/// shadow bindings sit in set 1): the checks use no handle.
fn hooks(
    modules: LightModules,
    bindings: &[vk::DescriptorSetLayoutBinding],
) -> Result<EngineHooks, Error> {
    let decode = HookSetLayout {
        layout: vk::DescriptorSetLayout::null(),
        bindings,
    };
    // SAFETY: refused, or never used to make a lighting.
    unsafe { EngineHooks::new(modules, decode, None, &SURFACE_FORMATS) }
}

#[test]
fn the_two_target_hooks_compile_and_fit_the_layout_the_book_gives() {
    let modules = TWO_TARGET;
    let bindings = two_target_bindings();
    hooks(modules, &bindings).expect("the layout the hooks' headers declare");
    // The material rows' block left out of the layout: refused, naming it.
    let without_params: Vec<_> = bindings
        .iter()
        .filter(|b| b.binding != 3)
        .copied()
        .collect();
    let err = match hooks(modules, &without_params) {
        Err(e @ Error::BadSetup(_)) => e.to_string(),
        other => panic!("expected a setup error, got {other:?}"),
    };
    // The reflected name of a uniform block is its instance name (`two_target_materials`).
    let words =
        "deferred_light: reads set 1 binding 3 (`two_target_materials`), a uniform buffer, \
                 and the decode layout (set 1) has no such binding";
    assert!(err.contains(words), "{err}\nshould say: {words}");
}

#[test]
fn the_two_target_hooks_make_light_pipelines_the_validation_layer_accepts() {
    let modules = TWO_TARGET;
    let mut scene = histencil_scene::embedded("brdfs-3").unwrap();
    scene.normalise_lights();
    let engine = Engine::start();
    let (width, height) = (48, 32);
    let extent = vk::Extent2D { width, height };
    let d = &engine.device;
    {
        // SAFETY: the engine's handles outlive the context; nothing else uses its queue.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.expect("context");
        let ds_format = ctx.depth_stencil_format().vk();
        let renderer = Renderer::new(&ctx, scene.clone(), width, height).unwrap();
        let layout = *renderer.stencil_layout();
        let brdfs = renderer.brdfs().to_vec();
        let bindings = two_target_bindings();
        let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings);
        // SAFETY: the engine's device; destroyed after the lighting.
        let set_layout = unsafe { d.create_descriptor_set_layout(&info, None) }.unwrap();
        let decode = HookSetLayout {
            layout: set_layout,
            bindings: &bindings,
        };
        // SAFETY: the layout is made from `bindings`, on the lent device, and outlives the
        // lighting; the modules are histencil_build's, from this version's shaders.
        let hooks = unsafe { EngineHooks::new(modules, decode, None, &SURFACE_FORMATS) }.unwrap();
        let desc = LightingDesc {
            hooks: LightHooks::Engine(hooks),
            ..lighting_desc(layout, brdfs.clone(), extent, ds_format, scene.lights.len())
        };
        let mut lighting = DeferredLighting::new(&ctx, &desc).unwrap();
        let view = scene.camera.view_desc(width as f32 / height as f32);
        let plan = stencil_plan(&scene, &layout, &brdfs, &view, Backend::Ps3);
        // The per-BRDF light pipelines, made from the two-target modules with the engine's
        // layout in set 1: the validation layer holds the shaders' interface to the layout.
        lighting.prepare(&plan).unwrap();
        assert!(
            lighting.pipeline_count() > 0,
            "the plan needs light pipelines"
        );
        drop(lighting);
        // SAFETY: the lighting that used it is gone.
        unsafe { d.destroy_descriptor_set_layout(set_layout, None) };
        assert!(ctx.validation_log().is_empty(), "messages go to the engine");
    }
    engine.destroy().assert_clean();
}
