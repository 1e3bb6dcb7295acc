//! An engine's hooks are held to the set layouts it binds them with and to the images its
//! decode reads: a hook reading a binding its layout lacks (which crashed lavapipe's pipeline
//! creation before, exit 139) is refused when the hooks are made, naming the module, set,
//! binding and types; surface images left out of a frame or in another format are refused when
//! it is recorded; a layout the tiled kernels cannot bind refuses the tiled technique. And an
//! engine's own decode set, described rightly, lights the frame bit for bit as histencil's own.

use ash::vk;
use histencil_tests::engine::{
    copy_to_buffer, gbuffer_bindings, hdr_floats, lighting_desc, plain_frame, stencil_plan, Engine,
};
use histencil_vk::{
    Backend, Context, DeferredLighting, EngineHooks, Error, HookSetLayout, HookSets, LightHooks,
    LightModules, LightingDesc, MixedTiles, Renderer, TileClassify, TileSide, TiledFrame,
};

const ALL_LIGHT_STAGES: vk::ShaderStageFlags = vk::ShaderStageFlags::from_raw(
    vk::ShaderStageFlags::FRAGMENT.as_raw() | vk::ShaderStageFlags::COMPUTE.as_raw(),
);

/// `EngineHooks::new` with histencil's modules (or `modules`) and a null decode layout of
/// `bindings`: every refusal below comes before any handle is used.
fn hooks(
    modules: LightModules,
    bindings: &[vk::DescriptorSetLayoutBinding],
) -> Result<EngineHooks, Error> {
    let decode = HookSetLayout {
        layout: vk::DescriptorSetLayout::null(),
        bindings,
    };
    // SAFETY: refused, or never used to make a lighting.
    unsafe { EngineHooks::new(modules, decode, None, &histencil_vk::GBUFFER_FORMATS) }
}

fn refusal(result: Result<EngineHooks, Error>) -> String {
    match result {
        Err(e @ Error::BadSetup(_)) => e.to_string(),
        other => panic!("expected a setup error, got {other:?}"),
    }
}

/// `spirv` with every `OpDecorate ... DescriptorSet 1` made `set`: the decode hook's resources
/// moved to another set, as a hook written for another layout would have them.
fn moved_to_set(spirv: &[u8], set: u32) -> &'static [u8] {
    let mut words = ash::util::read_spv(&mut std::io::Cursor::new(spirv)).unwrap();
    let mut at = 5;
    let mut moved = 0;
    while at < words.len() {
        let (count, opcode) = ((words[at] >> 16) as usize, words[at] & 0xffff);
        if opcode == 71 && count == 4 && words[at + 2] == 34 && words[at + 3] == 1 {
            words[at + 3] = set;
            moved += 1;
        }
        at += count;
    }
    assert!(moved > 0, "the module has no set 1 resources");
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    Box::leak(bytes.into_boxed_slice())
}

#[test]
fn hooks_that_are_not_spirv_are_refused() {
    let bindings = gbuffer_bindings(ALL_LIGHT_STAGES);
    let modules = LightModules {
        deferred_light: b"#version 460\nvoid main() {}\n",
        ..LightModules::BUILTIN
    };
    let err = refusal(hooks(modules, &bindings));
    assert!(err.contains("deferred_light: not SPIR-V"), "{err}");
    // Every module is checked, the tiled kernels too.
    let modules = LightModules {
        tile_shade_8: &[0x03, 0x02, 0x23, 0x07, 0],
        ..LightModules::BUILTIN
    };
    assert!(refusal(hooks(modules, &bindings)).contains("tile_shade_8"));
    // A module of another stage in a slot: no entry point for the pipeline that takes it.
    let modules = LightModules {
        deferred_light: LightModules::BUILTIN.tile_shade,
        ..LightModules::BUILTIN
    };
    let err = refusal(hooks(modules, &bindings));
    assert!(
        err.contains("deferred_light: a module of stage COMPUTE, where histencil's deferred_light is FRAGMENT"),
        "{err}"
    );
    hooks(LightModules::BUILTIN, &bindings).expect("histencil's own decode, rightly described");
}

