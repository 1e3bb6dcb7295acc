//! An engine that adopts histencil's lighting. It owns everything: instance, device, allocator
//! (`device.rs`), its world (`world.rs`), its G-buffer pass and shaders (`gbuffer.rs`), a
//! reversed-Z D32S8 depth buffer with its own data in stencil bits 6 and 7, command buffers and
//! fences with two frames in flight. histencil plans each frame on plain data
//! (`histencil::model::plan_frame`) and records its stencil-masked light volumes into the engine's
//! command buffer (`histencil::vk::DeferredLighting`), alternating the PS3-like and native
//! platform behaviours, with one frame by the tiled technique and one by depth ids. Its glass sphere and smoke cloud are lit by histencil's per-entity
//! lightmaps (`histencil::vk::AlphaLightmaps`, into the engine's own atlas) and drawn by the
//! engine's own alpha shaders, which sample them through histencil's `lightmap_sample.glsl`. The
//! last frame of each technique and backend (stencil PS3-like, stencil native, tiled, depth-id)
//! is compared with the engine's forward reference of the same state (lighting) and with
//! histencil's own lightmap frame (alpha), and on each stencil frame the engine's stencil bits
//! are checked to survive lighting (and, by histencil's `StencilReport`, to be what the layout
//! declares before it); the verdict line names every frame it compared.

mod alpha;
mod device;
mod gbuffer;
mod layouts;
mod reference;
mod shadow;
mod world;

use ash::vk;
use device::{barrier, Buffer, Gpu, Image};
use gbuffer::{CameraBlock, CompactDecode, GBufferKind, GBufferPass, DEPTH_FORMAT, ENGINE_MASK};
use gpu_allocator::MemoryLocation;
use histencil::vk::gpu_types::FrameUniforms;
use histencil::{
    mesh_bounds, plan_entities, plan_frame, AlphaEntity, AlphaEntityKind, AlphaLightmaps,
    AlphaLightmapsDesc, Backend, BrdfModules, BrdfParams, BrdfSource, ChoiceSettings, Context,
    DeferredLighting, DepthConvention, EngineHooks, FarPlane, FlushPolicy, HookSetLayout, HookSets,
    ImageState, LightHooks, LightModules, LightingDesc, LightingFrame, LightingTargets,
    LightmapFrame, MixedTiles, Perspective, PlanInputs, PlanSettings, StencilBits, StencilLayout,
    StencilReport, TechniqueChoice, TileClassify, TileSide, TiledFrame, View, ViewDesc, Viewer,
};
// histencil's own renderer, as the reference the engine's frames are compared with.
use histencil::vk::{AlphaMode, FrameDesc, Readback, Renderer, RendererDesc, Shading, Technique};
use std::sync::atomic::Ordering;
use std::time::Instant;
use world::{AlphaWorld, World};

const WIDTH: u32 = 160;
const HEIGHT: u32 = 96;
const FRAMES: usize = 120;
const IN_FLIGHT: usize = 2;
/// Lights the engine shadows through histencil's visibility hook.
const SHADOWED_LIGHTS: usize = 1;
/// Frames of each G-buffer layout timed for the comparison.
const TIMING_ROUNDS: usize = 21;
const HDR_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
/// histencil's light shaders compiled with the engine's decode hook (build.rs).
const LIGHT_MODULES: LightModules =
    include!(concat!(env!("OUT_DIR"), "/histencil_light_modules.rs"));
/// The engine's own BRDFs (`../brdfs`) and every module that evaluates them with histencil's
/// own G-buffer (build.rs): the lighting the compact layout is timed against, the lightmaps and
/// histencil's Renderer of the same state.
/// The generated file names everything by its full path, so it needs nothing in scope.
static BRDF_MODULES: std::sync::LazyLock<BrdfModules> =
    std::sync::LazyLock::new(|| include!(concat!(env!("OUT_DIR"), "/histencil_brdf_modules.rs")));
/// The engine's lightmap atlas: what its alpha entities need at this size fits easily.
const ATLAS_SIDE: u32 = 256;

/// Frame `f`'s camera, lights and plan for `backend`: histencil plans on plain data.
fn plan(
    layout: &StencilLayout,
    brdf_bounds: &[Vec<histencil::model::Aabb>],
    f: usize,
    backend: Backend,
) -> (
    ViewDesc,
    Vec<histencil::scene::Light>,
    histencil::model::FramePlan,
) {
    let view = view(f);
    let lights = world::lights(f);
    let shapes: Vec<_> = lights.iter().map(|l| l.shape()).collect();
    let checked = View::new(&view).expect("the engine's view");
    let settings = PlanSettings {
        technique: TechniqueChoice::Stencil,
        caps: backend.platform().caps(),
        flush: FlushPolicy::Auto,
    };
    let inputs = PlanInputs {
        lights: &shapes,
        brdf_bounds,
        view: &checked,
    };
    let plan = plan_frame(layout, &inputs, &settings).expect("a plan");
    (view, lights, plan)
}

