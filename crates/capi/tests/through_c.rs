//! The C API end to end, on lavapipe under the validation layer, called as a C engine calls it
//! (the `extern "C"` functions, handles and sized structs): its frames are the Rust API's, bit
//! for bit, on the talk's stencil technique (PS3-like, native) and the tiled one; and every
//! misuse a C engine can make returns its error code and a message naming the problem, with
//! the process going on and the layer silent.

use ash::vk;
use histencil::{Backend, DeferredLighting, HookSets};
use histencil_capi::*;
use histencil_tests::engine::{lighting_desc, plain_frame, stencil_plan};
mod common;

use common::{
    c_lighting_desc, c_targets_of, device_desc, expect, last_error, lit_frame, record_through_c,
    with_c_context, FrameInputs, SIZE,
};
use std::ffi::{c_char, CStr, CString};
use std::ptr::{null, null_mut};

#[test]
fn frames_lit_through_c_are_the_rust_apis_bit_for_bit() {
    with_c_context(|engine, renderer, c_ctx, images, world| {
        let ds = images.refs().depth_stencil.format;
        let names: Vec<*const c_char> = world.names.iter().map(|n| n.as_ptr()).collect();
        let desc = HistencilLightingDesc {
            depth_stencil_format: ds,
            ..c_lighting_desc(world, &names)
        };
        let mut c_lighting = null_mut();
        // SAFETY: a live context, a live desc whose names outlive the call.
        let made = unsafe { histencil_lighting_create(c_ctx, &desc, &mut c_lighting) };
        assert_eq!(made, HistencilResult::Success, "{}", last_error());
        // The Rust lighting, on the renderer's own context, made alike.
        let layout = *renderer.stencil_layout();
        let brdfs = renderer.brdfs().to_vec();
        let rust_desc = lighting_desc(layout, brdfs.clone(), SIZE, ds, world.scene.lights.len());
        let mut rust = DeferredLighting::new(renderer.context(), &rust_desc).unwrap();
        let readback = engine.readback_buffer(u64::from(SIZE.width * SIZE.height) * 8);
        let inputs = FrameInputs::new(world, &brdfs);
        let cases = [
            (
                HISTENCIL_TECHNIQUE_STENCIL,
                HISTENCIL_PLATFORM_PS3,
                Some(Backend::Ps3),
            ),
            (
                HISTENCIL_TECHNIQUE_STENCIL,
                HISTENCIL_PLATFORM_NATIVE,
                Some(Backend::Native),
            ),
            (
                HISTENCIL_TECHNIQUE_STENCIL,
                HISTENCIL_PLATFORM_X360_SAVE_RESTORE,
                Some(Backend::X360 {
                    zero_preserved: true,
                    save_restore: true,
                }),
            ),
            (HISTENCIL_TECHNIQUE_TILED, HISTENCIL_PLATFORM_NATIVE, None),
        ];
        for (technique, platform, backend) in cases {
            let lit =
                |record: &mut dyn FnMut(vk::CommandBuffer, &mut histencil::LightingTargets)| {
                    lit_frame(engine, renderer, images, &readback, record)
                };
            let frame = inputs.frame(technique, platform);
            let through_c =
                lit(&mut |cmd, targets| record_through_c(c_lighting, cmd, &frame, targets));
            // SAFETY: the frame was waited for.
            let r = unsafe { histencil_lighting_slot_finished(c_lighting, 0) };
            assert_eq!(r, HistencilResult::Success, "{}", last_error());
            let through_rust = lit(&mut |cmd, targets| {
                let tiled = world.rust_tiled_frame(renderer.context());
                // SAFETY: as above.
                unsafe {
                    match backend {
                        Some(backend) => {
                            let plan =
                                stencil_plan(&world.scene, &layout, &brdfs, &world.view, backend);
                            let frame = plain_frame(
                                &world.view,
                                &world.scene.lights,
                                &plan,
                                HookSets::default(),
                            );
                            rust.record(cmd, &frame, targets).unwrap();
                        }
                        None => rust.record_tiled(cmd, &tiled, targets).unwrap(),
                    }
                }
            });
            // SAFETY: the frame was waited for.
            unsafe { rust.slot_finished(0) }.unwrap();
            let lit_pixels = through_rust
                .chunks(4)
                .filter(|p| p[..3].iter().any(|v| *v > 0.0))
                .count();
            assert!(
                lit_pixels > through_rust.len() / 16,
                "the frame is lit ({lit_pixels} pixels)"
            );
            assert!(
                through_c
                    .iter()
                    .zip(&through_rust)
                    .all(|(a, b)| a.to_bits() == b.to_bits()),
                "technique {technique}, platform {platform}: the C API's frame differs from Rust's"
            );
        }
        rust.destroy().unwrap();
        // SAFETY: every frame was waited for and declared finished.
        let r = unsafe { histencil_lighting_destroy(c_lighting) };
        assert_eq!(r, HistencilResult::Success, "{}", last_error());
        engine.free_buffer(readback);
    });
}

