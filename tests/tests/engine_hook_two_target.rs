//! The book's two-target hooks (`examples/hooks/two_target`: an RG16 octahedral normal, RGBA8
//! tint with the material index in alpha, a row of BRDF id and parameters per material, depth
//! from the depth attachment, one shadow map in set 1) compile with histencil's light shaders
//! as `histencil_build` compiles an engine's, fit the set layout the book describes (and are
//! refused, naming the binding, by one that lacks a binding), make a lighting whose light
//! pipelines the validation layer accepts, and light a frame as histencil's own decode does.
//! The engine chapter includes those files, so what it shows is what this compiles and lights.

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

/// The book's two-target hooks light a frame: histencil's own G-buffer of `brdfs-3` (two
/// materials of each of its three BRDFs, differing in their parameters) is re-encoded as the
/// hooks' header says (an octahedral RG16 normal, an RGBA8 tint with the material index in
/// alpha, depth read back from the depth attachment, one row per material), and the stencil,
/// LUT, tiled and depth-id techniques lit through the hooks (the LUT technique picks each
/// pixel's table through `decode_lut_material`; the tiled and depth-id kernels call the hooks
/// from compute shaders) match the same frames lit through histencil's own decode, every
/// channel within what the encodings change:
/// - the tint, rounded to 8 bits: at most half a step, `0.5 / 255`, on a channel of tint `t`,
///   and the light is linear in the tint with a white part that only adds, so it moves a
///   channel lit `v` by at most `v * (0.5 / 255) / t` (plus the reference's own f16 tint,
///   2^-11 of `t`);
/// - the normal, rounded to 16 bits per octahedral coordinate: at most about 3e-5 rad, which
///   moves Lambert, Oren-Nayar and GGX at the scene's roughness (alpha 0.15 and 0.4) by well
///   under 1e-3 of their value; and the position, rebuilt from 32-bit depth rather than read
///   as linear depth, by less. Both are held to 1 %, ten times what they can reach;
/// - the HDR target's f16 rounding of each result, 2^-11 of it, and 1e-4 absolute for zeros.
///
/// Then two rows of one BRDF swap their parameters: exactly the pixels of those two
/// materials change, so the index each pixel carries picks its row.
#[test]
fn the_two_target_hooks_light_a_frame_as_histencils_own_decode_does() {
    use histencil_brdf::{Brdf, BrdfId, BrdfSet, MaterialRows};
    use histencil_tests::engine::{copy_to_buffer, hdr_floats, plain_frame};
    use histencil_vk::{
        BrdfParams, BrdfSource, HookSets, ImageState, MixedTiles, TileClassify, TileSide,
        TiledFrame,
    };
    let mut scene = histencil_scene::embedded("brdfs-3").unwrap();
    scene.normalise_lights();
    let engine = Engine::start();
    let (width, height) = (64u32, 48u32);
    let pixels = (width * height) as usize;
    let extent = vk::Extent2D { width, height };
    let d = &engine.device;
    {
        // SAFETY: the engine's handles outlive the context; nothing else uses its queue.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.expect("context");
        let ds_format = ctx.depth_stencil_format().vk();
        let mut renderer = Renderer::new(&ctx, scene.clone(), width, height).unwrap();
        let layout = *renderer.stencil_layout();
        let brdfs = renderer.brdfs().to_vec();
        let view = scene.camera.view_desc(width as f32 / height as f32);
        let plan = stencil_plan(&scene, &layout, &brdfs, &view, Backend::Ps3);
        let desc = lighting_desc(layout, brdfs.clone(), extent, ds_format, scene.lights.len());

        // The reference: histencil's G-buffer lit by its own decode, read back with its HDR.
        let targets = engine.lighting_targets(extent, ds_format);
        let mut refs = targets.refs();
        let mut builtin = DeferredLighting::new(&ctx, &desc).unwrap();
        let sizes = [8, 16, 16, 8].map(|b| b * pixels as u64);
        let readbacks = sizes.map(|size| engine.readback_buffer(size));
        // SAFETY: the engine's command buffer, recording; the images' states are tracked.
        unsafe {
            let (pool, cmd) = engine.command_buffer();
            d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                .unwrap();
            renderer.record_gbuffer(cmd, &mut refs).unwrap();
            let frame = plain_frame(&view, &scene.lights, &plan, HookSets::default());
            builtin.record(cmd, &frame, &mut refs).unwrap();
            for (image, buffer) in refs.gbuffer.iter_mut().zip(&readbacks) {
                copy_to_buffer(d, cmd, image, buffer.buffer);
            }
            copy_to_buffer(d, cmd, &mut refs.hdr, readbacks[3].buffer);
            engine.submit_and_wait(pool, cmd);
            builtin.slot_finished(0).unwrap();
        }
        let albedo = hdr_floats(readbacks[0].bytes());
        let floats = |b: &[u8]| -> Vec<f32> {
            (b.chunks_exact(4))
                .map(|w| f32::from_le_bytes(w.try_into().unwrap()))
                .collect()
        };
        let (normal_depth, material) = (floats(readbacks[1].bytes()), floats(readbacks[2].bytes()));
        let reference = hdr_floats(readbacks[3].bytes());

        // The materials as rows, and each drawn pixel's row found by its BRDF and parameters.
        let mut materials: Vec<Brdf> = vec![];
        for o in &scene.objects {
            if !materials.contains(&o.material.brdf) {
                materials.push(o.material.brdf);
            }
        }
        let row_of = |px: usize| -> Option<u8> {
            let m = &material[4 * px..4 * px + 4];
            let drawn = normal_depth[4 * px + 3] > 0.0;
            drawn.then(|| {
                let row = materials.iter().position(|b| {
                    let p = b.packed_params();
                    b.id().index() as f32 == m[3] && (0..3).all(|i| p[i] as f32 == m[i])
                });
                row.expect("every drawn pixel is one of the scene's materials") as u8
            })
        };
        let rows_of: Vec<Option<u8>> = (0..pixels).map(row_of).collect();
        let set = BrdfSet::new(&BrdfId::ALL, vec![]).unwrap();
        let rows = MaterialRows::new(&set, &materials).unwrap();
        let mut encoded = vec![0u8; pixels * 8];
        let (normals, tints) = encoded.split_at_mut(pixels * 4);
        for (px, row) in rows_of.iter().enumerate() {
            let Some(row) = row else { continue };
            let n = &normal_depth[4 * px..4 * px + 3];
            for (i, v) in octahedral(n).into_iter().enumerate() {
                let unorm = (v * 0.5 + 0.5) * 65535.0;
                normals[4 * px + 2 * i..4 * px + 2 * i + 2]
                    .copy_from_slice(&(unorm.round() as u16).to_le_bytes());
            }
            for c in 0..3 {
                tints[4 * px + c] = (albedo[4 * px + c].clamp(0.0, 1.0) * 255.0).round() as u8;
            }
            tints[4 * px + 3] = *row;
        }

        // The hooks' images, rows, shadow block (no light shadowed) and one-texel shadow map.
        use vk::ImageUsageFlags as U;
        let uploaded = U::SAMPLED | U::TRANSFER_DST;
        let normal = engine.image("two-target-normal", SURFACE_FORMATS[0], extent, uploaded);
        let tint = engine.image("two-target-tint", SURFACE_FORMATS[1], extent, uploaded);
        let one = vk::Extent2D {
            width: 1,
            height: 1,
        };
        let shadow_map = engine.image("shadow-map", vk::Format::D16_UNORM, one, uploaded);
        let hdr_usage = U::COLOR_ATTACHMENT | U::TRANSFER_SRC | U::TRANSFER_DST | U::STORAGE;
        let hdr = engine.image(
            "two-target-hdr",
            vk::Format::R16G16B16A16_SFLOAT,
            extent,
            hdr_usage,
        );
        let staging = engine.upload_buffer(&encoded, vk::BufferUsageFlags::TRANSFER_SRC);
        let ubo = vk::BufferUsageFlags::UNIFORM_BUFFER;
        // The hook's block: TWO_TARGET_MATERIALS (256) rows, those past the materials zeros.
        let row_block = |rows: &MaterialRows| {
            let mut bytes = rows.bytes();
            bytes.resize(256 * histencil_brdf::MATERIAL_ROW_BYTES, 0);
            engine.upload_buffer(&bytes, ubo)
        };
        let row_buffer = row_block(&rows);
        // std140: the matrix, the shadowed light (none: ~0u), the biases.
        let identity = glam::Mat4::IDENTITY.to_cols_array();
        let mut shadow_block: Vec<u8> = identity.iter().flat_map(|f| f.to_le_bytes()).collect();
        shadow_block.extend([u32::MAX, 0, 0, 0].iter().flat_map(|u| u.to_le_bytes()));
        shadow_block.extend([0u8; 16]);
        let shadow_buffer = engine.upload_buffer(&shadow_block, ubo);
        let depth_view = depth_only_view(d, targets.depth.image, ds_format);
        let sampler_info = vk::SamplerCreateInfo::default()
            .compare_enable(true)
            .compare_op(vk::CompareOp::LESS_OR_EQUAL);
        // SAFETY: the engine's device; destroyed after the frames that use them.
        let sampler = unsafe { d.create_sampler(&sampler_info, None) }.unwrap();
        let bindings = two_target_bindings();
        let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings);
        // SAFETY: as above.
        let set_layout = unsafe { d.create_descriptor_set_layout(&info, None) }.unwrap();
        let (pool, hook_set) = two_target_set(d, set_layout);
        let read_only = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
        let image = |view, layout| {
            [vk::DescriptorImageInfo::default()
                .image_view(view)
                .image_layout(layout)]
        };
        let depth_layout = vk::ImageLayout::DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL;
        let images = [
            image(normal.view, read_only),
            image(tint.view, read_only),
            image(depth_view, depth_layout),
            image(shadow_map.view, read_only).map(|i| i.sampler(sampler)),
        ];
        let buffer = |b: &histencil_tests::engine::EngineBuffer| {
            [vk::DescriptorBufferInfo::default()
                .buffer(b.buffer)
                .range(vk::WHOLE_SIZE)]
        };
        let buffers = [buffer(&row_buffer), buffer(&shadow_buffer)];
        let write = |binding: u32, ty| {
            vk::WriteDescriptorSet::default()
                .dst_set(hook_set)
                .dst_binding(binding)
                .descriptor_type(ty)
        };
        use vk::DescriptorType as T;
        let writes = [
            write(0, T::SAMPLED_IMAGE).image_info(&images[0]),
            write(1, T::SAMPLED_IMAGE).image_info(&images[1]),
            write(2, T::SAMPLED_IMAGE).image_info(&images[2]),
            write(3, T::UNIFORM_BUFFER).buffer_info(&buffers[0]),
            write(4, T::COMBINED_IMAGE_SAMPLER).image_info(&images[3]),
            write(5, T::UNIFORM_BUFFER).buffer_info(&buffers[1]),
        ];
        // SAFETY: a set of the engine's pool; every view, buffer and the sampler are live.
        unsafe { d.update_descriptor_sets(&writes, &[]) };

        let decode = HookSetLayout {
            layout: set_layout,
            bindings: &bindings,
        };
        // SAFETY: the layout is made from `bindings`, on the lent device, and outlives the
        // lighting; the modules are histencil_build's, from this version's shaders.
        let hooks = unsafe { EngineHooks::new(TWO_TARGET, decode, None, &SURFACE_FORMATS) }
            .unwrap()
            .with_brdf_params(BrdfParams::Materials);
        let two_desc = LightingDesc {
            hooks: LightHooks::Engine(hooks),
            ..desc.clone()
        };
        let mut lighting = DeferredLighting::new(&ctx, &two_desc).unwrap();
        lighting.check_materials(&rows).unwrap();
        let sampled = ImageState {
            layout: read_only,
            stage: vk::PipelineStageFlags2::FRAGMENT_SHADER,
            access: vk::AccessFlags2::SHADER_SAMPLED_READ,
        };
        let mut two = histencil_vk::LightingTargets {
            gbuffer: vec![
                normal.as_ref(ImageState::UNDEFINED),
                tint.as_ref(ImageState::UNDEFINED),
            ],
            depth_stencil: refs.depth_stencil,
            hdr: hdr.as_ref(ImageState::UNDEFINED),
        };
        let mut shadow = shadow_map.as_ref(ImageState::UNDEFINED);
        let hook_sets = HookSets {
            decode: Some(hook_set),
            visibility: None,
        };
        // One frame lit and read back as floats: the G-buffer pass again (the same depth and
        // stencil), then lit through histencil's own decode (`hooks` false) or through the
        // hooks (their images uploaded on the first such frame), by `how`.
        // The LUT technique's tables, one per material in the G-buffer's index order, which
        // is the order the book's tint alpha carries too.
        let tables = renderer.lut_tables().unwrap();
        // SAFETY: the tables outlive every frame below, each waited for.
        unsafe {
            builtin.set_lut_tables(tables);
            lighting.set_lut_tables(tables);
        }
        let mut uploaded = false;
        let mut light = |hooks: bool, how: How| -> Vec<f32> {
            let readback = engine.readback_buffer(8 * pixels as u64);
            // SAFETY: as above; every image's state is tracked, and the slots were finished.
            unsafe {
                let (pool, cmd) = engine.command_buffer();
                d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                    .unwrap();
                renderer.record_gbuffer(cmd, &mut refs).unwrap();
                let (lighting, targets, hook_sets) = match hooks {
                    false => (&mut builtin, &mut refs, HookSets::default()),
                    true => {
                        two.depth_stencil = refs.depth_stencil;
                        if !uploaded {
                            upload(d, cmd, &mut two.gbuffer, staging.buffer, extent, sampled);
                            clear_shadow_map(d, cmd, &mut shadow, sampled);
                            uploaded = true;
                        }
                        (&mut lighting, &mut two, hook_sets)
                    }
                };
                if matches!(how, How::Tiled | How::DepthId) {
                    let frame = TiledFrame {
                        slot: 0,
                        view: &view,
                        lights: &scene.lights,
                        clear_hdr: true,
                        side: TileSide::Sixteen,
                        mixed: MixedTiles::PerBrdf,
                        classify: TileClassify::for_context(&ctx),
                        hook_sets,
                    };
                    if how == How::Tiled {
                        lighting.record_tiled(cmd, &frame, targets).unwrap();
                    } else {
                        lighting.record_depth_id(cmd, &frame, targets).unwrap();
                    }
                } else {
                    let mut frame = plain_frame(&view, &scene.lights, &plan, hook_sets);
                    if how == How::Lut {
                        frame.brdf_source = BrdfSource::Table;
                    }
                    lighting.record(cmd, &frame, targets).unwrap();
                }
                copy_to_buffer(d, cmd, &mut targets.hdr, readback.buffer);
                let depth_stencil = targets.depth_stencil;
                engine.submit_and_wait(pool, cmd);
                lighting.slot_finished(0).unwrap();
                refs.depth_stencil = depth_stencil;
            }
            let out = hdr_floats(readback.bytes());
            engine.free_buffer(readback);
            out
        };
        let through_hooks = light(true, How::Stencil);
        let drawn = rows_of.iter().filter(|r| r.is_some()).count();
        assert!(drawn > pixels / 2, "the scene covers the frame");
        let lit = reference.iter().filter(|v| **v > 0.0).count();
        assert!(lit > pixels, "the reference is mostly dark");
        let worst = assert_within_encodings(&reference, &through_hooks, &rows_of, &albedo);
        eprintln!("stencil: worst channel at {worst:.3} of its bound, {drawn} of {pixels} drawn");
        // The LUT technique reads each pixel's table through decode_lut_material; the tiled
        // and depth-id kernels call the same hooks from compute shaders. Each is held to the
        // same technique through histencil's own decode (the LUT's own error against the
        // formulas is the same on both sides).
        for how in [How::Lut, How::Tiled, How::DepthId] {
            let builtin_frame = light(false, how);
            let hooks_frame = light(true, how);
            let worst = assert_within_encodings(&builtin_frame, &hooks_frame, &rows_of, &albedo);
            eprintln!("{how:?}: worst channel at {worst:.3} of its bound");
        }

        // Two rows of one BRDF swap their parameters: only their pixels change.
        let (a, b) = same_brdf_pair(&materials);
        let mut swapped = materials.clone();
        swapped.swap(a, b);
        let row_buffer_swapped = row_block(&MaterialRows::new(&set, &swapped).unwrap());
        let rows_write = buffer(&row_buffer_swapped);
        let rewrite = [write(3, T::UNIFORM_BUFFER).buffer_info(&rows_write)];
        // SAFETY: the set is not in use: its last frame finished.
        unsafe { d.update_descriptor_sets(&rewrite, &[]) };
        let after_swap = light(true, How::Stencil);
        let (mut moved, mut kept) = (0, 0);
        for (px, row) in rows_of.iter().enumerate() {
            let same = (0..4)
                .all(|c| through_hooks[4 * px + c].to_bits() == after_swap[4 * px + c].to_bits());
            match row {
                Some(r) if [a, b].contains(&(*r as usize)) => moved += usize::from(!same),
                _ => {
                    assert!(same, "pixel {px} of another material changed");
                    kept += 1;
                }
            }
        }
        assert!(moved > 0, "the swapped materials' pixels kept their light");
        eprintln!("swapping rows {a} and {b}: {moved} pixels changed, {kept} kept");

        drop((lighting, builtin));
        // SAFETY: the frames that used them finished, and the lightings are gone.
        unsafe {
            d.destroy_descriptor_pool(pool, None);
            d.destroy_descriptor_set_layout(set_layout, None);
            d.destroy_sampler(sampler, None);
            d.destroy_image_view(depth_view, None);
        }
        for b in
            readbacks
                .into_iter()
                .chain([staging, row_buffer, row_buffer_swapped, shadow_buffer])
        {
            engine.free_buffer(b);
        }
        for i in [normal, tint, shadow_map, hdr] {
            engine.free_image(i);
        }
        targets.free(&engine);
        assert!(ctx.validation_log().is_empty(), "messages go to the engine");
    }
    engine.destroy().assert_clean();
}

