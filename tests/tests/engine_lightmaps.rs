//! histencil's alpha lightmaps recorded into an engine's frames: the test plays the engine (its
//! own device, allocator, atlas, command pools and fences, two frames in flight), hands over its
//! translucent objects and particle systems as plain values each frame, plans their regions on
//! plain data and records `AlphaLightmaps` into its own command buffers. The same state recorded
//! through the other slot, after frames that moved the lights and grew every buffer, gives the
//! same atlas bit for bit; texels outside every region stay black; frames that do not fit are
//! refused before anything is recorded. Validation with synchronisation validation sees nothing.

use ash::vk;
use glam::Vec3;
use histencil_alpha::{
    plan_regions, scene_alpha_entities as entities, EntityRegion, LightmapLayout, ProbeMeshes,
    Viewer,
};
use histencil_scene::{Light, ParticleLayout, Scene, Shape};
use histencil_tests::engine::{copy_to_buffer, Engine, EngineBuffer, EngineImage};
use histencil_vk::{
    AlphaEntity, AlphaEntityKind, AlphaLightmaps, AlphaLightmapsDesc, Context, Error, ImageRef,
    ImageState, LightmapFrame, LightmapTimings,
};

const HEIGHT: u32 = 240;
const ATLAS: u32 = 512;
const FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
static NAN_PARTICLE: [histencil_scene::Particle; 1] = [histencil_scene::Particle {
    position: Vec3::NAN,
    size: 0.1,
}];

/// Every kind of entity: the glass sphere and smoke column of `alpha`, a box, `dust` and
/// `ribbon`'s systems, `volume`'s slices.
fn all_kinds() -> Scene {
    let mut scene = histencil_scene::embedded("alpha").unwrap();
    for name in ["dust", "ribbon", "volume"] {
        let other = histencil_scene::embedded(name).unwrap();
        scene.particle_systems.extend(other.particle_systems);
        scene.lights.extend(other.lights);
    }
    let mut glass_box = scene.alpha_objects[0].clone();
    glass_box.shape = Shape::Box;
    glass_box.transform = glam::Mat4::from_translation(Vec3::new(1.0, 1.2, 2.0))
        * glam::Mat4::from_scale(Vec3::splat(0.4));
    scene.alpha_objects.push(glass_box);
    scene
}

/// The lights at frame `f`: each moved along its own circle.
fn lights_at(scene: &Scene, f: usize) -> Vec<Light> {
    scene
        .lights
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let angle = 0.9 * f as f32 + i as f32;
            Light {
                position: l.position + Vec3::new(angle.cos(), 0.0, angle.sin()) * 0.5,
                ..*l
            }
        })
        .collect()
}

fn layout_for(scene: &Scene, entities: &[AlphaEntity]) -> LightmapLayout {
    let view = scene.camera.view_desc(4.0 / 3.0);
    let viewer = Viewer::from_view(&view).unwrap();
    let descs: Vec<_> = entities.iter().map(AlphaEntity::desc).collect();
    plan_regions(&descs, &viewer, HEIGHT, ATLAS).unwrap()
}

/// Records one frame of lightmaps into `cmd` (begun here, ended here) and, when `readback` is
/// given, copies the atlas into it.
#[allow(clippy::too_many_arguments)]
unsafe fn record_frame(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    lightmaps: &mut AlphaLightmaps<&Context>,
    frame: &LightmapFrame,
    atlas: &mut ImageRef,
    readback: Option<&EngineBuffer>,
) {
    d.begin_command_buffer(
        cmd,
        &vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
    )
    .unwrap();
    lightmaps.record(cmd, frame, atlas).unwrap();
    assert_eq!(
        atlas.state.layout,
        vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL
    );
    if let Some(buffer) = readback {
        copy_to_buffer(d, cmd, atlas, buffer.buffer);
    }
    d.end_command_buffer(cmd).unwrap();
}