/// The frame lit by the tiled technique, through the same hooks: the first captured one.
const TILED_FRAME: usize = FRAMES - 2;
/// The frame lit by the depth-id technique (Bevy's), through the same hooks: the last one.
const DEPTH_ID_FRAME: usize = FRAMES - 1;

/// How frame `f` is lit: planned, on its backend, tiled, or by depth ids.
fn technique(f: usize) -> Technique {
    if f == TILED_FRAME {
        return Technique::Tiled {
            mixed: MixedTiles::PerBrdf,
            side: TileSide::Sixteen,
        };
    }
    if f == DEPTH_ID_FRAME {
        return Technique::DepthId {
            side: TileSide::Sixteen,
        };
    }
    Technique::Stencil {
        backend: backend(f),
        flush: FlushPolicy::Auto,
    }
}

/// How the verdict names a frame's technique.
fn technique_name(technique: Technique) -> &'static str {
    match technique {
        Technique::Stencil {
            backend: Backend::Ps3,
            ..
        } => "stencil PS3-like",
        Technique::Stencil {
            backend: Backend::Native,
            ..
        } => "stencil native",
        Technique::Tiled { .. } => "tiled",
        Technique::DepthId { .. } => "depth-id",
        _ => "other",
    }
}

/// Frame `f`'s platform behaviour: PS3-like and native in turn.
fn backend(f: usize) -> Backend {
    if f % 2 == 0 {
        Backend::Ps3
    } else {
        Backend::Native
    }
}

/// The engine's camera: reversed Z, no far plane.
fn view(frame: usize) -> ViewDesc {
    let c = world::camera(frame);
    Perspective {
        eye: c.eye.into(),
        target: c.target.into(),
        up: c.up.into(),
        fov_y_radians: c.fov_y_radians,
        aspect: WIDTH as f32 / HEIGHT as f32,
        near: c.near,
        far: FarPlane::Infinite,
        depth: DepthConvention::Reversed,
    }
    .desc()
}

/// A frame slot: the engine's command pool and buffer, fence, and camera block.
struct Slot {
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    camera: Buffer,
    camera_set: vk::DescriptorSet,
    /// The engine's alpha set: histencil's entity records for this slot, and the atlas.
    alpha_set: vk::DescriptorSet,
}

/// What the last frame of each technique and backend copies back.
struct Capture {
    frame: usize,
    /// HDR after lighting, and after the alpha pass.
    lit: Buffer,
    hdr: Buffer,
    stencil_before: Buffer,
    stencil_after: Buffer,
    /// The engine's forward reference of the same state (shadows and G-buffer rounding).
    reference: Buffer,
}