/// The techniques the test lights a frame with.
#[derive(Clone, Copy, Debug, PartialEq)]
enum How {
    Stencil,
    Lut,
    Tiled,
    DepthId,
}

/// Asserts every channel of `got` is within what the two targets' encodings change of
/// `reference` (the bound the test above derives; undrawn pixels and alpha bit for bit), and
/// returns the worst channel's error as a fraction of its bound.
fn assert_within_encodings(
    reference: &[f32],
    got: &[f32],
    rows_of: &[Option<u8>],
    albedo: &[f32],
) -> f32 {
    let mut worst = 0.0f32;
    for (px, row) in rows_of.iter().enumerate() {
        for c in 0..4 {
            let (want, got) = (reference[4 * px + c], got[4 * px + c]);
            if row.is_none() || c == 3 {
                assert_eq!(want.to_bits(), got.to_bits(), "pixel {px} channel {c}");
                continue;
            }
            let t = albedo[4 * px + c];
            let tinted = if t > 0.0 {
                (0.5 / 255.0) / t + 2f32.powi(-11)
            } else {
                0.0
            };
            let bound = want.abs() * (tinted + 0.01 + 2f32.powi(-10)) + 1e-4;
            let error = (got - want).abs();
            worst = worst.max(error / bound);
            assert!(
                error <= bound,
                "pixel {px} channel {c}: {got} through the hooks, {want} through histencil's \
                 decode (tint {t}, bound {bound})"
            );
        }
    }
    worst
}

