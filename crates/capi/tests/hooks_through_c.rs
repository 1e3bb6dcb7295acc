//! An engine's hooks through C, both ways a C engine gets them: compiled at run time from its
//! hook folder (`histencil_shaders_compile`) and read from the file `histencil shaders` wrote at
//! its build (`histencil_shaders_load`). A hook folder holding histencil's own decode, bound
//! through the engine's layout and set, lights every technique bit for bit as histencil's
//! built-in G-buffer does; a visibility hook of the engine's that shadows every light turns the
//! frame black; and what the engine can get wrong (no hooks for hooked shaders, a layout the
//! hooks do not fit, no decode set, a damaged or foreign file) is refused with its reason.

use ash::vk;
use histencil::{DeferredLighting, HookSets};
use histencil_capi::*;
use histencil_tests::engine::{lighting_desc, plain_frame, stencil_plan};
mod common;

use common::{
    c_lighting_desc, c_targets_of, expect, last_error, lit_frame, record_through_c, with_c_context,
    FrameInputs, SIZE,
};
use std::ffi::{c_char, CString};
use std::path::{Path, PathBuf};
use std::ptr::{null, null_mut};

const ALL_LIGHT_STAGES: vk::ShaderStageFlags = vk::ShaderStageFlags::from_raw(
    vk::ShaderStageFlags::FRAGMENT.as_raw() | vk::ShaderStageFlags::COMPUTE.as_raw(),
);

