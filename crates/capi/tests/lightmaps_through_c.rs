//! Lightmaps for translucent entities through C: a glass sphere, a glass box, a smoke column and
//! dust motes handed over as C structs are planned and lit into the engine's atlas bit for bit
//! as the Rust API lights them, plain and with a direction map; what a C engine can get wrong
//! (a mesh index past its vertices, an unknown kind, a BRDF the set lacks, an atlas too small,
//! destroying in flight) is refused with its reason and the process goes on.

use ash::vk;
use glam::Vec3;
use histencil::alpha::{plan_entities, scene_alpha_entities, ChoiceSettings, ProbeMeshes, Viewer};
use histencil::brdf::Brdf;
use histencil::scene::{ParticleLayout, Scene};
use histencil::{
    AlphaEntity, AlphaEntityKind, AlphaLightmaps, AlphaLightmapsDesc, Context, ImageState,
    LightmapFrame, Material,
};
use histencil_capi::*;
use histencil_tests::engine::{copy_to_buffer, Engine, EngineImage};
mod common;

use common::{device_desc, expect, last_error};
use std::ffi::CString;
use std::ptr::{null, null_mut};

const ATLAS: u32 = 256;
const HEIGHT: u32 = 240;
const FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

/// The `alpha` scene with a glass box and `dust`'s motes beside its sphere and smoke.
fn scene() -> Scene {
    let mut scene = histencil::scene::embedded("alpha").unwrap();
    let dust = histencil::scene::embedded("dust").unwrap();
    scene.particle_systems.extend(dust.particle_systems);
    let mut glass_box = scene.alpha_objects[0].clone();
    glass_box.shape = histencil::scene::Shape::Box;
    glass_box.transform = glam::Mat4::from_translation(Vec3::new(1.0, 1.2, 2.0))
        * glam::Mat4::from_scale(Vec3::splat(0.4));
    scene.alpha_objects.push(glass_box);
    scene
}