#[test]
fn an_engine_lights_its_alpha_entities_with_two_frames_in_flight() {
    let scene = all_kinds();
    let meshes = ProbeMeshes::new(&scene);
    // A smaller first state, so the later frames grow every buffer of both slots.
    let mut small = scene.clone();
    small.particle_systems.truncate(1);
    small.alpha_objects.truncate(1);
    let engine = Engine::start();
    {
        // SAFETY: the engine's handles outlive the context; nothing else uses its queue.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.expect("context");
        let mut lightmaps = AlphaLightmaps::new(
            &ctx,
            &AlphaLightmapsDesc {
                atlas_format: FORMAT,
                frames_in_flight: 2,
                direction_format: None,
            },
        )
        .unwrap();
        use vk::ImageUsageFlags as U;
        let extent = vk::Extent2D {
            width: ATLAS,
            height: ATLAS,
        };
        let atlas_image = engine.image(
            "atlas",
            FORMAT,
            extent,
            U::COLOR_ATTACHMENT | U::TRANSFER_SRC,
        );
        let mut atlas = atlas_image.as_ref(ImageState::UNDEFINED);
        let bytes = u64::from(ATLAS * ATLAS) * 8;
        let (first, last) = (engine.readback_buffer(bytes), engine.readback_buffer(bytes));
        let d = &engine.device;
        let queue = unsafe { d.get_device_queue(engine.queue_family, 0) };
        let slots = engine.frame_slots(2);
        let view = scene.camera.view_desc(4.0 / 3.0);
        // Frames 0 and 5 light the same state through slots 0 and 1; between them the lights
        // move and the entities grow from two to six.
        let states = [0usize, 1, 2, 3, 4, 0];
        let mut draws = Vec::new();
        let mut layouts = Vec::new();
        for (f, &state) in states.iter().enumerate() {
            let source = if f == 0 { &small } else { &scene };
            let entities = entities(source, &meshes);
            let layout = layout_for(source, &entities);
            let lights = lights_at(source, state);
            let slot = f % 2;
            let (pool, cmd, fence) = slots[slot];
            let frame = LightmapFrame {
                slot: slot as u32,
                view: &view,
                lights: &lights,
                entities: &entities,
                layout: &layout,
                // Slot 1's frames are timed; of slot 0's only the first, whose times its
                // later untimed frames must not report.
                timestamps: slot == 1 || f == 0,
            };
            let readback = match f {
                0 => Some(&first),
                5 => Some(&last),
                _ => None,
            };
            unsafe {
                d.wait_for_fences(&[fence], true, u64::MAX).unwrap();
                lightmaps.slot_finished(slot as u32).unwrap();
                d.reset_fences(&[fence]).unwrap();
                d.reset_command_pool(pool, vk::CommandPoolResetFlags::empty())
                    .unwrap();
                record_frame(d, cmd, &mut lightmaps, &frame, &mut atlas, readback);
                let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
                let submit = vk::SubmitInfo2::default().command_buffer_infos(&cmds);
                d.queue_submit2(queue, &[submit], fence).unwrap();
            }
            draws.push(lightmaps.draws(slot as u32));
            layouts.push(layout);
        }
        let fences: Vec<_> = slots.iter().map(|s| s.2).collect();
        unsafe { d.wait_for_fences(&fences, true, u64::MAX) }.unwrap();
        for slot in 0..slots.len() as u32 {
            // SAFETY: every slot's fence was waited for just above.
            unsafe { lightmaps.slot_finished(slot) }.unwrap();
        }
        assert_eq!(
            lightmaps.timings(0).unwrap(),
            None,
            "slot 0's last frame was not timed"
        );
        assert_timed(&lightmaps.timings(1).unwrap().expect("slot 1 was timed"), 6);
        assert!(draws.iter().all(|&n| n > 0), "{draws:?}");
        assert!(
            draws[1] > draws[0],
            "the later frames light more: {draws:?}"
        );

        // Frame 0 (slot 0, two entities) is not frame 5 (slot 1, six); frame 5 against a frame
        // of the same six entities through slot 0 is the bit-for-bit check.
        let entities6 = entities(&scene, &meshes);
        let layout6 = layout_for(&scene, &entities6);
        let lights0 = lights_at(&scene, 0);
        let (pool, cmd, fence) = slots[0];
        let again = engine.readback_buffer(bytes);
        let frame = LightmapFrame {
            slot: 0,
            view: &view,
            lights: &lights0,
            entities: &entities6,
            layout: &layout6,
            // Timestamps change no texel.
            timestamps: true,
        };
        unsafe {
            d.reset_fences(&[fence]).unwrap();
            d.reset_command_pool(pool, vk::CommandPoolResetFlags::empty())
                .unwrap();
            record_frame(d, cmd, &mut lightmaps, &frame, &mut atlas, Some(&again));
            let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
            let submit = vk::SubmitInfo2::default().command_buffer_infos(&cmds);
            d.queue_submit2(queue, &[submit], fence).unwrap();
            d.wait_for_fences(&[fence], true, u64::MAX).unwrap();
        }
        assert_eq!(
            again.bytes(),
            last.bytes(),
            "the same frame through the other slot"
        );
        assert_timed(&lightmaps.timings(0).unwrap().expect("timed"), 6);
        assert_ne!(first.bytes(), last.bytes());

        // Every lit entity has light in its region; nothing outside the regions is touched.
        let texels: Vec<[u16; 4]> = last
            .bytes()
            .chunks_exact(8)
            .map(|t| [0, 1, 2, 3].map(|c| u16::from_le_bytes([t[2 * c], t[2 * c + 1]])))
            .collect();
        let inside = |r: &EntityRegion, x: u32, y: u32| {
            let (w, h) = r.shape.size();
            x >= r.region.x && x < r.region.x + w && y >= r.region.y && y < r.region.y + h
        };
        let regions = &layouts[5].regions;
        let mut lit_regions = vec![false; regions.len()];
        for y in 0..ATLAS {
            for x in 0..ATLAS {
                let t = texels[(y * ATLAS + x) as usize];
                let owner = regions.iter().position(|r| inside(r, x, y));
                match owner {
                    Some(i) => lit_regions[i] |= t[..3].iter().any(|c| *c != 0),
                    None => assert_eq!(t, [0; 4], "texel ({x}, {y}) outside every region"),
                }
            }
        }
        assert!(lit_regions.iter().all(|l| *l), "{lit_regions:?}");

        drop(lightmaps);
        engine.free_frame_slots(&slots);
        engine.free_image(atlas_image);
        for b in [first, last, again] {
            engine.free_buffer(b);
        }
        assert!(ctx.validation_log().is_empty(), "messages go to the engine");
    }
    engine.destroy().assert_clean();
}