fn main() {
    let gpu = Gpu::new();
    let extent = vk::Extent2D {
        width: WIDTH,
        height: HEIGHT,
    };
    let brdf_modules: &'static BrdfModules = &BRDF_MODULES;
    let world = World::new(&brdf_modules.set);
    // histencil's bits where this engine wants them: the culling bit at 5, the BRDF field from
    // bit 1; bits 6 and 7 are the engine's.
    let layout = StencilLayout::with_positions(
        world.brdfs.len() as u32,
        StencilBits {
            culling_bit: 5,
            brdf_shift: 1,
            engine_mask: ENGINE_MASK,
        },
    )
    .expect("the engine's bit positions fit");

    // SAFETY: the engine's handles outlive the context, its device was made with histencil's
    // REQUIREMENTS, and the engine submits from this thread only.
    let ctx = unsafe { Context::from_raw(gpu.lend()) }.expect("histencil on the engine's device");
    // histencil's hazard check, as an engine's debug build turns it on: the buffers histencil's
    // commands use, held to Vulkan's synchronisation rule across this engine's frames in flight
    // (told of each begin, submit and wait below). Before the lightings are made.
    let hazards = std::sync::Arc::new(histencil::vk::ValidationLog::default());
    ctx.check_hazards(hazards.clone());

    let gbuffer_pass = GBufferPass::new(&gpu, GBufferKind::Compact);
    use vk::ImageUsageFlags as U;
    let gbuffer: Vec<Image> = ["albedo", "normal-params"]
        .iter()
        .zip(gbuffer_pass.kind.formats())
        .map(|(n, f)| gpu.image(n, *f, extent, U::COLOR_ATTACHMENT | U::SAMPLED))
        .collect();
    // Sampled too: the decode hook reads depth from it.
    let depth = gpu.image(
        "depth",
        DEPTH_FORMAT,
        extent,
        U::DEPTH_STENCIL_ATTACHMENT | U::TRANSFER_SRC | U::SAMPLED,
    );
    let depth_view = gpu.depth_view(&depth);
    let gbuffer_refs: Vec<_> = gbuffer.iter().map(|g| g.target).collect();
    let mut shadow = shadow::ShadowMap::new(&gpu, IN_FLIGHT);
    // One hook layout for both hooks: the decode's images and the visibility's shadow map in
    // set 1, so the light pipelines bind the 4 sets every device binds (no visibility set).
    let decode = CompactDecode::new(&gpu, IN_FLIGHT, &gbuffer_refs, depth_view, &shadow);
    // The hooks are held to the layouts they bind (set, binding, type, stage) and the decode to
    // the G-buffer images it reads.
    let decode_layout = HookSetLayout {
        layout: decode.set_layout,
        bindings: &decode.bindings,
    };
    let surface_formats = gbuffer_pass.kind.formats();
    // SAFETY: the decode set layout is the engine's, made from those bindings on the lent
    // device, and is destroyed after the lighting; LIGHT_MODULES come from histencil_build of
    // this histencil-vk.
    // The compact G-buffer carries each pixel's BRDF parameters (surface_decode.glsl): every
    // id of the set reads its own.
    let hooks = unsafe { EngineHooks::new(LIGHT_MODULES, decode_layout, None, surface_formats) }
        .expect("the engine's light shaders")
        .with_brdf_params(BrdfParams::PerPixel);
    let mut lighting = DeferredLighting::new(
        &ctx,
        &LightingDesc {
            layout,
            brdfs: world.brdfs.clone(),
            extent,
            depth_stencil_format: DEPTH_FORMAT,
            hdr_format: HDR_FORMAT,
            frames_in_flight: IN_FLIGHT as u32,
            max_lights: world::LIGHTS as u32 + 1,
            // The PS3-like frames need the emulated hi-stencil.
            hi_stencil: true,
            hooks: LightHooks::Engine(hooks),
        },
    )
    .expect("lighting");
    // Storage: the tiled technique's kernels write it.
    let hdr = gpu.image(
        "hdr",
        HDR_FORMAT,
        extent,
        U::COLOR_ATTACHMENT | U::TRANSFER_SRC | U::STORAGE,
    );
    let mut lightmaps = AlphaLightmaps::with_modules(
        &ctx,
        &AlphaLightmapsDesc {
            atlas_format: HDR_FORMAT,
            frames_in_flight: IN_FLIGHT as u32,
            direction_format: None,
        },
        brdf_modules,
    )
    .expect("lightmaps");
    let atlas_image = gpu.image(
        "lightmap-atlas",
        HDR_FORMAT,
        vk::Extent2D {
            width: ATLAS_SIDE,
            height: ATLAS_SIDE,
        },
        U::COLOR_ATTACHMENT | U::SAMPLED,
    );
    let mut atlas = atlas_image.target;
    let mut alpha_pass = alpha::AlphaPass::new(&gpu, gbuffer_pass.set_layout, IN_FLIGHT);
    let sphere = world::sphere_mesh();
    let mut targets = LightingTargets {
        gbuffer: gbuffer_refs,
        depth_stencil: depth.target,
        hdr: hdr.target,
    };

    let d = &gpu.device;
    let sized = |ty| {
        vk::DescriptorPoolSize::default()
            .ty(ty)
            .descriptor_count(IN_FLIGHT as u32)
    };
    let pool_sizes = [
        sized(vk::DescriptorType::UNIFORM_BUFFER),
        sized(vk::DescriptorType::STORAGE_BUFFER),
        sized(vk::DescriptorType::SAMPLED_IMAGE),
        sized(vk::DescriptorType::SAMPLER),
    ];
    let descriptor_pool = unsafe {
        d.create_descriptor_pool(
            &vk::DescriptorPoolCreateInfo::default()
                .max_sets(2 * IN_FLIGHT as u32)
                .pool_sizes(&pool_sizes),
            None,
        )
    }
    .unwrap();
    let mut slots: Vec<Slot> = (0..IN_FLIGHT)
        .map(|i| unsafe {
            let pool = d
                .create_command_pool(
                    &vk::CommandPoolCreateInfo::default().queue_family_index(gpu.queue_family),
                    None,
                )
                .unwrap();
            let cmd = d
                .allocate_command_buffers(
                    &vk::CommandBufferAllocateInfo::default()
                        .command_pool(pool)
                        .command_buffer_count(1),
                )
                .unwrap()[0];
            let fence = d
                .create_fence(
                    &vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED),
                    None,
                )
                .unwrap();
            let camera = gpu.buffer(
                &format!("camera-{i}"),
                std::mem::size_of::<CameraBlock>() as u64,
                vk::BufferUsageFlags::UNIFORM_BUFFER,
                MemoryLocation::CpuToGpu,
            );
            let layouts = [gbuffer_pass.set_layout, alpha_pass.set_layout];
            let sets = d
                .allocate_descriptor_sets(
                    &vk::DescriptorSetAllocateInfo::default()
                        .descriptor_pool(descriptor_pool)
                        .set_layouts(&layouts),
                )
                .unwrap();
            let (camera_set, alpha_set) = (sets[0], sets[1]);
            let info = [vk::DescriptorBufferInfo::default()
                .buffer(camera.buffer)
                .range(vk::WHOLE_SIZE)];
            let write = vk::WriteDescriptorSet::default()
                .dst_set(camera_set)
                .descriptor_type(vk::DescriptorType::UNIFORM_BUFFER)
                .buffer_info(&info);
            d.update_descriptor_sets(&[write], &[]);
            Slot {
                pool,
                cmd,
                fence,
                camera,
                camera_set,
                alpha_set,
            }
        })
        .collect();
    let pixels = u64::from(WIDTH * HEIGHT);
    let readback = |name: &str, size| {
        gpu.buffer(
            name,
            size,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )
    };
    // The last frame of each: PS3-like and native stencil (even and odd frames), tiled, depth-id.
    let mut captures: Vec<Capture> = [FRAMES - 4, FRAMES - 3, TILED_FRAME, DEPTH_ID_FRAME]
        .map(|frame| Capture {
            frame,
            lit: readback("lit-readback", pixels * 8),
            hdr: readback("hdr-readback", pixels * 8),
            stencil_before: readback("stencil-before", pixels),
            stencil_after: readback("stencil-after", pixels),
            reference: readback("reference-readback", pixels * 8),
        })
        .into();

    // One forward reference per captured frame: two may be in flight at once.
    let mut references: Vec<reference::ForwardReference> = captures
        .iter()
        .map(|_| {
            reference::ForwardReference::new(
                &gpu,
                extent,
                HDR_FORMAT,
                shadow.set_layout,
                world::LIGHTS + 1,
            )
        })
        .collect();
    let brdf_bounds = world.brdf_bounds();
    let started = Instant::now();
    for f in 0..FRAMES {
        let slot = &mut slots[f % IN_FLIGHT];
        let (view, lights, plan) = plan(&layout, &brdf_bounds, f, backend(f));
        let capture = captures.iter().position(|c| c.frame == f);
        unsafe {
            // Wait for the frame that last used this slot: the only wait, and the engine's own;
            // then tell the lighting, which refuses to record a slot still in flight.
            d.wait_for_fences(&[slot.fence], true, u64::MAX).unwrap();
            ctx.note_wait(slot.fence);
            lighting.slot_finished((f % IN_FLIGHT) as u32).unwrap();
            lightmaps.slot_finished((f % IN_FLIGHT) as u32).unwrap();
            d.reset_fences(&[slot.fence]).unwrap();
            slot.camera.write(bytemuck::bytes_of(&CameraBlock {
                view: view.world_to_view,
                proj: view.view_to_clip,
            }));
            d.reset_command_pool(slot.pool, vk::CommandPoolResetFlags::empty())
                .unwrap();
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            d.begin_command_buffer(slot.cmd, &begin).unwrap();
            ctx.note_begin(slot.cmd);
            gbuffer_pass.record(
                d,
                slot.cmd,
                slot.camera_set,
                &world,
                lighting.desc(),
                &mut targets.gbuffer,
                &mut targets.depth_stencil,
            );
            // The spot light's shadow map, which histencil's visibility hook samples.
            let shadowed = &lights[world::SHADOWED_LIGHT];
            let light_view_proj = world::shadow_view_proj(shadowed);
            let block = shadow::ShadowBlock::new(light_view_proj, Some(world::SHADOWED_LIGHT));
            shadow.record(d, slot.cmd, f % IN_FLIGHT, &world, light_view_proj, block);
            if let Some(c) = capture.map(|i| &captures[i]) {
                copy_stencil(
                    d,
                    slot.cmd,
                    &mut targets.depth_stencil,
                    c.stencil_before.buffer,
                );
            }
            let frame = LightingFrame {
                slot: (f % IN_FLIGHT) as u32,
                view: &view,
                lights: &lights,
                plan: &plan,
                clear_hdr: true,
                timestamps: false,
                brdf_source: BrdfSource::Formula,
                tile_stats: false,
                hook_sets: HookSets {
                    decode: Some(decode.sets[f % IN_FLIGHT]),
                    visibility: None,
                },
            };
            // SAFETY: the command buffer is recording on the engine's device; the images' states
            // are the ones the engine's own barriers left; this slot's last frame has finished.
            // The tiled frame's kernels read the same hooks (their sets include the compute
            // stage) and write the HDR image as storage; so do the depth-id frame's classification
            // and its full-screen passes' fragment shaders.
            let tiled = |side, mixed| TiledFrame {
                slot: frame.slot,
                view: &view,
                lights: &lights,
                clear_hdr: true,
                side,
                mixed,
                classify: TileClassify::for_context(&ctx),
                hook_sets: frame.hook_sets,
            };
            match technique(f) {
                Technique::Tiled { mixed, side } => {
                    lighting.record_tiled(slot.cmd, &tiled(side, mixed), &mut targets)
                }
                Technique::DepthId { side } => {
                    let frame = tiled(side, MixedTiles::PerBrdf);
                    lighting.record_depth_id(slot.cmd, &frame, &mut targets)
                }
                _ => lighting.record(slot.cmd, &frame, &mut targets),
            }
            .expect("lighting recorded");
            if let Some(c) = capture.map(|i| &captures[i]) {
                copy_stencil(
                    d,
                    slot.cmd,
                    &mut targets.depth_stencil,
                    c.stencil_after.buffer,
                );
                copy_color(d, slot.cmd, &mut targets.hdr, c.lit.buffer);
            }
            if let Some(i) = capture {
                let uniforms = FrameUniforms::from_view(&view, WIDTH, HEIGHT, lights.len() as u32)
                    .expect("the engine's projection");
                let set = shadow.sets[f % IN_FLIGHT];
                let reference = &mut references[i];
                reference.record(d, slot.cmd, &world, &uniforms, &lights, set);
                copy_color(
                    d,
                    slot.cmd,
                    &mut reference.hdr.target,
                    captures[i].reference.buffer,
                );
            }
            // The translucent entities: histencil plans their regions and lights them into the
            // engine's atlas; the engine draws them with its own shaders.
            let alpha_world = AlphaWorld::at(f);
            let entities = [
                AlphaEntity {
                    kind: AlphaEntityKind::Object {
                        probe_mesh: &sphere,
                        transform: alpha_world.glass_transform,
                        local_bounds: mesh_bounds(&sphere),
                    },
                    material: alpha_world.glass_material,
                    opacity: alpha_world.glass_opacity,
                },
                AlphaEntity {
                    kind: AlphaEntityKind::Particles {
                        layout: alpha_world.smoke.layout,
                        particles: &alpha_world.smoke.particles,
                    },
                    material: alpha_world.smoke.material,
                    opacity: alpha_world.smoke.opacity,
                },
            ];
            // Each entity's slices and texels from histencil's error estimate, then the atlas.
            let viewer = Viewer::from_view(&view).expect("the engine's camera");
            let plan = plan_entities(
                &entities,
                &viewer,
                &lights,
                HEIGHT,
                ATLAS_SIDE,
                &ChoiceSettings::default(),
            )
            .expect("lightmap regions");
            let regions = plan.layout;
            let slot_index = (f % IN_FLIGHT) as u32;
            let lightmap_frame = LightmapFrame {
                slot: slot_index,
                view: &view,
                lights: &lights,
                entities: &entities,
                layout: &regions,
                timestamps: false,
            };
            // SAFETY: as for the lighting; the atlas state and usage are the ones the engine
            // tracks; this slot was declared finished after its fence wait above.
            lightmaps
                .record(slot.cmd, &lightmap_frame, &mut atlas)
                .expect("lightmaps recorded");
            let records = lightmaps.entity_buffer(slot_index).expect("the slot");
            alpha_pass.write_set(d, slot.alpha_set, records, atlas.view);
            alpha_pass.record(
                d,
                slot.cmd,
                f % IN_FLIGHT,
                [slot.camera_set, slot.alpha_set],
                &alpha_world,
                &mut atlas,
                (&mut targets.hdr, &mut targets.depth_stencil),
            );
            if let Some(c) = capture.map(|i| &captures[i]) {
                copy_color(d, slot.cmd, &mut targets.hdr, c.hdr.buffer);
                host_barrier(d, slot.cmd);
            }
            d.end_command_buffer(slot.cmd).unwrap();
            let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(slot.cmd)];
            let submit = vk::SubmitInfo2::default().command_buffer_infos(&cmds);
            d.queue_submit2(gpu.queue, &[submit], slot.fence).unwrap();
            ctx.note_submit(&[slot.cmd], slot.fence);
        }
    }
    let fences: Vec<_> = slots.iter().map(|s| s.fence).collect();
    unsafe { d.wait_for_fences(&fences, true, u64::MAX) }.unwrap();
    fences.iter().for_each(|f| ctx.note_wait(*f));
    for slot in 0..IN_FLIGHT as u32 {
        // SAFETY: every slot's fence was waited for just above.
        unsafe { lighting.slot_finished(slot) }.unwrap();
        // SAFETY: likewise, and the alpha draws reading the entity records were in those frames.
        unsafe { lightmaps.slot_finished(slot) }.unwrap();
    }
    let engine_ms = started.elapsed().as_secs_f64() * 1e3 / FRAMES as f64;

    // The lighting's time with the compact G-buffer against histencil's 40-byte layout, on the
    // last frame's state, native stencil, in one run.
    let histencil_pass = GBufferPass::new(&gpu, GBufferKind::Histencil);
    let histencil_images: Vec<Image> = ["albedo-40", "normal-depth-40", "material-40"]
        .iter()
        .zip(histencil_pass.kind.formats())
        .map(|(n, f)| gpu.image(n, *f, extent, U::COLOR_ATTACHMENT | U::SAMPLED))
        .collect();
    let mut histencil_lighting = DeferredLighting::new(
        &ctx,
        &LightingDesc {
            hooks: LightHooks::BuiltinWithBrdfs(brdf_modules.light),
            ..lighting.desc().clone()
        },
    )
    .expect("lighting with histencil's G-buffer");
    let timing_ms = {
        let f = FRAMES - 1;
        let (view, lights, plan) = plan(&layout, &brdf_bounds, f, Backend::Native);
        let slot = &mut slots[0];
        slot.camera.write(bytemuck::bytes_of(&CameraBlock {
            view: view.world_to_view,
            proj: view.view_to_clip,
        }));
        // The two layouts differ in the decode only: slot 0's shadow block names no light, so
        // the visibility hook returns 1 without reading the map.
        let light_view_proj = world::shadow_view_proj(&lights[world::SHADOWED_LIGHT]);
        shadow.blocks[0].write(bytemuck::bytes_of(&shadow::ShadowBlock::new(
            light_view_proj,
            None,
        )));
        let frame = layouts::Frame {
            cmd: slot.cmd,
            pool: slot.pool,
            fence: slot.fence,
            camera_set: slot.camera_set,
            world: &world,
            view: &view,
            lights: &lights,
            plan: &plan,
        };
        let mut variants = [
            layouts::Layout {
                pass: &gbuffer_pass,
                images: targets.gbuffer.clone(),
                lighting: &mut lighting,
                hook_sets: HookSets {
                    decode: Some(decode.sets[0]),
                    visibility: None,
                },
            },
            layouts::Layout {
                pass: &histencil_pass,
                images: histencil_images.iter().map(|i| i.target).collect(),
                lighting: &mut histencil_lighting,
                hook_sets: HookSets::default(),
            },
        ];
        // SAFETY: every frame above has finished (the fences were waited for); the handles
        // are the engine's, live.
        unsafe { layouts::time(&gpu, &frame, &mut variants, &mut targets, TIMING_ROUNDS) }
    };

    // histencil's forward reference of each captured state, and the Renderer's own stencil frame
    // of the same state for the frame time.
    let mut worst = 0u8;
    let mut intact = true;
    // What each captured frame was and what it showed, for the verdict line; how many of them
    // tested the engine's stencil bits.
    let mut compared = Vec::new();
    let mut stencil_frames = 0;
    let mut renderer_ms = 0.0;
    let (mut alpha_worst, mut alpha_mean, mut forward_mean) = (0u8, 0.0f64, 0.0f64);
    let mut alpha_pixels = usize::MAX;
    let mut shadowed_pixels = usize::MAX;
    for c in &captures {
        let scene = world::scene(&world, c.frame);
        let hdr_only = Readback {
            hdr: true,
            ..Readback::NONE
        };
        let hdr_of = |renderer: &mut Renderer, desc: FrameDesc| {
            let frame = renderer.render_frame(&desc).expect("reference frame");
            frame.images.hdr.expect("hdr").into_raw()
        };
        // Lighting: the engine's forward reference of the same state (its shadows, its G-buffer's
        // rounding) against the engine's HDR before its alpha pass.
        let lit = half_floats(&c.lit);
        let difference = max_difference(&half_floats(&c.reference), &lit, |_| true).0;
        worst = worst.max(difference);
        // histencil's own forward frame knows no shadows: the pixels where the engine's differs
        // from it are the shadowed ones. The alpha comparisons below skip them.
        let desc = RendererDesc {
            brdfs: brdf_modules,
            ..RendererDesc::new(WIDTH, HEIGHT)
        };
        let mut opaque =
            Renderer::with_desc(&ctx, scene.without_alpha(), &desc).expect("reference renderer");
        let forward = hdr_of(&mut opaque, FrameDesc::new(Shading::Forward, hdr_only));
        let unshadowed: Vec<bool> = pixel_differences(&forward, &lit)
            .into_iter()
            .map(|d| d <= 1)
            .collect();
        shadowed_pixels = shadowed_pixels.min(unshadowed.iter().filter(|u| !**u).count());
        let keep = |p: usize| unshadowed[p];
        // Alpha: histencil's own lightmap frame of the same state, and the per-pixel reference.
        let mut renderer = Renderer::with_desc(&ctx, scene, &desc).expect("reference renderer");
        let with_alpha = |alpha| FrameDesc {
            alpha,
            ..FrameDesc::new(Shading::Forward, hdr_only)
        };
        let lightmapped = hdr_of(&mut renderer, with_alpha(AlphaMode::Lightmap));
        let per_pixel = hdr_of(&mut renderer, with_alpha(AlphaMode::Forward));
        let ours = half_floats(&c.hdr);
        // The pixels the engine's alpha pass changed: it must have drawn something.
        let changed = lit
            .chunks_exact(4)
            .zip(ours.chunks_exact(4))
            .filter(|(a, b)| a[..3] != b[..3])
            .count();
        alpha_pixels = alpha_pixels.min(changed);
        let (max, mean) = max_difference(&lightmapped, &ours, keep);
        alpha_worst = alpha_worst.max(max);
        alpha_mean += mean / captures.len() as f64;
        forward_mean += max_difference(&per_pixel, &ours, keep).1 / captures.len() as f64;
        let before = c.stencil_before.bytes();
        let after = c.stencil_after.bytes();
        let marked = before.iter().filter(|s| **s & ENGINE_MASK != 0).count();
        // histencil's stencil check on the engine's own copy: the G-buffer pass wrote only the
        // bits the layout gives it (no culling bit, no slot past the BRDFs, nothing undeclared).
        let declared = StencilReport::of(&layout, before);
        assert!(declared.is_clean(), "frame {}: {declared}", c.frame);
        let kept = (before.iter().zip(after)).all(|(b, a)| (b ^ a) & ENGINE_MASK == 0);
        let technique = technique(c.frame);
        // Only the stencil technique touches stencil: its frames are the ones that test the bits.
        let mut what = format!(
            "{} {}: {difference}/255",
            c.frame,
            technique_name(technique)
        );
        if let Technique::Stencil { .. } = technique {
            stencil_frames += 1;
            intact &= marked > 0 && kept;
            what += if marked > 0 && kept {
                ", engine bits intact"
            } else {
                ", engine bits NOT intact"
            };
        }
        compared.push(what);
        let timed = Instant::now();
        let runs = 5;
        for _ in 0..runs {
            renderer
                .render(technique, Readback::NONE)
                .expect("renderer frame");
        }
        renderer_ms += timed.elapsed().as_secs_f64() * 1e3 / runs as f64 / captures.len() as f64;
    }
    println!(
        "alpha: {alpha_pixels} pixels or more drawn; engine frame vs histencil's lightmap frame of \
         the same state max {alpha_worst}/255 (mean {alpha_mean:.3}); lightmaps vs per-pixel \
         forward alpha mean {forward_mean:.3}/255 over the frame; both over the pixels the \
         spot light's shadow does not darken ({shadowed_pixels} or more are)"
    );
    println!(
        "engine: {engine_ms:.1} ms per frame with {IN_FLIGHT} in flight (wall clock, validation on); \
         histencil's Renderer on the same state: {renderer_ms:.1} ms per frame (it waits for each)"
    );

    let [(compact, c_lo, c_hi), (full, f_lo, f_hi)] =
        [0, 1].map(|i| layouts::median_interval(&timing_ms[i]));
    println!(
        "lighting GPU time, native stencil, frame {}, {TIMING_ROUNDS} frames of each layout in \
         turn: compact G-buffer ({} bytes per pixel) median {compact:.3} ms [{c_lo:.3}, \
         {c_hi:.3}], histencil's ({} bytes per pixel) {full:.3} ms [{f_lo:.3}, {f_hi:.3}] (95 % \
         intervals); compact / histencil {:.3}",
        FRAMES - 1,
        GBufferKind::Compact.bytes_per_pixel(),
        GBufferKind::Histencil.bytes_per_pixel(),
        compact / full
    );
    unsafe {
        let fences: Vec<_> = slots.iter().map(|s| s.fence).collect();
        d.wait_for_fences(&fences, true, u64::MAX).unwrap();
        // The GPU is done with every frame, and the lightings were told: histencil's parts
        // are freed without the device-wide wait that dropping them would do.
        lighting.destroy().expect("every slot declared finished");
        histencil_lighting
            .destroy()
            .expect("every slot declared finished");
        lightmaps.destroy().expect("every slot declared finished");
        for s in slots.drain(..) {
            d.destroy_fence(s.fence, None);
            d.destroy_command_pool(s.pool, None);
            gpu.free_buffer(s.camera);
        }
        d.destroy_descriptor_pool(descriptor_pool, None);
    }
    for c in captures.drain(..) {
        gpu.free_buffer(c.lit);
        gpu.free_buffer(c.hdr);
        gpu.free_buffer(c.stencil_before);
        gpu.free_buffer(c.stencil_after);
        gpu.free_buffer(c.reference);
    }
    unsafe { gpu.device.destroy_image_view(depth_view, None) };
    for image in gbuffer
        .into_iter()
        .chain(histencil_images)
        .chain([depth, hdr, atlas_image])
    {
        gpu.free_image(image);
    }
    let bytes = gbuffer_pass.kind.bytes_per_pixel();
    gbuffer_pass.destroy(&gpu);
    histencil_pass.destroy(&gpu);
    decode.destroy(&gpu);
    shadow.destroy(&gpu);
    for r in references {
        r.destroy(&gpu);
    }
    alpha_pass.destroy(&gpu);
    drop(ctx);
    gpu.destroy();
    let messages = device::MESSAGES.load(Ordering::SeqCst);
    for finding in hazards.problems() {
        eprintln!("{finding}");
    }
    let hazards = hazards.len();
    let names: Vec<&str> = brdf_modules
        .set
        .engine()
        .map(|(_, s)| s.name.as_str())
        .collect();
    let own = world.brdfs.iter().filter(|b| !b.is_builtin()).count();
    let names = names.join(", ");
    let materials = world.material_count();
    let brdf_count = world.brdfs.len();
    println!(
        "engine example: {FRAMES} frames, {IN_FLIGHT} in flight, lighting max {worst}/255 vs forward \
         over frames {}; engine stencil bits {} on {stencil_frames} stencil frames; {messages} \
         validation messages, {hazards} hazards, G-buffer {bytes} bytes per pixel, {SHADOWED_LIGHTS} shadowed \
         lights, {materials} materials of {brdf_count} BRDFs, {own} of them its own ({names}), through \
         the hooks",
        compared.join("; "),
        if intact { "intact" } else { "NOT intact" }
    );
    let alpha_ok = alpha_worst <= ALPHA_TOLERANCE && alpha_pixels > 0;
    // The shadow must darken something, or the visibility hook went unused.
    let bits_tested = stencil_frames > 0;
    if worst > 1
        || !alpha_ok
        || !intact
        || !bits_tested
        || messages > 0
        || hazards > 0
        || shadowed_pixels == 0
    {
        std::process::exit(1);
    }
}