/// A material as a C engine gives it: its BRDF's name, parameters by name, and tint.
type CMaterial = (&'static str, &'static [(&'static str, f64)], [f32; 3]);

/// Each entity's material, alternating.
const MATERIALS: [CMaterial; 2] = [
    ("lambert", &[("rho", 0.8)], [0.9, 0.6, 0.3]),
    ("ggx", &[("alpha", 0.2), ("f0", 0.04)], [0.5, 0.7, 0.9]),
];

fn material(i: usize) -> Material {
    let (name, params, tint) = MATERIALS[i % 2];
    let map = params
        .iter()
        .map(|(k, v)| ((*k).to_owned(), serde_json::json!(v)))
        .collect();
    Material::new(Brdf::parse(name, &map).unwrap(), Vec3::from(tint))
}

/// The C engine's copies of `entities`: meshes, particles and parameter lists it owns.
struct CEntities {
    names: Vec<CString>,
    params: Vec<Vec<HistencilBrdfParam>>,
    vertices: Vec<Vec<HistencilVertex>>,
    meshes: Vec<HistencilMesh>,
    particles: Vec<Vec<HistencilParticle>>,
    entities: Vec<HistencilAlphaEntity>,
}

fn c_entities(entities: &[AlphaEntity]) -> CEntities {
    let mut out = CEntities {
        names: Vec::new(),
        params: Vec::new(),
        vertices: Vec::new(),
        meshes: Vec::new(),
        particles: Vec::new(),
        entities: Vec::new(),
    };
    for (i, _) in entities.iter().enumerate() {
        let (name, params, _) = MATERIALS[i % 2];
        out.names.push(CString::new(name).unwrap());
        let keys: Vec<CString> = params
            .iter()
            .map(|(k, _)| CString::new(*k).unwrap())
            .collect();
        // The names live as long as the test: leaked, as a C engine's string literals are.
        out.params.push(
            keys.into_iter()
                .zip(params)
                .map(|(k, (_, v))| HistencilBrdfParam {
                    name: Box::leak(k.into_boxed_c_str()).as_ptr(),
                    value: *v,
                })
                .collect(),
        );
    }
    for e in entities {
        match e.kind {
            AlphaEntityKind::Object { probe_mesh, .. } => {
                out.vertices.push(
                    (probe_mesh.vertices.iter())
                        .map(|v| HistencilVertex {
                            position: v.position,
                            normal: v.normal,
                            uv: v.uv,
                        })
                        .collect(),
                );
                out.particles.push(Vec::new());
            }
            AlphaEntityKind::Particles { particles, .. } => {
                out.vertices.push(Vec::new());
                out.particles.push(
                    (particles.iter())
                        .map(|p| HistencilParticle {
                            position: p.position.to_array(),
                            size: p.size,
                        })
                        .collect(),
                );
            }
        }
    }
    for (e, vertices) in entities.iter().zip(&out.vertices) {
        let indices = match e.kind {
            AlphaEntityKind::Object { probe_mesh, .. } => probe_mesh.indices.as_slice(),
            AlphaEntityKind::Particles { .. } => &[],
        };
        out.meshes.push(HistencilMesh {
            vertex_count: vertices.len() as u32,
            vertices: vertices.as_ptr(),
            index_count: indices.len() as u32,
            indices: indices.as_ptr(),
        });
    }
    for (i, e) in entities.iter().enumerate() {
        let (_, _, tint) = MATERIALS[i % 2];
        let mut c = HistencilAlphaEntity {
            kind: HISTENCIL_ENTITY_OBJECT,
            mesh: null(),
            transform: [0.0; 16],
            local_min: [0.0; 3],
            local_max: [0.0; 3],
            particle_layout: HISTENCIL_PARTICLES_BILLBOARD,
            slices: 0,
            particle_count: out.particles[i].len() as u32,
            particles: out.particles[i].as_ptr(),
            brdf_name: out.names[i].as_ptr(),
            param_count: out.params[i].len() as u32,
            params: out.params[i].as_ptr(),
            tint,
            opacity: e.opacity,
        };
        match e.kind {
            AlphaEntityKind::Object {
                transform,
                local_bounds: (lo, hi),
                ..
            } => {
                c.mesh = &out.meshes[i];
                c.transform = transform.to_cols_array();
                c.local_min = lo.to_array();
                c.local_max = hi.to_array();
            }
            AlphaEntityKind::Particles { layout, .. } => {
                c.kind = HISTENCIL_ENTITY_PARTICLES;
                (c.particle_layout, c.slices) = match layout {
                    ParticleLayout::Billboard => (HISTENCIL_PARTICLES_BILLBOARD, 0),
                    ParticleLayout::Slices { count } => (HISTENCIL_PARTICLES_SLICES, count),
                    ParticleLayout::Auto => (HISTENCIL_PARTICLES_AUTO, 0),
                    ParticleLayout::Dust => (HISTENCIL_PARTICLES_DUST, 0),
                    ParticleLayout::Ribbon => (HISTENCIL_PARTICLES_RIBBON, 0),
                };
            }
        }
        out.entities.push(c);
    }
    out
}

fn c_image(image: &EngineImage, state: ImageState) -> HistencilImage {
    common::c_image(&image.as_ref(state))
}

#[test]
fn lightmaps_through_c_are_the_rust_apis_bit_for_bit() {
    use HistencilResult as R;
    let scene = scene();
    let meshes = ProbeMeshes::new(&scene);
    let mut entities = scene_alpha_entities(&scene, &meshes);
    for (i, e) in entities.iter_mut().enumerate() {
        e.material = material(i);
    }
    assert!(entities.len() >= 4, "objects and particle systems");
    let c = c_entities(&entities);
    let view = scene.camera.view_desc(4.0 / 3.0);
    let world = common::World {
        view,
        scene: scene.clone(),
        names: Vec::new(),
    };
    let c_lights = world.c_lights();
    let engine = Engine::start();
    {
        // SAFETY: the engine's handles outlive the context; nothing else uses its queue.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.unwrap();
        use vk::ImageUsageFlags as U;
        let extent = vk::Extent2D {
            width: ATLAS,
            height: ATLAS,
        };
        let images: Vec<EngineImage> = ["atlas", "direction"]
            .map(|n| engine.image(n, FORMAT, extent, U::COLOR_ATTACHMENT | U::TRANSFER_SRC))
            .into();
        let bytes = u64::from(ATLAS * ATLAS) * 8;
        let readbacks = [engine.readback_buffer(bytes), engine.readback_buffer(bytes)];
        let d = &engine.device;
        let mut c_ctx = null_mut();
        // SAFETY: a live desc of the engine's live handles.
        let made = unsafe { histencil_context_create(&device_desc(&engine), &mut c_ctx) };
        assert_eq!(made, R::Success, "{}", last_error());
        // Runs `record` into a fresh command buffer, copies both images out, waits; their bytes.
        let lit = |record: &mut dyn FnMut(vk::CommandBuffer) -> [histencil::ImageRef; 2]| {
            let (pool, cmd) = engine.command_buffer();
            // SAFETY: the engine's command buffer, recorded here and waited for.
            unsafe {
                d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                    .unwrap();
                let [mut atlas, mut direction] = record(cmd);
                copy_to_buffer(d, cmd, &mut atlas, readbacks[0].buffer);
                copy_to_buffer(d, cmd, &mut direction, readbacks[1].buffer);
                engine.submit_and_wait(pool, cmd);
            }
            [readbacks[0].bytes(), readbacks[1].bytes()].concat()
        };
        let frame = HistencilLightmapFrame {
            size: size_of::<HistencilLightmapFrame>() as u32,
            slot: 0,
            view: world.c_view(),
            light_count: c_lights.len() as u32,
            lights: c_lights.as_ptr(),
            entity_count: c.entities.len() as u32,
            entities: c.entities.as_ptr(),
            viewport_height: HEIGHT,
        };
        let desc = HistencilLightmapsDesc {
            size: size_of::<HistencilLightmapsDesc>() as u32,
            shaders: null(),
            atlas_format: FORMAT,
            frames_in_flight: 1,
            direction_format: FORMAT,
        };
        // SAFETY: every call passes live handles and structs, or ones the C API refuses; each
        // frame is waited for before its slot is declared finished.
        unsafe {
            let mut lightmaps = null_mut();
            let r = histencil_lightmaps_create(c_ctx, &desc, &mut lightmaps);
            assert_eq!(r, R::Success, "{}", last_error());
            let mut rust = AlphaLightmaps::new(
                &ctx,
                &AlphaLightmapsDesc {
                    atlas_format: FORMAT,
                    frames_in_flight: 1,
                    direction_format: Some(FORMAT),
                },
            )
            .unwrap();
            let viewer = Viewer::from_view(&view).unwrap();
            let plan = plan_entities(
                &entities,
                &viewer,
                &scene.lights,
                HEIGHT,
                ATLAS,
                &ChoiceSettings::default(),
            )
            .unwrap();
            for directional in [false, true] {
                let through_c = lit(&mut |cmd| {
                    let mut atlas = c_image(&images[0], ImageState::UNDEFINED);
                    let mut direction = c_image(&images[1], ImageState::UNDEFINED);
                    let direction_ptr: *mut HistencilImage = if directional {
                        &mut direction
                    } else {
                        null_mut()
                    };
                    let r = histencil_lightmaps_record(
                        lightmaps,
                        cmd,
                        &frame,
                        &mut atlas,
                        direction_ptr,
                    );
                    assert_eq!(r, R::Success, "{}", last_error());
                    let mut refs = [
                        images[0].as_ref(ImageState::UNDEFINED),
                        images[1].as_ref(ImageState::UNDEFINED),
                    ];
                    for (r, c) in refs.iter_mut().zip([atlas, direction]) {
                        r.state = ImageState {
                            layout: c.layout,
                            stage: c.stage,
                            access: c.access,
                        };
                    }
                    if !directional {
                        refs[1] = images[1].as_ref(ImageState::UNDEFINED);
                    }
                    refs
                });
                let r = histencil_lightmaps_slot_finished(lightmaps, 0);
                assert_eq!(r, R::Success, "{}", last_error());
                let through_rust = lit(&mut |cmd| {
                    let rust_frame = LightmapFrame {
                        slot: 0,
                        view: &view,
                        lights: &scene.lights,
                        entities: &entities,
                        layout: &plan.layout,
                        timestamps: false,
                    };
                    let mut atlas = images[0].as_ref(ImageState::UNDEFINED);
                    let mut direction = images[1].as_ref(ImageState::UNDEFINED);
                    if directional {
                        rust.record_directional(cmd, &rust_frame, &mut atlas, &mut direction)
                            .unwrap();
                    } else {
                        rust.record(cmd, &rust_frame, &mut atlas).unwrap();
                    }
                    [atlas, direction]
                });
                rust.slot_finished(0).unwrap();
                let atlas_bytes = bytes as usize;
                let lit_texels = (through_rust[..atlas_bytes].chunks(8))
                    .filter(|t| t.iter().any(|b| *b != 0))
                    .count();
                assert!(lit_texels > 1000, "the atlas is lit ({lit_texels} texels)");
                let compared = if directional {
                    2 * atlas_bytes
                } else {
                    atlas_bytes
                };
                assert!(
                    through_c[..compared] == through_rust[..compared],
                    "directional {directional}: the C API's lightmaps differ from Rust's"
                );
            }
            let mut buffer = vk::Buffer::null();
            let r = histencil_lightmaps_entity_buffer(lightmaps, 0, &mut buffer);
            assert_eq!(r, R::Success, "{}", last_error());
            assert_ne!(buffer, vk::Buffer::null());
            expect(
                histencil_lightmaps_entity_buffer(lightmaps, 1, &mut buffer),
                R::BadFrame,
                "slot 1",
            );

            // Misuse, each refused before anything is recorded.
            let (pool, cmd) = engine.command_buffer();
            d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                .unwrap();
            let mut atlas = c_image(&images[0], ImageState::UNDEFINED);
            let object = c
                .entities
                .iter()
                .position(|e| e.kind == HISTENCIL_ENTITY_OBJECT);
            let object = object.expect("an object");
            let mut bad_mesh = c.meshes[object];
            let bad_indices = [0u32, 1, bad_mesh.vertex_count];
            bad_mesh.indices = bad_indices.as_ptr();
            bad_mesh.index_count = 3;
            let mut bad = c.entities.clone();
            bad[object].mesh = &bad_mesh;
            let with = |entities: &[HistencilAlphaEntity]| HistencilLightmapFrame {
                entities: entities.as_ptr(),
                entity_count: entities.len() as u32,
                ..frame
            };
            expect(
                histencil_lightmaps_record(lightmaps, cmd, &with(&bad), &mut atlas, null_mut()),
                R::InvalidArgument,
                "mesh.indices[2]",
            );
            let mut unknown = c.entities.clone();
            unknown[0].kind = 7;
            expect(
                histencil_lightmaps_record(lightmaps, cmd, &with(&unknown), &mut atlas, null_mut()),
                R::InvalidArgument,
                "entities[0].kind is 7",
            );
            let mut velvet = c.entities.clone();
            velvet[0].brdf_name = c"velvet".as_ptr();
            expect(
                histencil_lightmaps_record(lightmaps, cmd, &with(&velvet), &mut atlas, null_mut()),
                R::BadSetup,
                "velvet",
            );
            let mut opaque = c.entities.clone();
            opaque[0].opacity = 2.0;
            expect(
                histencil_lightmaps_record(lightmaps, cmd, &with(&opaque), &mut atlas, null_mut()),
                R::BadFrame,
                "opacity 2",
            );
            let mut tiny = atlas;
            tiny.width = 2;
            tiny.height = 2;
            expect(
                histencil_lightmaps_record(lightmaps, cmd, &frame, &mut tiny, null_mut()),
                R::BadFrame,
                "the lightmap atlas is full",
            );
            // A slot recorded and not declared finished: destroy is refused, the lightmaps stay.
            let r = histencil_lightmaps_record(lightmaps, cmd, &frame, &mut atlas, null_mut());
            assert_eq!(r, R::Success, "{}", last_error());
            expect(
                histencil_lightmaps_destroy(lightmaps),
                R::InFlight,
                "frames in flight",
            );
            d.end_command_buffer(cmd).unwrap();
            d.destroy_command_pool(pool, None);
            // Never submitted: finished at once.
            assert_eq!(histencil_lightmaps_slot_finished(lightmaps, 0), R::Success);
            assert_eq!(
                histencil_lightmaps_destroy(lightmaps),
                R::Success,
                "{}",
                last_error()
            );
            expect(
                histencil_lightmaps_destroy(lightmaps),
                R::InvalidArgument,
                "not a live Lightmaps handle",
            );
            rust.destroy().unwrap();
            assert_eq!(
                histencil_context_destroy(c_ctx),
                R::Success,
                "{}",
                last_error()
            );
        }
        for image in images {
            engine.free_image(image);
        }
        for readback in readbacks {
            engine.free_buffer(readback);
        }
    }
    engine.destroy().assert_clean();
}