#[test]
fn misuse_through_c_returns_its_error_and_names_the_problem() {
    use HistencilResult as R;
    with_c_context(|engine, renderer, c_ctx, images, world| {
        let names: Vec<*const c_char> = world.names.iter().map(|n| n.as_ptr()).collect();
        let ds = images.refs().depth_stencil.format;
        let good = HistencilLightingDesc {
            depth_stencil_format: ds,
            ..c_lighting_desc(world, &names)
        };
        let mut out = null_mut();
        // SAFETY: every call below passes null, a live struct or a live or freed handle, which
        // the C API refuses or uses; nothing is left dangling.
        unsafe {
            // Asked before the device is made: the engine's fits; a queue family it lacks does
            // not, and says why.
            let mut suits = 7;
            let gipa = Some(engine.entry.static_fn().get_instance_proc_addr);
            let (instance, physical) = (engine.instance.handle(), engine.physical_device);
            let r =
                histencil_device_suits(gipa, instance, physical, engine.queue_family, &mut suits);
            assert_eq!((r, suits), (R::Success, 1), "{}", last_error());
            let r = histencil_device_suits(gipa, instance, physical, 99, &mut suits);
            assert_eq!((r, suits), (R::Success, 0));
            assert!(last_error().contains("queue family 99"), "{}", last_error());
            // Null pointers and handles.
            expect(
                histencil_context_create(null(), &mut null_mut()),
                R::InvalidArgument,
                "desc is null",
            );
            expect(
                histencil_lighting_create(null_mut(), &good, &mut out),
                R::InvalidArgument,
                "context is null",
            );
            expect(
                histencil_lighting_create(c_ctx, null(), &mut out),
                R::InvalidArgument,
                "desc is null",
            );
            expect(
                histencil_lighting_create(c_ctx, &good, null_mut()),
                R::InvalidArgument,
                "out pointer",
            );
            let mut desc = device_desc(engine);
            desc.device = vk::Device::null();
            expect(
                histencil_context_create(&desc, &mut null_mut()),
                R::InvalidArgument,
                "device is VK_NULL_HANDLE",
            );
            desc = device_desc(engine);
            desc.get_instance_proc_addr = None;
            expect(
                histencil_context_create(&desc, &mut null_mut()),
                R::InvalidArgument,
                "get_instance_proc_addr is null",
            );
            // A wrong struct size, counts out of range, a null array with a count, a BRDF
            // histencil lacks.
            let unknown = CString::new("velvet").unwrap();
            let mut wrong = names.clone();
            wrong[0] = unknown.as_ptr();
            let bad_descs = [
                (
                    HistencilLightingDesc { size: 12, ..good },
                    R::InvalidArgument,
                    "HistencilLightingDesc.size is 12",
                ),
                (
                    HistencilLightingDesc {
                        brdf_count: 0,
                        ..good
                    },
                    R::InvalidArgument,
                    "brdf_count is 0",
                ),
                (
                    HistencilLightingDesc {
                        brdf_names: null(),
                        ..good
                    },
                    R::InvalidArgument,
                    "brdf_names is null",
                ),
                (
                    HistencilLightingDesc {
                        brdf_names: wrong.as_ptr(),
                        ..good
                    },
                    R::BadSetup,
                    "no BRDF named `velvet`",
                ),
                (
                    HistencilLightingDesc {
                        frames_in_flight: 99,
                        ..good
                    },
                    R::InvalidArgument,
                    "frames_in_flight is 99",
                ),
                (
                    HistencilLightingDesc {
                        engine_stencil_bits: 7,
                        ..good
                    },
                    R::BadSetup,
                    "bits",
                ),
                // An HDR format no light pass can blend into: refused at creation (an outside
                // trial's was accepted, then failed the validation layer at the first frame).
                (
                    HistencilLightingDesc {
                        hdr_format: vk::Format::UNDEFINED,
                        ..good
                    },
                    R::BadSetup,
                    "HDR format UNDEFINED",
                ),
                (
                    HistencilLightingDesc {
                        hdr_format: vk::Format::D32_SFLOAT,
                        ..good
                    },
                    R::BadSetup,
                    "cannot blend into it",
                ),
            ];
            for (desc, code, words) in bad_descs {
                expect(
                    histencil_lighting_create(c_ctx, &desc, &mut out),
                    code,
                    words,
                );
            }
            // A lighting, then a frame with each thing wrong.
            let mut lighting = null_mut();
            assert_eq!(
                histencil_lighting_create(c_ctx, &good, &mut lighting),
                R::Success,
                "{}",
                last_error()
            );
            let (mut r, mut m) = (0u8, 0u8);
            expect(
                histencil_lighting_stencil_reference(lighting, unknown.as_ptr(), &mut r, &mut m),
                R::BadSetup,
                "velvet",
            );
            let mut targets = images.refs();
            let mut gbuffer = Vec::new();
            let mut c_targets = c_targets_of(&targets, &mut gbuffer);
            let lights = world.c_lights();
            let empty: Vec<HistencilBrdfBounds> = names
                .iter()
                .map(|_| HistencilBrdfBounds {
                    boxes: null(),
                    box_count: 0,
                })
                .collect();
            let frame = HistencilFrame {
                size: size_of::<HistencilFrame>() as u32,
                slot: 0,
                technique: HISTENCIL_TECHNIQUE_STENCIL,
                platform: HISTENCIL_PLATFORM_PS3,
                view: world.c_view(),
                light_count: lights.len() as u32,
                lights: lights.as_ptr(),
                brdf_bounds_count: empty.len() as u32,
                brdf_bounds: empty.as_ptr(),
                clear_hdr: 1,
                decode_set: vk::DescriptorSet::null(),
                visibility_set: vk::DescriptorSet::null(),
                timestamps: 0,
            };
            let (pool, cmd) = engine.command_buffer();
            let d = &engine.device;
            d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                .unwrap();
            let bad_frames: [(HistencilFrame, R, &str); 7] = [
                (
                    HistencilFrame { size: 4, ..frame },
                    R::InvalidArgument,
                    "HistencilFrame.size is 4",
                ),
                (
                    HistencilFrame {
                        technique: 77,
                        ..frame
                    },
                    R::InvalidArgument,
                    "technique is 77",
                ),
                (
                    HistencilFrame {
                        platform: 9,
                        ..frame
                    },
                    R::InvalidArgument,
                    "platform is 9",
                ),
                (
                    HistencilFrame { slot: 3, ..frame },
                    R::BadFrame,
                    "slot 3 of 1 frames in flight",
                ),
                (
                    HistencilFrame {
                        lights: null(),
                        ..frame
                    },
                    R::InvalidArgument,
                    "lights is null",
                ),
                (
                    HistencilFrame {
                        brdf_bounds_count: 1,
                        ..frame
                    },
                    R::InvalidArgument,
                    "brdf_bounds_count is 1",
                ),
                (
                    HistencilFrame {
                        light_count: u32::MAX,
                        ..frame
                    },
                    R::InvalidArgument,
                    "light_count is 4294967295",
                ),
            ];
            for (bad, code, words) in bad_frames {
                expect(
                    histencil_lighting_record(lighting, cmd, &bad, &mut c_targets),
                    code,
                    words,
                );
            }
            let mut spot = lights.clone();
            spot[0].kind = 5;
            let bad_light = HistencilFrame {
                lights: spot.as_ptr(),
                ..frame
            };
            expect(
                histencil_lighting_record(lighting, cmd, &bad_light, &mut c_targets),
                R::InvalidArgument,
                "lights[0].kind is 5",
            );
            expect(
                histencil_lighting_record(
                    lighting,
                    vk::CommandBuffer::null(),
                    &frame,
                    &mut c_targets,
                ),
                R::InvalidArgument,
                "command_buffer",
            );
            expect(
                histencil_lighting_record(lighting, cmd, &frame, null_mut()),
                R::InvalidArgument,
                "targets is null",
            );
            // A frame recorded: the slot is in flight until declared finished.
            renderer.record_gbuffer(cmd, &mut targets).unwrap();
            c_targets = c_targets_of(&targets, &mut gbuffer);
            assert_eq!(
                histencil_lighting_record(lighting, cmd, &frame, &mut c_targets),
                R::Success,
                "{}",
                last_error()
            );
            let mut in_flight = 0;
            assert_eq!(
                histencil_lighting_in_flight(lighting, &mut in_flight),
                R::Success
            );
            assert_eq!(in_flight, 1);
            expect(
                histencil_lighting_record(lighting, cmd, &frame, &mut c_targets),
                R::InFlight,
                "slot_finished(0)",
            );
            expect(
                histencil_lighting_resize(lighting, 64, 64),
                R::InFlight,
                "resize while slot 0",
            );
            expect(
                histencil_lighting_destroy(lighting),
                R::InFlight,
                "histencil_lighting_slot_finished",
            );
            expect(
                histencil_context_destroy(c_ctx),
                R::InFlight,
                "1 lighting(s)",
            );
            engine.submit_and_wait(pool, cmd);
            assert_eq!(histencil_lighting_slot_finished(lighting, 0), R::Success);
            expect(
                histencil_lighting_slot_finished(lighting, 1),
                R::BadFrame,
                "slot_finished(1) of 1",
            );
            expect(
                histencil_lighting_resize(lighting, 1 << 20, 8),
                R::DeviceLimit,
                "maxImageDimension2D",
            );
            expect(
                histencil_lighting_resize(lighting, 0, 8),
                R::BadSetup,
                "0x8",
            );
            assert_eq!(
                histencil_lighting_destroy(lighting),
                R::Success,
                "{}",
                last_error()
            );
            // The freed handle, and a handle of the wrong kind, are refused, not used.
            expect(
                histencil_lighting_destroy(lighting),
                R::InvalidArgument,
                "not a live Lighting handle",
            );
            expect(
                histencil_lighting_resize(c_ctx.cast(), 8, 8),
                R::InvalidArgument,
                "not a live Lighting handle",
            );
            expect(
                histencil_lighting_in_flight(lighting, &mut in_flight),
                R::InvalidArgument,
                "not a live",
            );
        }
        // The message of a success-only call leaves the last error as it was; a fresh thread
        // has none.
        let fresh = std::thread::spawn(last_error).join().unwrap();
        assert_eq!(fresh, "");
        assert!(histencil_version() >> 22 == HISTENCIL_VERSION_MAJOR);
    });
}