#[test]
fn a_hook_that_reads_what_its_layout_lacks_is_refused_naming_set_binding_and_type() {
    let good = gbuffer_bindings(ALL_LIGHT_STAGES);
    let expect = |bindings: &[vk::DescriptorSetLayoutBinding], words: &str| {
        let err = refusal(hooks(LightModules::BUILTIN, bindings));
        assert!(err.contains(words), "{err}\nshould say: {words}");
    };
    // The case that crashed: a binding the layout does not have.
    expect(
        &good[..2],
        "deferred_light: reads set 1 binding 2 (`gbuffer_material`), a sampled image \
         (texture2D), and the decode layout (set 1) has no such binding",
    );
    let mut wrong_type = good.clone();
    wrong_type[1].descriptor_type = vk::DescriptorType::STORAGE_BUFFER;
    expect(&wrong_type, "binding 1 (`gbuffer_normal_depth`), a sampled image (texture2D), and the decode layout (set 1) declares it STORAGE_BUFFER");
    let mut no_descriptors = good.clone();
    no_descriptors[0].descriptor_count = 0;
    expect(&no_descriptors, "declares 0 descriptors there");
    let mut vertex_only = good.clone();
    vertex_only[0].stage_flags = vk::ShaderStageFlags::VERTEX;
    expect(&vertex_only, "makes it visible to VERTEX only");
    // A combined image sampler serves a separate sampled image (Vulkan's interface rules).
    let mut combined = good.clone();
    combined[2].descriptor_type = vk::DescriptorType::COMBINED_IMAGE_SAMPLER;
    hooks(LightModules::BUILTIN, &combined).expect("a combined image sampler serves");

    // A hook whose resources sit in set 4 with no visibility layout, and one in histencil's sets.
    for (set, words) in [
        (4, "set 4 binding 0 (`gbuffer_albedo`), a sampled image (texture2D), and the hooks have no visibility layout"),
        (2, "set 2 binding 0 (`gbuffer_albedo`), a sampled image (texture2D), and set 2 is histencil's"),
    ] {
        let modules = LightModules {
            lut_light: moved_to_set(LightModules::BUILTIN.lut_light, set),
            ..LightModules::BUILTIN
        };
        let err = refusal(hooks(modules, &good));
        assert!(err.starts_with("bad lighting setup: lut_light: reads"), "{err}");
        assert!(err.contains(words), "{err}");
    }
}

#[test]
fn an_engine_decode_set_lights_as_histencil_does_and_its_images_are_checked() {
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
        // The engine's decode set: its three G-buffer images, through a layout of its own for
        // histencil's decode, fragment stage only (no tiled).
        let images = engine.lighting_targets(extent, ds_format);
        let decode_set = engine.decode_set(&images, vk::ShaderStageFlags::FRAGMENT);
        let (set_layout, bindings) = (decode_set.layout, decode_set.bindings.clone());
        let decode = HookSetLayout {
            layout: set_layout,
            bindings: &bindings,
        };
        // SAFETY: the layout is made from `bindings`, on the lent device, and outlives the
        // lighting; the modules are histencil-vk's own.
        let hooks = unsafe {
            EngineHooks::new(
                LightModules::BUILTIN,
                decode,
                None,
                &histencil_vk::GBUFFER_FORMATS,
            )
        }
        .unwrap();
        let desc = |hooks| LightingDesc {
            hooks,
            ..lighting_desc(layout, brdfs.clone(), extent, ds_format, scene.lights.len())
        };
        let mut engines = DeferredLighting::new(&ctx, &desc(LightHooks::Engine(hooks))).unwrap();
        let mut histencils = DeferredLighting::new(&ctx, &desc(LightHooks::Builtin)).unwrap();
        let view = scene.camera.view_desc(width as f32 / height as f32);
        let plan = stencil_plan(&scene, &layout, &brdfs, &view, Backend::Ps3);

        // One frame: the G-buffer, then `lighting` with `hook_sets`, the HDR image read back.
        let readback = engine.readback_buffer(u64::from(width * height) * 8);
        let lit = |lighting: &mut DeferredLighting<&Context>, hook_sets: HookSets| {
            let mut targets = images.refs();
            let (pool, cmd) = engine.command_buffer();
            let frame = plain_frame(&view, &scene.lights, &plan, hook_sets);
            // SAFETY: recording on the lent device; each frame is waited for.
            unsafe {
                d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                    .unwrap();
                renderer.record_gbuffer(cmd, &mut targets).unwrap();
                lighting.record(cmd, &frame, &mut targets).unwrap();
                copy_to_buffer(d, cmd, &mut targets.hdr, readback.buffer);
                engine.submit_and_wait(pool, cmd);
                lighting.slot_finished(0).unwrap();
            }
            hdr_floats(readback.bytes())
        };
        let theirs = lit(
            &mut engines,
            HookSets {
                decode: Some(decode_set.set),
                visibility: None,
            },
        );
        let ours = lit(&mut histencils, HookSets::default());
        assert!(ours.iter().filter(|v| **v > 0.0).count() > ours.len() / 8);
        assert!(
            ours.iter()
                .zip(&theirs)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "the engine's decode set lit the frame differently"
        );

        // Misuse, each refused before anything is recorded.
        let (pool, cmd) = engine.command_buffer();
        unsafe { d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default()) }.unwrap();
        let hook_sets = HookSets {
            decode: Some(decode_set.set),
            visibility: None,
        };
        let frame = plain_frame(&view, &scene.lights, &plan, hook_sets);
        let mut refused = |mut targets: histencil_vk::LightingTargets, words: &str| {
            // SAFETY: refused before any command is recorded.
            let err = unsafe { engines.record(cmd, &frame, &mut targets) }.unwrap_err();
            assert!(matches!(err, Error::BadFrame(_)), "{err:?}");
            assert!(
                err.to_string().contains(words),
                "{err}\nshould say: {words}"
            );
        };
        let mut left_out = images.refs();
        left_out.gbuffer.clear();
        refused(
            left_out,
            "0 surface images in LightingTargets::gbuffer, and the engine's decode hook reads 3",
        );
        let mut swapped = images.refs();
        swapped.gbuffer.swap(0, 1);
        refused(
            swapped,
            "surface image 0 is R32G32B32A32_SFLOAT, the lighting expects R16G16B16A16_SFLOAT",
        );
        let tiled = TiledFrame {
            slot: 0,
            view: &view,
            lights: &scene.lights,
            clear_hdr: true,
            side: TileSide::Sixteen,
            mixed: MixedTiles::PerBrdf,
            classify: TileClassify::for_context(&ctx),
            hook_sets,
        };
        // SAFETY: refused before any command is recorded.
        let err = unsafe { engines.record_tiled(cmd, &tiled, &mut images.refs()) }.unwrap_err();
        assert!(
            err.to_string().contains("tile_classify (the tiled technique) reads set 1 binding 0 (`gbuffer_albedo`), a sampled image (texture2D) and the decode layout (set 1) makes it visible to FRAGMENT only, not COMPUTE"),
            "{err}"
        );
        // The depth-id technique classifies with the same kernels: refused the same way.
        // SAFETY: refused before any command is recorded.
        let err = unsafe { engines.record_depth_id(cmd, &tiled, &mut images.refs()) }.unwrap_err();
        assert!(
            err.to_string()
                .contains("tile_classify (the tiled technique) reads set 1 binding 0"),
            "{err}"
        );
        assert_eq!(
            engines.tiled_pipeline_count(),
            0,
            "refused before any kernel was made"
        );
        unsafe {
            d.end_command_buffer(cmd).unwrap();
            d.destroy_command_pool(pool, None);
            // Every frame was waited for and declared finished.
            engines.destroy().unwrap();
            histencils.destroy().unwrap();
        }
        decode_set.free(&engine);
        images.free(&engine);
        engine.free_buffer(readback);
        assert!(ctx.validation_log().is_empty(), "messages go to the engine");
    }
    engine.destroy().assert_clean();
}

