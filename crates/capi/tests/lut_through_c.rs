//! The talk's LUT technique through C: the engine's materials (BRDF names and parameters, as a C
//! engine has them) baked into tables by `histencil_lut_tables_create`, lent to a lighting, and a
//! PS3-like LUT frame lit bit for bit as the Rust API lights it with the renderer's own tables;
//! a LUT frame before any tables, tables set while a frame is in flight, and a material no
//! table can hold are refused with their reasons.

use ash::vk;
use histencil::{Backend, BrdfSource, DeferredLighting, HookSets, LightingFrame, TechniqueChoice};
use histencil_capi::*;
use histencil_tests::engine::{lighting_desc, plan};
mod common;

use common::{
    c_lighting_desc, expect, last_error, lit_frame, record_through_c, with_c_context, FrameInputs,
    SIZE,
};
use std::ffi::{c_char, CString};
use std::ptr::{null, null_mut};

#[test]
fn lut_frames_through_c_are_the_rust_apis_bit_for_bit() {
    use HistencilResult as R;
    with_c_context(|engine, renderer, c_ctx, images, world| {
        let names: Vec<*const c_char> = world.names.iter().map(|n| n.as_ptr()).collect();
        let ds = images.refs().depth_stencil.format;
        // The renderer's tables: what its G-buffer's material indices name, in that order; the C
        // tables are baked at the same resolution.
        let resolution = renderer.lut_resolution();
        let brdfs_of_tables: Vec<_> = (renderer.lut_tables().unwrap().luts().iter())
            .map(|l| l.brdf)
            .collect();
        // The same materials as a C engine names them.
        let material_names: Vec<CString> = (brdfs_of_tables.iter())
            .map(|b| CString::new(b.name()).unwrap())
            .collect();
        let params: Vec<Vec<HistencilBrdfParam>> = (brdfs_of_tables.iter())
            .map(|b| {
                (b.params().into_iter())
                    .map(|(name, value)| HistencilBrdfParam {
                        name: Box::leak(CString::new(name).unwrap().into_boxed_c_str()).as_ptr(),
                        value,
                    })
                    .collect()
            })
            .collect();
        let materials: Vec<HistencilMaterial> = (material_names.iter().zip(&params))
            .map(|(n, p)| HistencilMaterial {
                brdf_name: n.as_ptr(),
                param_count: p.len() as u32,
                params: p.as_ptr(),
            })
            .collect();

        let brdfs = renderer.brdfs().to_vec();
        let layout = *renderer.stencil_layout();
        let inputs = FrameInputs::new(world, &brdfs);
        let frame = inputs.frame(HISTENCIL_TECHNIQUE_LUT, HISTENCIL_PLATFORM_PS3);
        let readback = engine.readback_buffer(u64::from(SIZE.width * SIZE.height) * 8);

        // The Rust lighting with the renderer's tables.
        let rust_desc = lighting_desc(layout, brdfs.clone(), SIZE, ds, world.scene.lights.len());
        let mut rust = DeferredLighting::new(renderer.context(), &rust_desc).unwrap();
        // SAFETY: the renderer's tables outlive the frame below, which is waited for.
        unsafe { rust.set_lut_tables(renderer.lut_tables().unwrap()) };
        let branching = plan(
            &world.scene,
            &layout,
            &brdfs,
            &world.view,
            Backend::Ps3,
            TechniqueChoice::Branching,
        );
        let renderer = &*renderer;
        let ours = lit_frame(engine, renderer, images, &readback, &mut |cmd, targets| {
            let frame = LightingFrame {
                brdf_source: BrdfSource::Table,
                ..histencil_tests::engine::plain_frame(
                    &world.view,
                    &world.scene.lights,
                    &branching,
                    HookSets::default(),
                )
            };
            // SAFETY: a recording command buffer of the lent device, waited for.
            unsafe { rust.record(cmd, &frame, targets) }.unwrap();
        });
        // SAFETY: the frame was waited for.
        unsafe { rust.slot_finished(0) }.unwrap();
        rust.destroy().unwrap();

        // SAFETY: every call passes live handles and structs or ones the C API refuses; every
        // frame recorded is waited for before its slot is declared finished.
        unsafe {
            let desc = HistencilLightingDesc {
                depth_stencil_format: ds,
                ..c_lighting_desc(world, &names)
            };
            let mut lighting = null_mut();
            let r = histencil_lighting_create(c_ctx, &desc, &mut lighting);
            assert_eq!(r, R::Success, "{}", last_error());
            // A LUT frame before any tables: refused, nothing recorded.
            let (pool, cmd) = engine.command_buffer();
            let d = &engine.device;
            d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                .unwrap();
            let mut gbuffer = Vec::new();
            let targets = images.refs();
            let mut c_targets = common::c_targets_of(&targets, &mut gbuffer);
            let r = histencil_lighting_record(lighting, cmd, &frame, &mut c_targets);
            assert_ne!(r, R::Success, "a LUT frame without tables");
            assert!(last_error().contains("table"), "{}", last_error());
            d.end_command_buffer(cmd).unwrap();
            d.destroy_command_pool(pool, None);

            // The same materials as rows a decode hook reads by material index: written as
            // MaterialRows writes them, held to the lighting's BRDFs, and one of a BRDF the
            // lighting does not shade refused by name.
            let count = materials.len() as u32;
            let row = HISTENCIL_MATERIAL_ROW_BYTES as usize;
            let mut rows = vec![0u8; materials.len() * row];
            let r = histencil_material_rows_write(
                null(),
                materials.as_ptr(),
                count,
                rows.as_mut_ptr(),
                rows.len(),
            );
            assert_eq!(r, R::Success, "{}", last_error());
            let set = histencil::brdf::BrdfSet::new(&histencil::BrdfId::ALL, vec![]).unwrap();
            let expected = histencil::brdf::MaterialRows::new(&set, &brdfs_of_tables).unwrap();
            assert_eq!(rows, expected.bytes());
            let short = histencil_material_rows_write(
                null(),
                materials.as_ptr(),
                count,
                rows.as_mut_ptr(),
                rows.len() - 1,
            );
            assert_eq!(short, R::InvalidArgument, "{}", last_error());
            let r = histencil_lighting_check_materials(lighting, materials.as_ptr(), count);
            assert_eq!(r, R::Success, "{}", last_error());
            let candidates = [
                histencil::brdf::Brdf::KajiyaKay {
                    kd: 0.4,
                    ks: 0.6,
                    p: 30.0,
                },
                histencil::brdf::Brdf::Lambert { rho: 0.5 },
                histencil::brdf::Brdf::BlinnPhong { exponent: 16.0 },
            ];
            let other = (candidates.into_iter())
                .find(|b| !brdfs.contains(&b.id()))
                .expect("a built-in the lighting does not shade");
            let other_name = CString::new(other.name()).unwrap();
            let other_params: Vec<HistencilBrdfParam> = (other.params().into_iter())
                .map(|(name, value)| HistencilBrdfParam {
                    name: Box::leak(CString::new(name).unwrap().into_boxed_c_str()).as_ptr(),
                    value,
                })
                .collect();
            let unshaded = [
                materials[0],
                HistencilMaterial {
                    brdf_name: other_name.as_ptr(),
                    param_count: other_params.len() as u32,
                    params: other_params.as_ptr(),
                },
            ];
            let r = histencil_lighting_check_materials(lighting, unshaded.as_ptr(), 2);
            assert_eq!(r, R::BadSetup, "{}", last_error());
            let message = last_error();
            let words = format!("material 1 is `{}`", other.name());
            assert!(
                message.contains(&words) && message.contains("does not shade"),
                "{message}"
            );

            let mut tables = null_mut();
            let r = histencil_lut_tables_create(
                c_ctx,
                null(),
                materials.as_ptr(),
                materials.len() as u32,
                resolution,
                &mut tables,
            );
            assert_eq!(r, R::Success, "{}", last_error());
            let r = histencil_lighting_set_lut_tables(lighting, tables);
            assert_eq!(r, R::Success, "{}", last_error());
            let theirs = lit_frame(engine, renderer, images, &readback, &mut |cmd, targets| {
                record_through_c(lighting, cmd, &frame, targets);
                // Tables swapped while the frame is pending: refused.
                expect(
                    histencil_lighting_set_lut_tables(lighting, tables),
                    R::InFlight,
                    "frames in flight",
                );
            });
            assert_eq!(histencil_lighting_slot_finished(lighting, 0), R::Success);
            let lit_pixels = ours.chunks(4).filter(|p| p[..3].iter().any(|v| *v > 0.0));
            assert!(lit_pixels.count() > ours.len() / 16, "the LUT frame is lit");
            assert!(
                theirs
                    .iter()
                    .zip(&ours)
                    .all(|(a, b)| a.to_bits() == b.to_bits()),
                "the C API's LUT frame differs from Rust's"
            );
            // The tables may go at once: the lighting keeps what it bound until the context goes.
            assert_eq!(histencil_lut_tables_destroy(tables), R::Success);
            expect(
                histencil_lut_tables_destroy(tables),
                R::InvalidArgument,
                "not a live LutTables handle",
            );
            // glTF's metallic-roughness: its entries hold the tinted and the white factor. (Every
            // built-in has a table; the BRDFs no table holds are an engine's, `tint = true` or
            // `tangent = true`.) Then a resolution out of range.
            let metal = c"gltf_metal_rough";
            let metal_params = [
                HistencilBrdfParam {
                    name: c"alpha".as_ptr(),
                    value: 0.3,
                },
                HistencilBrdfParam {
                    name: c"metallic".as_ptr(),
                    value: 0.5,
                },
            ];
            let gltf = HistencilMaterial {
                brdf_name: metal.as_ptr(),
                param_count: 2,
                params: metal_params.as_ptr(),
            };
            let mut out = null_mut();
            let r = histencil_lut_tables_create(c_ctx, null(), &gltf, 1, 8, &mut out);
            assert_eq!(r, R::Success, "{}", last_error());
            assert_eq!(
                histencil_lut_tables_destroy(out),
                R::Success,
                "{}",
                last_error()
            );
            let r = histencil_lut_tables_create(c_ctx, null(), materials.as_ptr(), 1, 1, &mut out);
            assert_ne!(r, R::Success, "resolution 1");
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