/// An engine's own BRDFs through C: `examples/brdfs` (a toon ramp, glTF's Charlie sheen) loaded,
/// compiled and probed on the context's device; a lighting made with them beside histencil's
/// own, their stencil references given; their G-buffer values as the Rust API's; and a folder or
/// name histencil refuses says why.
#[test]
fn an_engines_own_brdfs_come_through_c_from_its_folder() {
    use HistencilResult as R;
    with_c_context(|_, _, c_ctx, images, world| {
        let folder = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/brdfs\0");
        let mut set = null_mut();
        // SAFETY: a live context, a NUL-terminated folder, a writable out pointer; every call
        // below passes live structs and handles, or ones the C API refuses.
        unsafe {
            let loaded = histencil_shaders_compile(c_ctx, folder.as_ptr().cast(), null(), &mut set);
            assert_eq!(loaded, R::Success, "{}", last_error());
            let missing = c"/nonexistent/brdfs";
            expect(
                histencil_shaders_compile(c_ctx, missing.as_ptr(), null(), &mut null_mut()),
                R::BadSetup,
                "/nonexistent/brdfs",
            );
            let names = [c"lambert", c"toon", c"charlie_sheen"];
            let pointers: Vec<*const c_char> = names.iter().map(|n| n.as_ptr()).collect();
            let desc = HistencilLightingDesc {
                shaders: set,
                depth_stencil_format: images.refs().depth_stencil.format,
                ..c_lighting_desc(world, &pointers)
            };
            let mut lighting = null_mut();
            let made = histencil_lighting_create(c_ctx, &desc, &mut lighting);
            assert_eq!(made, R::Success, "{}", last_error());
            let (mut reference, mut mask) = (0u8, 0u8);
            let r = histencil_lighting_stencil_reference(
                lighting,
                c"toon".as_ptr(),
                &mut reference,
                &mut mask,
            );
            assert_eq!(r, R::Success, "{}", last_error());
            assert_ne!(mask, 0);
            // Without the set, histencil does not know `toon`.
            let own = HistencilLightingDesc {
                shaders: null(),
                ..desc
            };
            expect(
                histencil_lighting_create(c_ctx, &own, &mut null_mut()),
                R::BadSetup,
                "no BRDF named `toon`",
            );
            // The G-buffer's values, as the Rust set gives them.
            let rust_set =
                histencil::brdf::BrdfSet::load(folder.trim_end_matches('\0').as_ref()).unwrap();
            let expected = rust_set.engine_brdf("toon", &[("bands", 4.0)]).unwrap();
            let bands = HistencilBrdfParam {
                name: c"bands".as_ptr(),
                value: 4.0,
            };
            let (mut packed, mut id) = ([0.0f32; 4], 0u32);
            let r = histencil_brdf_encode(
                set,
                c"toon".as_ptr(),
                &bands,
                1,
                packed.as_mut_ptr(),
                &mut id,
            );
            assert_eq!(r, R::Success, "{}", last_error());
            assert_eq!(id, expected.id().index());
            assert_eq!(packed, expected.packed_params().map(|p| p as f32));
            expect(
                histencil_brdf_encode(
                    null(),
                    c"toon".as_ptr(),
                    &bands,
                    1,
                    packed.as_mut_ptr(),
                    &mut id,
                ),
                R::BadSetup,
                "toon",
            );
            let huge = HistencilBrdfParam {
                name: c"bands".as_ptr(),
                value: 1e9,
            };
            expect(
                histencil_brdf_encode(
                    set,
                    c"toon".as_ptr(),
                    &huge,
                    1,
                    packed.as_mut_ptr(),
                    &mut id,
                ),
                R::BadSetup,
                "bands",
            );
            // The set's GLSL for the engine's own shaders (a forward reference).
            let out = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("c-set-includes");
            let out_c = CString::new(out.to_str().unwrap()).unwrap();
            let r = histencil_shaders_write_includes(set, out_c.as_ptr());
            assert_eq!(r, R::Success, "{}", last_error());
            let ids = std::fs::read_to_string(out.join("brdf_set/ids.glsl")).unwrap();
            assert!(ids.contains("#define BRDF_ENGINE_TOON 8u"), "{ids}");
            let r = histencil_lighting_destroy(lighting);
            assert_eq!(r, R::Success, "{}", last_error());
            assert_eq!(histencil_shaders_destroy(set), R::Success);
            expect(
                histencil_shaders_destroy(set),
                R::InvalidArgument,
                "not a live Shaders handle",
            );
        }
    });
}