/// One numbering: an engine names BRDF ids (its materials, its decode hook's `Surface::brdf`)
/// and takes each draw's stencil reference from the lighting's description, so the slot in
/// stencil and the id in the G-buffer cannot disagree; a BRDF in two slots is refused.
#[test]
fn an_engine_names_brdfs_and_the_lighting_gives_their_stencil_slots() {
    use histencil_brdf::BrdfId;
    use histencil_model::StencilLayout;
    histencil_tests::with_validated_context(|ctx| {
        let brdfs = vec![BrdfId::Ggx, BrdfId::Lambert, BrdfId::KajiyaKay];
        let layout = StencilLayout::new(3, 0).unwrap();
        let extent = vk::Extent2D {
            width: 16,
            height: 16,
        };
        let mut desc = LightingDesc {
            hi_stencil: false,
            ..lighting_desc(
                layout,
                brdfs.clone(),
                extent,
                ctx.depth_stencil_format().vk(),
                4,
            )
        };
        for (slot, brdf) in brdfs.iter().enumerate() {
            let reference = desc.stencil_reference(*brdf);
            assert_eq!(
                reference,
                histencil_vk::gbuffer_stencil_reference(&layout, slot as u32)
            );
            // One write mask for every BRDF: an engine's pipelines can bake it in.
            assert_eq!(reference.unwrap().1, desc.stencil_write_mask());
        }
        assert_eq!(
            desc.stencil_reference(BrdfId::PennerSkin),
            None,
            "not one of its BRDFs"
        );
        desc.brdfs = vec![BrdfId::Ggx, BrdfId::Lambert, BrdfId::Ggx];
        let err = DeferredLighting::new(ctx, &desc)
            .err()
            .expect("a BRDF in two slots");
        assert!(
            err.to_string()
                .contains("Ggx is in BRDF slots 0 and 2: one slot per BRDF"),
            "{err}"
        );
    });
}