/// The most the engine's alpha may differ from histencil's lightmap frame, in 8-bit steps: the
/// two draw the same lightmaps with different depth conventions and shaders.
const ALPHA_TOLERANCE: u8 = 2;

/// An HDR readback of R16G16B16A16_SFLOAT texels as f32.
fn half_floats(buffer: &Buffer) -> Vec<f32> {
    buffer
        .bytes()
        .chunks_exact(2)
        .map(|h| half::f16::from_le_bytes([h[0], h[1]]).to_f32())
        .collect()
}

/// The largest and the mean difference of two RGBA HDR images after tonemapping to 8 bits, over
/// the pixels `keep` keeps.
fn max_difference(a: &[f32], b: &[f32], keep: impl Fn(usize) -> bool) -> (u8, f64) {
    let (mut max, mut sum, mut n) = (0u8, 0u64, 0u64);
    for (p, (a, b)) in a.chunks_exact(4).zip(b.chunks_exact(4)).enumerate() {
        if !keep(p) {
            continue;
        }
        for ch in 0..3 {
            let d = tonemap(a[ch]).abs_diff(tonemap(b[ch]));
            max = max.max(d);
            sum += u64::from(d);
            n += 1;
        }
    }
    (max, sum as f64 / n.max(1) as f64)
}