/// The octahedral coordinates in [-1, 1]^2 of unit vector `n`, the inverse of
/// `two_target_octahedral_decode` (its fold sends x or y of 0 to the positive side).
fn octahedral(n: &[f32]) -> [f32; 2] {
    let s = n[0].abs() + n[1].abs() + n[2].abs();
    let (x, y) = (n[0] / s, n[1] / s);
    if n[2] >= 0.0 {
        return [x, y];
    }
    let sign = |v: f32| if v >= 0.0 { 1.0 } else { -1.0 };
    [(1.0 - y.abs()) * sign(x), (1.0 - x.abs()) * sign(y)]
}

/// Two materials of one BRDF with different parameters.
fn same_brdf_pair(materials: &[histencil_brdf::Brdf]) -> (usize, usize) {
    for a in 0..materials.len() {
        for b in a + 1..materials.len() {
            if materials[a].id() == materials[b].id() && materials[a] != materials[b] {
                return (a, b);
            }
        }
    }
    panic!("the scene has no two materials of one BRDF");
}

/// A view of `image`'s depth aspect alone, as a sampled-image descriptor needs.
fn depth_only_view(d: &ash::Device, image: vk::Image, format: vk::Format) -> vk::ImageView {
    let range = vk::ImageSubresourceRange::default()
        .aspect_mask(vk::ImageAspectFlags::DEPTH)
        .level_count(1)
        .layer_count(1);
    let info = vk::ImageViewCreateInfo::default()
        .image(image)
        .view_type(vk::ImageViewType::TYPE_2D)
        .format(format)
        .subresource_range(range);
    // SAFETY: the engine's live image, of a depth-stencil format; destroyed by the caller.
    unsafe { d.create_image_view(&info, None) }.unwrap()
}