/// Every frame that does not fit is refused with `BadFrame` before anything is recorded (the
/// command buffer ends empty and valid), one case per class of mistake.
/// A direction map recorded into an engine's images: at every dust mote (a probe whose position
/// the test knows) under one light, the atlas holds the light's irradiance through the mote's
/// normal (it faces the camera) and the map its direction with weight; everywhere, no weight
/// without irradiance, directions no longer than their weight, nothing outside the regions.
#[test]
fn an_engine_records_a_direction_map() {
    let mut scene = all_kinds();
    let meshes = ProbeMeshes::new(&scene);
    let dust_index = scene
        .particle_systems
        .iter()
        .position(|p| p.layout == ParticleLayout::Dust)
        .unwrap();
    let motes = scene.particle_systems[dust_index].particles.clone();
    let centre = motes.iter().map(|p| p.position).sum::<Vec3>() / motes.len() as f32;
    scene.lights = vec![Light::point(
        centre + Vec3::new(0.4, 1.2, 0.6),
        20.0,
        Vec3::new(2.0, 1.5, 1.0),
    )];
    let light = scene.lights[0];
    let engine = Engine::start();
    {
        // SAFETY: as above.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.expect("context");
        let mut lightmaps = AlphaLightmaps::new(
            &ctx,
            &AlphaLightmapsDesc {
                atlas_format: FORMAT,
                frames_in_flight: 1,
                direction_format: Some(FORMAT),
            },
        )
        .unwrap();
        use vk::ImageUsageFlags as U;
        let extent = vk::Extent2D {
            width: ATLAS,
            height: ATLAS,
        };
        let usage = U::COLOR_ATTACHMENT | U::TRANSFER_SRC;
        let atlas_image = engine.image("atlas", FORMAT, extent, usage);
        let direction_image = engine.image("direction-map", FORMAT, extent, usage);
        let bytes = u64::from(ATLAS * ATLAS) * 8;
        let (atlas_bytes, direction_bytes) =
            (engine.readback_buffer(bytes), engine.readback_buffer(bytes));
        let entities = entities(&scene, &meshes);
        let layout = layout_for(&scene, &entities);
        let view = scene.camera.view_desc(4.0 / 3.0);
        let frame = LightmapFrame {
            slot: 0,
            view: &view,
            lights: &scene.lights,
            entities: &entities,
            layout: &layout,
            timestamps: true,
        };
        let d = &engine.device;
        let queue = unsafe { d.get_device_queue(engine.queue_family, 0) };
        let (pool, cmd) = engine.command_buffer();
        let mut atlas = atlas_image.as_ref(ImageState::UNDEFINED);
        let mut direction = direction_image.as_ref(ImageState::UNDEFINED);
        unsafe {
            d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                .unwrap();
            lightmaps
                .record_directional(cmd, &frame, &mut atlas, &mut direction)
                .unwrap();
            copy_to_buffer(d, cmd, &mut atlas, atlas_bytes.buffer);
            copy_to_buffer(d, cmd, &mut direction, direction_bytes.buffer);
            d.end_command_buffer(cmd).unwrap();
            let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
            let submit = vk::SubmitInfo2::default().command_buffer_infos(&cmds);
            d.queue_submit2(queue, &[submit], vk::Fence::null())
                .unwrap();
            d.queue_wait_idle(queue).unwrap();
        }
        let entity_count = entities.len() as u32;
        assert_timed(&lightmaps.timings(0).unwrap().expect("timed"), entity_count);
        let texels = |buffer: &EngineBuffer| -> Vec<[f32; 4]> {
            buffer
                .bytes()
                .chunks_exact(8)
                .map(|t| {
                    [0, 1, 2, 3]
                        .map(|c| half::f16::from_le_bytes([t[2 * c], t[2 * c + 1]]).to_f32())
                })
                .collect()
        };
        let (irradiance, directions) = (texels(&atlas_bytes), texels(&direction_bytes));

        let region = &layout.regions[scene.alpha_objects.len() + dust_index];
        let width = region.shape.tile_width;
        let mut checked = 0;
        for (i, mote) in motes.iter().enumerate() {
            let (x, y) = (
                region.region.x + i as u32 % width,
                region.region.y + i as u32 / width,
            );
            let at = (y * ATLAS + x) as usize;
            let (incident, l) = light.incident(mote.position).unwrap();
            let n_dot_l = (scene.camera.eye - mote.position).normalize().dot(l);
            let [dx, dy, dz, w] = directions[at];
            if n_dot_l <= 1e-3 {
                continue;
            }
            let expected = incident * n_dot_l;
            let got = Vec3::from_slice(&irradiance[at][..3]);
            assert!(
                (got - expected).abs().max_element() <= 2e-3 * expected.max_element().max(1.0),
                "mote {i}: irradiance {got} against {expected}"
            );
            let dominant = Vec3::new(dx, dy, dz) / w;
            assert!(
                (dominant - l).length() <= 3e-3,
                "mote {i}: direction {dominant} against {l}"
            );
            checked += 1;
        }
        assert!(
            checked > motes.len() / 2,
            "{checked} of {} motes lit",
            motes.len()
        );

        let inside = |r: &EntityRegion, x: u32, y: u32| {
            let (w, h) = r.shape.size();
            x >= r.region.x && x < r.region.x + w && y >= r.region.y && y < r.region.y + h
        };
        for y in 0..ATLAS {
            for x in 0..ATLAS {
                let at = (y * ATLAS + x) as usize;
                let ([r, g, b, _], [dx, dy, dz, w]) = (irradiance[at], directions[at]);
                if !layout.regions.iter().any(|r| inside(r, x, y)) {
                    assert_eq!([r, g, b, w], [0.0; 4], "({x}, {y}) outside every region");
                }
                assert_eq!(
                    w > 0.0,
                    r + g + b > 0.0,
                    "({x}, {y}): weight {w}, light {r} {g} {b}"
                );
                let length = Vec3::new(dx, dy, dz).length();
                assert!(
                    length <= w * 1.002 + 1e-6,
                    "({x}, {y}): |sum w L| {length} > {w}"
                );
            }
        }

        drop(lightmaps);
        unsafe { d.destroy_command_pool(pool, None) };
        engine.free_image(atlas_image);
        engine.free_image(direction_image);
        engine.free_buffer(atlas_bytes);
        engine.free_buffer(direction_bytes);
        assert!(ctx.validation_log().is_empty(), "messages go to the engine");
    }
    engine.destroy().assert_clean();
}