/// Per pixel, the largest channel difference of two RGBA HDR images after tonemapping.
fn pixel_differences(a: &[f32], b: &[f32]) -> Vec<u8> {
    a.chunks_exact(4)
        .zip(b.chunks_exact(4))
        .map(|(a, b)| {
            (0..3)
                .map(|ch| tonemap(a[ch]).abs_diff(tonemap(b[ch])))
                .max()
                .unwrap_or(0)
        })
        .collect()
}

/// histencil's tonemap (exposure 1, Reinhard, sRGB), on the CPU, to 8 bits.
fn tonemap(x: f32) -> u8 {
    let c = (x.max(0.0) / (1.0 + x.max(0.0))).clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u8
}

const TRANSFER_READ: ImageState = ImageState {
    layout: vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
    stage: vk::PipelineStageFlags2::COPY,
    access: vk::AccessFlags2::TRANSFER_READ,
};

/// Copies the stencil aspect of `image` into `buffer` (one byte per pixel).
///
/// # Safety
/// As [`copy`].
unsafe fn copy_stencil(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    image: &mut histencil::vk::ImageRef,
    buffer: vk::Buffer,
) {
    copy(d, cmd, image, vk::ImageAspectFlags::STENCIL, buffer);
}

/// Copies the colour aspect of `image` into `buffer`.
///
/// # Safety
/// As [`copy`].
unsafe fn copy_color(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    image: &mut histencil::vk::ImageRef,
    buffer: vk::Buffer,
) {
    copy(d, cmd, image, vk::ImageAspectFlags::COLOR, buffer);
}