/// A fresh folder under the test output, emptied first.
fn folder(name: &str) -> PathBuf {
    let dir = histencil_tests::output_dir()
        .join("hooks-through-c")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Hook folders as an engine writes them: `copy` holds histencil's own decode (so its frames
/// must be histencil's, bit for bit), `dark` a visibility hook that shadows every light.
fn hook_folders() -> (PathBuf, PathBuf) {
    let own = Path::new(env!("CARGO_MANIFEST_DIR")).join("../vk/shaders/hooks/surface_decode.glsl");
    let copy = folder("copy");
    std::fs::copy(own, copy.join("surface_decode.glsl")).unwrap();
    let dark = folder("dark");
    std::fs::write(
        dark.join("light_visibility.glsl"),
        "#ifndef LIGHT_VISIBILITY_GLSL\n#define LIGHT_VISIBILITY_GLSL\n#include \"frame.glsl\"\n\
         #include \"surface.glsl\"\nfloat light_visibility(uint light_index, Light light, \
         Surface s) {\n    return 0.0;\n}\n#endif\n",
    )
    .unwrap();
    (copy, dark)
}

fn c_path(path: &Path) -> CString {
    CString::new(path.to_str().unwrap()).unwrap()
}

#[test]
fn hooks_compiled_at_run_time_or_read_from_a_file_light_as_histencil_does() {
    use HistencilResult as R;
    let (copy, dark) = hook_folders();
    let file = folder("file").join("histencil.shaders");
    // What `histencil shaders --hooks copy --out file` writes.
    let modules = histencil_vk::write_shader_file(None, Some(&copy), &file).unwrap();
    assert_eq!(
        modules, 14,
        "the eight light modules and six that evaluate a BRDF"
    );
    with_c_context(|engine, renderer, c_ctx, images, world| {
        let d = &engine.device;
        let names: Vec<*const c_char> = world.names.iter().map(|n| n.as_ptr()).collect();
        let ds = images.refs().depth_stencil.format;
        // The engine's decode set and layout: histencil's decode reads its three G-buffer images.
        let decode = engine.decode_set(images, ALL_LIGHT_STAGES);
        let (set_layout, bindings, decode_set) = (decode.layout, &decode.bindings, decode.set);
        let formats = histencil::GBUFFER_FORMATS;
        let hooks = HistencilHooks {
            size: size_of::<HistencilHooks>() as u32,
            decode_layout: set_layout,
            decode_binding_count: bindings.len() as u32,
            decode_bindings: bindings.as_ptr(),
            visibility_layout: vk::DescriptorSetLayout::null(),
            visibility_binding_count: 0,
            visibility_bindings: null(),
            surface_format_count: formats.len() as u32,
            surface_formats: formats.as_ptr(),
            // histencil's G-buffer carries each pixel's parameters.
            brdf_param_rows: 0,
        };

        let readback = engine.readback_buffer(u64::from(SIZE.width * SIZE.height) * 8);
        let brdfs = renderer.brdfs().to_vec();
        let inputs = FrameInputs::new(world, &brdfs);
        let frame = |technique, decode_set| HistencilFrame {
            decode_set,
            ..inputs.frame(technique, HISTENCIL_PLATFORM_PS3)
        };
        let lit = |record: &mut dyn FnMut(vk::CommandBuffer, &mut histencil::LightingTargets)| {
            lit_frame(engine, renderer, images, &readback, record)
        };
        let through_c = |lighting: *mut HistencilLighting, frame: HistencilFrame| {
            let out = lit(&mut |cmd, targets| record_through_c(lighting, cmd, &frame, targets));
            // SAFETY: the frame was waited for.
            let r = unsafe { histencil_lighting_slot_finished(lighting, 0) };
            assert_eq!(r, R::Success, "{}", last_error());
            out
        };

        // histencil's own lighting, through Rust: what the copied decode must give.
        let layout = *renderer.stencil_layout();
        let rust_desc = lighting_desc(layout, brdfs.clone(), SIZE, ds, world.scene.lights.len());
        let mut rust = DeferredLighting::new(renderer.context(), &rust_desc).unwrap();
        let plan = stencil_plan(
            &world.scene,
            &layout,
            &brdfs,
            &world.view,
            histencil::Backend::Ps3,
        );
        let ours = lit(&mut |cmd, targets| {
            let frame = plain_frame(&world.view, &world.scene.lights, &plan, HookSets::default());
            // SAFETY: as above.
            unsafe { rust.record(cmd, &frame, targets) }.unwrap();
        });
        // SAFETY: the frame was waited for.
        unsafe { rust.slot_finished(0) }.unwrap();
        let lit_pixels = ours
            .chunks(4)
            .filter(|p| p[..3].iter().any(|v| *v > 0.0))
            .count();
        assert!(
            lit_pixels > ours.len() / 16,
            "the frame is lit ({lit_pixels} pixels)"
        );
        let tiled_ours = lit(&mut |cmd, targets| {
            let tiled = world.rust_tiled_frame(renderer.context());
            // SAFETY: as above.
            unsafe { rust.record_tiled(cmd, &tiled, targets) }.unwrap();
        });
        // SAFETY: the frame was waited for.
        unsafe { rust.slot_finished(0) }.unwrap();
        rust.destroy().unwrap();

        // SAFETY: every call below passes live structs and handles, or ones the C API refuses;
        // every frame recorded is waited for before its slot is declared finished.
        unsafe {
            let (folder_c, dark_c, file_c) = (c_path(&copy), c_path(&dark), c_path(&file));
            let (mut compiled, mut read, mut shadowed) = (null_mut(), null_mut(), null_mut());
            let r = histencil_shaders_compile(c_ctx, null(), folder_c.as_ptr(), &mut compiled);
            assert_eq!(r, R::Success, "{}", last_error());
            let r = histencil_shaders_load(c_ctx, file_c.as_ptr(), &mut read);
            assert_eq!(r, R::Success, "{}", last_error());
            let r = histencil_shaders_compile(c_ctx, null(), dark_c.as_ptr(), &mut shadowed);
            assert_eq!(r, R::Success, "{}", last_error());
            let base = HistencilLightingDesc {
                depth_stencil_format: ds,
                hooks: &hooks,
                ..c_lighting_desc(world, &names)
            };
            for (shaders, how) in [
                (compiled, "compiled at run time"),
                (read, "read from a file"),
            ] {
                let desc = HistencilLightingDesc { shaders, ..base };
                let mut lighting = null_mut();
                let r = histencil_lighting_create(c_ctx, &desc, &mut lighting);
                assert_eq!(r, R::Success, "{how}: {}", last_error());
                let theirs = through_c(lighting, frame(HISTENCIL_TECHNIQUE_STENCIL, decode_set));
                assert!(
                    theirs
                        .iter()
                        .zip(&ours)
                        .all(|(a, b)| a.to_bits() == b.to_bits()),
                    "hooks {how}: the stencil frame differs from histencil's own"
                );
                let tiled = through_c(lighting, frame(HISTENCIL_TECHNIQUE_TILED, decode_set));
                assert!(
                    tiled
                        .iter()
                        .zip(&tiled_ours)
                        .all(|(a, b)| a.to_bits() == b.to_bits()),
                    "hooks {how}: the tiled frame differs from histencil's own"
                );
                // A frame without the decode set the hooks read is refused, nothing recorded.
                let (pool, cmd) = engine.command_buffer();
                d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                    .unwrap();
                let targets = images.refs();
                let mut gbuffer = Vec::new();
                let mut c_targets = c_targets_of(&targets, &mut gbuffer);
                let without = frame(HISTENCIL_TECHNIQUE_STENCIL, vk::DescriptorSet::null());
                let r = histencil_lighting_record(lighting, cmd, &without, &mut c_targets);
                assert_ne!(r, R::Success, "a frame without the decode set");
                assert!(last_error().contains("decode"), "{}", last_error());
                d.end_command_buffer(cmd).unwrap();
                d.destroy_command_pool(pool, None);
                assert_eq!(
                    histencil_lighting_destroy(lighting),
                    R::Success,
                    "{}",
                    last_error()
                );
            }
            // Shadowed by the engine's own visibility hook: every light reaches nothing.
            let desc = HistencilLightingDesc {
                shaders: shadowed,
                ..base
            };
            let mut lighting = null_mut();
            let r = histencil_lighting_create(c_ctx, &desc, &mut lighting);
            assert_eq!(r, R::Success, "{}", last_error());
            let dark_frame = through_c(lighting, frame(HISTENCIL_TECHNIQUE_STENCIL, decode_set));
            assert!(
                dark_frame.chunks(4).all(|p| p[..3] == [0.0; 3]),
                "shadowed, yet lit"
            );
            assert_eq!(
                histencil_lighting_destroy(lighting),
                R::Success,
                "{}",
                last_error()
            );

            // Hooked shaders without the layouts their resources are bound with.
            let no_hooks = HistencilLightingDesc {
                shaders: compiled,
                hooks: null(),
                ..base
            };
            expect(
                histencil_lighting_create(c_ctx, &no_hooks, &mut null_mut()),
                R::BadSetup,
                "HistencilLightingDesc.hooks",
            );
            // A layout the decode does not fit: its third image left out.
            let short = HistencilHooks {
                decode_binding_count: 2,
                ..hooks
            };
            let desc = HistencilLightingDesc {
                shaders: compiled,
                hooks: &short,
                ..base
            };
            expect(
                histencil_lighting_create(c_ctx, &desc, &mut null_mut()),
                R::BadSetup,
                "set 1 binding 2",
            );
            let unsized_hooks = HistencilHooks { size: 3, ..hooks };
            let desc = HistencilLightingDesc {
                shaders: compiled,
                hooks: &unsized_hooks,
                ..base
            };
            expect(
                histencil_lighting_create(c_ctx, &desc, &mut null_mut()),
                R::InvalidArgument,
                "HistencilHooks.size is 3",
            );
            // A hook folder with no hook, a damaged file, a file that is no shader file.
            let empty = c_path(&folder("empty"));
            expect(
                histencil_shaders_compile(c_ctx, null(), empty.as_ptr(), &mut null_mut()),
                R::BadSetup,
                "holds neither surface_decode.glsl nor light_visibility.glsl",
            );
            let mut bytes = std::fs::read(&file).unwrap();
            let last = bytes.len() - 10;
            bytes[last] ^= 0xff;
            let damaged = folder("damaged").join("histencil.shaders");
            std::fs::write(&damaged, &bytes).unwrap();
            let damaged_c = c_path(&damaged);
            expect(
                histencil_shaders_load(c_ctx, damaged_c.as_ptr(), &mut null_mut()),
                R::BadSetup,
                "damaged or cut",
            );
            let foreign = c_path(&copy.join("surface_decode.glsl"));
            expect(
                histencil_shaders_load(c_ctx, foreign.as_ptr(), &mut null_mut()),
                R::BadSetup,
                "not a histencil shader file",
            );
            for shaders in [compiled, read, shadowed] {
                assert_eq!(
                    histencil_shaders_destroy(shaders),
                    R::Success,
                    "{}",
                    last_error()
                );
            }
        }
        decode.free(engine);
        engine.free_buffer(readback);
    });
}

/// A shader file of an engine's BRDFs carries its folder: the set is read from it again, its
/// BRDFs light, and the includes an engine's own shaders need are written from it.
#[test]
fn a_shader_file_carries_the_engines_brdfs() {
    use HistencilResult as R;
    let brdfs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/brdfs");
    let file = folder("brdf-file").join("histencil.shaders");
    histencil_vk::write_shader_file(Some(&brdfs), None, &file).unwrap();
    with_c_context(|_, _, c_ctx, images, world| {
        // SAFETY: live handles and structs, NUL-terminated strings, writable out pointers.
        unsafe {
            let file_c = c_path(&file);
            let mut shaders = null_mut();
            let r = histencil_shaders_load(c_ctx, file_c.as_ptr(), &mut shaders);
            assert_eq!(r, R::Success, "{}", last_error());
            let names = [c"lambert", c"toon", c"charlie_sheen"];
            let pointers: Vec<*const c_char> = names.iter().map(|n| n.as_ptr()).collect();
            let desc = HistencilLightingDesc {
                shaders,
                depth_stencil_format: images.refs().depth_stencil.format,
                ..c_lighting_desc(world, &pointers)
            };
            let mut lighting = null_mut();
            let r = histencil_lighting_create(c_ctx, &desc, &mut lighting);
            assert_eq!(r, R::Success, "{}", last_error());
            let includes = folder("brdf-file-includes");
            let includes_c = c_path(&includes);
            let r = histencil_shaders_write_includes(shaders, includes_c.as_ptr());
            assert_eq!(r, R::Success, "{}", last_error());
            let ids = std::fs::read_to_string(includes.join("brdf_set/ids.glsl")).unwrap();
            assert!(ids.contains("TOON"), "{ids}");
            assert!(includes.join("engine/toon.glsl").is_file());
            assert_eq!(histencil_shaders_destroy(shaders), R::Success);
            assert_eq!(histencil_lighting_destroy(lighting), R::Success);
        }
    });
}