/// An outside viewer's decode hook read its per-BRDF parameter rows for ids 0 to 7, as the book
/// sized them, while its own BRDFs took ids 8 and up: its toon wall came out unlit with no error
/// and no validation message. The lighting now holds what the hook says of its rows
/// (`EngineHooks::with_brdf_params`) against the ids it shades, at creation, naming both; a hook
/// that says nothing is taken to have the built-ins' 8 rows.
#[test]
fn a_decode_hook_without_rows_for_the_ids_the_lighting_shades_is_refused_at_creation() {
    use histencil_brdf::{BrdfId, EngineBrdf};
    use histencil_vk::BrdfParams;
    let toon = BrdfId::Engine(EngineBrdf::new(0, "toon"));
    let mut ids: Vec<u32> = BrdfId::ALL.iter().map(|b| b.index()).collect();
    ids.push(toon.index());
    let mut names: Vec<&'static str> = BrdfId::ALL.iter().map(|b| b.name()).collect();
    names.push("toon");
    // The modules' list of ids is what `DeferredLighting::new` holds a description to first;
    // every refusal below comes before any module or layout is used.
    let modules = LightModules {
        brdfs: Vec::leak(ids),
        brdf_names: Vec::leak(names),
        ..LightModules::BUILTIN
    };
    let engine = Engine::start();
    {
        // SAFETY: the engine's handles outlive the context; nothing else uses its queue.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.expect("context");
        let brdfs = vec![BrdfId::Lambert, toon];
        let layout = histencil_model::StencilLayout::new(2, 0).unwrap();
        let extent = vk::Extent2D {
            width: 16,
            height: 16,
        };
        let ds = ctx.depth_stencil_format().vk();
        let bindings = gbuffer_bindings(ALL_LIGHT_STAGES);
        let with = |params: Option<BrdfParams>| {
            let hooks = hooks(modules, &bindings).unwrap();
            let hooks = match params {
                Some(p) => hooks.with_brdf_params(p),
                None => hooks,
            };
            LightingDesc {
                hooks: LightHooks::Engine(hooks),
                ..lighting_desc(layout, brdfs.clone(), extent, ds, 1)
            }
        };
        let cases = [
            (None, "taken to have the built-ins' 8 rows"),
            (Some(BrdfParams::Rows(8)), "reads 8 BRDF rows"),
        ];
        for (params, words) in cases {
            match DeferredLighting::new(&ctx, &with(params)) {
                Err(e @ Error::BadSetup(_)) => {
                    let m = e.to_string();
                    assert!(
                        m.contains(words) && m.contains("`toon` (id 8)") && m.contains("unlit"),
                        "{m}"
                    );
                }
                Err(other) => panic!("{params:?}: {other}"),
                Ok(_) => panic!("{params:?}: a hook without toon's row was accepted"),
            }
        }
    }
    engine.destroy().assert_clean();
}

/// Parameters per material: rows indexed by a material index the G-buffer carries, each a BRDF
/// id and its parameters (`MaterialRows`, `BrdfParams::Materials`, the book's two-target
/// hook). Two materials of one BRDF are two rows and one BRDF to shade; rows naming a BRDF the
/// lighting does not shade are refused (`DeferredLighting::check_materials`), naming the
/// material, since its pixels would get no light pass and no error.
#[test]
fn material_rows_are_held_to_the_brdfs_the_lighting_shades() {
    use histencil_brdf::{Brdf, BrdfId, BrdfSet, MaterialRows};
    let set = BrdfSet::new(&BrdfId::ALL, vec![]).unwrap();
    let ggx = |alpha| Brdf::Ggx {
        alpha,
        f0: 0.04,
        f90: 1.0,
    };
    let rows = MaterialRows::new(&set, &[ggx(0.2), Brdf::Lambert { rho: 0.8 }, ggx(0.6)]).unwrap();
    assert_eq!(rows.brdfs(), [BrdfId::Ggx, BrdfId::Lambert]);
    let engine = Engine::start();
    {
        // SAFETY: the engine's handles outlive the context; nothing else uses its queue.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.expect("context");
        let layout = histencil_model::StencilLayout::new(2, 0).unwrap();
        let extent = vk::Extent2D {
            width: 16,
            height: 16,
        };
        let ds = ctx.depth_stencil_format().vk();
        let desc = lighting_desc(layout, rows.brdfs(), extent, ds, 1);
        let lighting = DeferredLighting::new(&ctx, &desc).expect("lighting");
        lighting
            .check_materials(&rows)
            .expect("every material's BRDF is shaded");
        let cloth = Brdf::OrenNayarFull {
            rho: 0.7,
            sigma: 0.3,
        };
        let more = MaterialRows::new(&set, &[ggx(0.2), Brdf::Lambert { rho: 0.8 }, cloth]).unwrap();
        let m = lighting.check_materials(&more).unwrap_err().to_string();
        assert!(
            m.contains("material 2 is `oren_nayar_full`") && m.contains("unlit"),
            "{m}"
        );
        drop(lighting);
        assert!(ctx.validation_log().is_empty());
    }
    engine.destroy().assert_clean();
}