/// GPU timings through C: a frame recorded with `timestamps` reports its step groups' times
/// once finished, by the count-then-fill convention; a frame without reports none.
#[test]
fn step_timings_come_through_c_by_group() {
    use HistencilResult as R;
    with_c_context(|engine, renderer, c_ctx, images, world| {
        let names: Vec<*const c_char> = world.names.iter().map(|n| n.as_ptr()).collect();
        let desc = HistencilLightingDesc {
            depth_stencil_format: images.refs().depth_stencil.format,
            ..c_lighting_desc(world, &names)
        };
        let inputs = FrameInputs::new(world, renderer.brdfs());
        let readback = engine.readback_buffer(u64::from(SIZE.width * SIZE.height) * 8);
        // SAFETY: live handles and structs; each frame is waited for before its slot is
        // declared finished and its timings read.
        unsafe {
            let mut lighting = null_mut();
            let r = histencil_lighting_create(c_ctx, &desc, &mut lighting);
            assert_eq!(r, R::Success, "{}", last_error());
            for timed in [1, 0] {
                let frame = HistencilFrame {
                    timestamps: timed,
                    ..inputs.frame(HISTENCIL_TECHNIQUE_STENCIL, HISTENCIL_PLATFORM_PS3)
                };
                lit_frame(engine, renderer, images, &readback, &mut |cmd, targets| {
                    record_through_c(lighting, cmd, &frame, targets)
                });
                assert_eq!(histencil_lighting_slot_finished(lighting, 0), R::Success);
                let mut count = 0;
                let r = histencil_lighting_step_timings(lighting, 0, null_mut(), &mut count);
                assert_eq!(r, R::Success, "{}", last_error());
                if timed == 0 {
                    assert_eq!(count, 0, "an untimed frame reports no times");
                    continue;
                }
                assert!(count > 2, "setup, masks and shades: {count} groups");
                let mut times = vec![
                    HistencilStepTime {
                        group: null(),
                        ms: -1.0
                    };
                    count as usize
                ];
                let r =
                    histencil_lighting_step_timings(lighting, 0, times.as_mut_ptr(), &mut count);
                assert_eq!(r, R::Success, "{}", last_error());
                let groups: Vec<String> = (times.iter())
                    .map(|t| CStr::from_ptr(t.group).to_string_lossy().into_owned())
                    .collect();
                assert!(
                    times.iter().all(|t| t.ms.is_finite() && t.ms >= 0.0),
                    "{groups:?}"
                );
                assert!(groups.iter().any(|g| g.contains("shade")), "{groups:?}");
            }
            expect(
                histencil_lighting_step_timings(lighting, 5, null_mut(), &mut 0),
                R::BadFrame,
                "slot 5",
            );
            assert_eq!(
                histencil_lighting_destroy(lighting),
                R::Success,
                "{}",
                last_error()
            );
        }
        engine.free_buffer(readback);
    });
}