/// Barriers `image` to a transfer read and copies its `aspect` into `buffer`.
///
/// # Safety
/// `cmd` is recording, outside a render pass, on `d`; `image.state` is true when `cmd` executes;
/// `buffer` is live, has `TRANSFER_DST` usage and holds the whole aspect.
unsafe fn copy(
    d: &ash::Device,
    cmd: vk::CommandBuffer,
    image: &mut histencil::vk::ImageRef,
    aspect: vk::ImageAspectFlags,
    buffer: vk::Buffer,
) {
    barrier(d, cmd, image, TRANSFER_READ, false);
    let region = vk::BufferImageCopy::default()
        .image_subresource(
            vk::ImageSubresourceLayers::default()
                .aspect_mask(aspect)
                .layer_count(1),
        )
        .image_extent(vk::Extent3D {
            width: image.extent.width,
            height: image.extent.height,
            depth: 1,
        });
    d.cmd_copy_image_to_buffer(cmd, image.image, TRANSFER_READ.layout, buffer, &[region]);
}

/// Makes the copies recorded before it visible to the host once `cmd` has finished.
///
/// # Safety
/// `cmd` is recording, outside a render pass, on `d`.
unsafe fn host_barrier(d: &ash::Device, cmd: vk::CommandBuffer) {
    let b = [vk::MemoryBarrier2::default()
        .src_stage_mask(vk::PipelineStageFlags2::COPY)
        .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
        .dst_stage_mask(vk::PipelineStageFlags2::HOST)
        .dst_access_mask(vk::AccessFlags2::HOST_READ)];
    d.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().memory_barriers(&b));
}