#[test]
fn lightmap_frames_that_do_not_fit_are_refused_before_recording() {
    let scene = all_kinds();
    let meshes = ProbeMeshes::new(&scene);
    let engine = Engine::start();
    {
        // SAFETY: as above.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.expect("context");
        for bad in [
            AlphaLightmapsDesc {
                atlas_format: FORMAT,
                frames_in_flight: 0,
                direction_format: None,
            },
            AlphaLightmapsDesc {
                atlas_format: vk::Format::D32_SFLOAT,
                frames_in_flight: 1,
                direction_format: None,
            },
            AlphaLightmapsDesc {
                atlas_format: FORMAT,
                frames_in_flight: 1,
                direction_format: Some(vk::Format::D32_SFLOAT),
            },
        ] {
            let err = AlphaLightmaps::new(&ctx, &bad).err().expect("refused");
            assert!(matches!(err, Error::BadSetup(_)), "{err}");
        }
        let mut lightmaps = AlphaLightmaps::new(
            &ctx,
            &AlphaLightmapsDesc {
                atlas_format: FORMAT,
                frames_in_flight: 2,
                direction_format: None,
            },
        )
        .unwrap();
        use vk::ImageUsageFlags as U;
        let image = |side| {
            let extent = vk::Extent2D {
                width: side,
                height: side,
            };
            engine.image("atlas", FORMAT, extent, U::COLOR_ATTACHMENT)
        };
        let (atlas_image, small_image) = (image(ATLAS), image(64));
        let other_format = engine.image(
            "atlas-f32",
            vk::Format::R32G32B32A32_SFLOAT,
            vk::Extent2D {
                width: ATLAS,
                height: ATLAS,
            },
            U::COLOR_ATTACHMENT,
        );
        let entities = entities(&scene, &meshes);
        let layout = layout_for(&scene, &entities);
        let view = scene.camera.view_desc(4.0 / 3.0);
        let frame = LightmapFrame {
            slot: 0,
            view: &view,
            lights: &scene.lights,
            entities: &entities,
            layout: &layout,
            timestamps: false,
        };

        let mut bad_entities: Vec<(&str, Vec<AlphaEntity>)> = Vec::new();
        let mut with = |what, i: usize, f: &dyn Fn(&mut AlphaEntity)| {
            let mut e = entities.clone();
            let before = format!("{:?}", e[i]);
            f(&mut e[i]);
            assert_ne!(before, format!("{:?}", e[i]), "{what}: nothing changed");
            bad_entities.push((what, e));
        };
        with("opacity", 0, &|e| e.opacity = 1.5);
        with("tint", 0, &|e| e.material.tint = Vec3::splat(f32::NAN));
        with("transform", 0, &|e| {
            if let AlphaEntityKind::Object { transform, .. } = &mut e.kind {
                *transform = glam::Mat4::ZERO;
            }
        });
        let system = scene.alpha_objects.len();
        with("particles", system, &|e| {
            if let AlphaEntityKind::Particles { particles, .. } = &mut e.kind {
                *particles = &NAN_PARTICLE;
            }
        });
        with("slices", system, &|e| {
            if let AlphaEntityKind::Particles { layout, .. } = &mut e.kind {
                *layout = ParticleLayout::Slices { count: 99 };
            }
        });
        // Dust in a region too small for its motes.
        let dust = entities
            .iter()
            .position(|e| {
                matches!(
                    e.kind,
                    AlphaEntityKind::Particles {
                        layout: ParticleLayout::Dust,
                        ..
                    }
                )
            })
            .unwrap();

        let (pool, cmd) = engine.command_buffer();
        let d = &engine.device;
        unsafe {
            d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
                .unwrap();
        }
        let mut refuse = |what: &str, frame: &LightmapFrame, atlas: &mut ImageRef| {
            let err = unsafe { lightmaps.record(cmd, frame, atlas) }
                .err()
                .unwrap_or_else(|| panic!("{what} was recorded"));
            assert!(matches!(err, Error::BadFrame(_)), "{what}: {err}");
            assert_eq!(atlas.state, ImageState::UNDEFINED, "{what}: state changed");
        };
        let atlas = || atlas_image.as_ref(ImageState::UNDEFINED);
        refuse("slot", &LightmapFrame { slot: 2, ..frame }, &mut atlas());
        // A NaN view or light, as the lighting's record paths refuse them.
        let mut nan_view = *frame.view;
        nan_view.view_to_clip[0][0] = f32::NAN;
        refuse(
            "view",
            &LightmapFrame {
                view: &nan_view,
                ..frame
            },
            &mut atlas(),
        );
        let mut nan_lights = frame.lights.to_vec();
        nan_lights[0].radius = f32::NAN;
        let lights = &nan_lights;
        refuse("light", &LightmapFrame { lights, ..frame }, &mut atlas());
        // An atlas said to lack COLOR_ATTACHMENT: refused, naming the usage, not drawn into.
        let no_attachment = ImageRef {
            usage: U::SAMPLED,
            ..atlas()
        };
        refuse("atlas usage", &frame, &mut no_attachment.clone());
        refuse(
            "entity count",
            &LightmapFrame {
                entities: &entities[1..],
                ..frame
            },
            &mut atlas(),
        );
        for (what, bad) in &bad_entities {
            refuse(
                what,
                &LightmapFrame {
                    entities: bad,
                    ..frame
                },
                &mut atlas(),
            );
        }
        refuse(
            "atlas size",
            &frame,
            &mut small_image.as_ref(ImageState::UNDEFINED),
        );
        refuse(
            "atlas format",
            &frame,
            &mut other_format.as_ref(ImageState::UNDEFINED),
        );
        let mut outside = layout_for(&scene, &entities);
        outside.regions[0].region.x = ATLAS - 1;
        refuse(
            "region outside the atlas",
            &LightmapFrame {
                layout: &outside,
                ..frame
            },
            &mut atlas(),
        );
        let mut cramped = layout_for(&scene, &entities);
        cramped.regions[dust].shape.tile_height = 1;
        refuse(
            "dust region",
            &LightmapFrame {
                layout: &cramped,
                ..frame
            },
            &mut atlas(),
        );
        let mut singular = view;
        singular.world_to_view = [[0.0; 4]; 4];
        refuse(
            "view",
            &LightmapFrame {
                view: &singular,
                ..frame
            },
            &mut atlas(),
        );
        // A direction map these lightmaps were not made for, or one that does not match.
        let refuse_directional = |what: &str,
                                  lightmaps: &mut AlphaLightmaps<&Context>,
                                  direction: &EngineImage| {
            let mut direction = direction.as_ref(ImageState::UNDEFINED);
            let err =
                unsafe { lightmaps.record_directional(cmd, &frame, &mut atlas(), &mut direction) }
                    .err()
                    .unwrap_or_else(|| panic!("{what} was recorded"));
            assert!(matches!(err, Error::BadFrame(_)), "{what}: {err}");
            assert_eq!(
                direction.state,
                ImageState::UNDEFINED,
                "{what}: state changed"
            );
        };
        refuse_directional("no direction format", &mut lightmaps, &atlas_image);
        let mut directional = AlphaLightmaps::new(
            &ctx,
            &AlphaLightmapsDesc {
                atlas_format: FORMAT,
                frames_in_flight: 1,
                direction_format: Some(FORMAT),
            },
        )
        .unwrap();
        refuse_directional("direction format", &mut directional, &other_format);
        refuse_directional("direction extent", &mut directional, &small_image);
        drop(directional);

        // A slot recorded, then recorded again or destroyed before it is declared finished:
        // refused (the command buffer is never submitted, so it may then be declared).
        let mut atlas_now = atlas();
        unsafe { lightmaps.record(cmd, &frame, &mut atlas_now) }.expect("a frame that fits");
        assert!(lightmaps.in_flight());
        let again = unsafe { lightmaps.record(cmd, &frame, &mut atlas_now) };
        match again {
            Err(Error::InFlight(m)) => assert!(m.contains("slot_finished(0)"), "{m}"),
            other => panic!("slot 0 recorded again in flight: {other:?}"),
        }
        let refused = lightmaps.destroy().expect_err("a destroy in flight");
        assert!(matches!(refused.error, Error::InFlight(_)), "{refused}");
        let mut lightmaps = refused.value;
        unsafe {
            d.end_command_buffer(cmd).unwrap();
            d.destroy_command_pool(pool, None);
            // SAFETY: the command buffer was never submitted, and its pool is gone.
            lightmaps.slot_finished(0).unwrap();
        }
        lightmaps.destroy().expect("no slot in flight");
        for image in [atlas_image, small_image, other_format] {
            engine.free_image(image);
        }
        assert!(ctx.validation_log().is_empty());
    }
    engine.destroy().assert_clean();
}

/// Timings of a frame of `entities` entities: the clear and each lit entity once, in order.
fn assert_timed(t: &LightmapTimings, entities: u32) {
    assert!(t.clear_ms.is_finite() && t.clear_ms >= 0.0, "{t:?}");
    assert!(!t.per_entity.is_empty(), "{t:?}");
    assert!(t.per_entity.windows(2).all(|w| w[0].0 < w[1].0), "{t:?}");
    assert!(t
        .per_entity
        .iter()
        .all(|&(e, ms)| e < entities && ms.is_finite() && ms >= 0.0));
    assert!(t.total_ms() >= t.clear_ms);
}