/// A pool and the one hook set of `layout` (the two-target bindings).
fn two_target_set(
    d: &ash::Device,
    layout: vk::DescriptorSetLayout,
) -> (vk::DescriptorPool, vk::DescriptorSet) {
    use vk::DescriptorType as T;
    let size = |ty, n| vk::DescriptorPoolSize::default().ty(ty).descriptor_count(n);
    let sizes = [
        size(T::SAMPLED_IMAGE, 3),
        size(T::UNIFORM_BUFFER, 2),
        size(T::COMBINED_IMAGE_SAMPLER, 1),
    ];
    let info = vk::DescriptorPoolCreateInfo::default()
        .max_sets(1)
        .pool_sizes(&sizes);
    // SAFETY: the engine's device; the caller destroys it.
    let pool = unsafe { d.create_descriptor_pool(&info, None) }.unwrap();
    let layouts = [layout];
    let alloc = vk::DescriptorSetAllocateInfo::default()
        .descriptor_pool(pool)
        .set_layouts(&layouts);
    // SAFETY: as above.
    let set = unsafe { d.allocate_descriptor_sets(&alloc) }.unwrap()[0];
    (pool, set)
}

/// Copies the encoded normals then tints from `staging` into the two targets, and leaves
/// them in `next`.
///
/// # Safety
/// `cmd` is recording on the engine's device; the images' states are true.
unsafe fn upload(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    targets: &mut [histencil_vk::ImageRef],
    staging: vk::Buffer,
    extent: vk::Extent2D,
    next: histencil_vk::ImageState,
) {
    use histencil_tests::engine::barrier;
    let dst = histencil_vk::ImageState {
        layout: vk::ImageLayout::TRANSFER_DST_OPTIMAL,
        stage: vk::PipelineStageFlags2::COPY,
        access: vk::AccessFlags2::TRANSFER_WRITE,
    };
    let bytes = u64::from(extent.width * extent.height) * 4;
    for (i, image) in targets.iter_mut().enumerate() {
        // SAFETY: this fn's # Safety.
        unsafe {
            barrier(d, cmd, image, dst, true);
            let region = vk::BufferImageCopy::default()
                .buffer_offset(i as u64 * bytes)
                .image_subresource(
                    vk::ImageSubresourceLayers::default()
                        .aspect_mask(vk::ImageAspectFlags::COLOR)
                        .layer_count(1),
                )
                .image_extent(vk::Extent3D {
                    width: extent.width,
                    height: extent.height,
                    depth: 1,
                });
            d.cmd_copy_buffer_to_image(cmd, staging, image.image, dst.layout, &[region]);
            barrier(d, cmd, image, next, false);
        }
    }
}

/// Clears the shadow map to the far depth and leaves it sampled: no light reads it (the
/// shadow block names none), but a bound image is in its descriptor's layout.
///
/// # Safety
/// As [`upload`].
unsafe fn clear_shadow_map(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    image: &mut histencil_vk::ImageRef,
    next: histencil_vk::ImageState,
) {
    use histencil_tests::engine::barrier;
    let dst = histencil_vk::ImageState {
        layout: vk::ImageLayout::TRANSFER_DST_OPTIMAL,
        stage: vk::PipelineStageFlags2::CLEAR,
        access: vk::AccessFlags2::TRANSFER_WRITE,
    };
    let range = vk::ImageSubresourceRange::default()
        .aspect_mask(vk::ImageAspectFlags::DEPTH)
        .level_count(1)
        .layer_count(1);
    // SAFETY: this fn's # Safety.
    unsafe {
        barrier(d, cmd, image, dst, true);
        let far = vk::ClearDepthStencilValue {
            depth: 1.0,
            stencil: 0,
        };
        d.cmd_clear_depth_stencil_image(cmd, image.image, dst.layout, &far, &[range]);
        barrier(d, cmd, image, next, false);
    }
}
