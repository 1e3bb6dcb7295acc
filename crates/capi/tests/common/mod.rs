//! What the C API's tests and benchmark share: the engine's handles, images, camera and lights
//! as a C engine passes them.

#![allow(dead_code)]

use ash::vk;
use histencil::Context;
use histencil_capi::*;
use histencil_tests::engine::{Engine, EngineTargets};
use std::ffi::{c_char, CStr, CString};
use std::ptr::{null, null_mut};

pub fn device_desc(engine: &Engine) -> HistencilDeviceDesc {
    HistencilDeviceDesc {
        size: size_of::<HistencilDeviceDesc>() as u32,
        queue_family: engine.queue_family,
        get_instance_proc_addr: Some(engine.entry.static_fn().get_instance_proc_addr),
        instance: engine.instance.handle(),
        physical_device: engine.physical_device,
        device: engine.device.handle(),
        // SAFETY: the engine's live device and a queue it created.
        queue: unsafe { engine.device.get_device_queue(engine.queue_family, 0) },
        depth_stencil_format: vk::Format::UNDEFINED,
        debug_utils: 1,
        memory_budget: 0,
    }
}

pub fn c_image(image: &histencil::ImageRef) -> HistencilImage {
    HistencilImage {
        image: image.image,
        view: image.view,
        format: image.format,
        width: image.extent.width,
        height: image.extent.height,
        usage: image.usage,
        layout: image.state.layout,
        stage: image.state.stage,
        access: image.state.access,
    }
}

/// `targets` as the C side passes them, its images kept in `images`: the G-buffer's, then the
/// depth-stencil, then the HDR image (`images[images.len() - 1]` after a recording holds the
/// state the HDR image was left in).
pub fn c_targets_of(
    targets: &histencil::LightingTargets,
    images: &mut Vec<HistencilImage>,
) -> HistencilTargets {
    *images = targets.gbuffer.iter().map(c_image).collect();
    images.push(c_image(&targets.depth_stencil));
    images.push(c_image(&targets.hdr));
    let gbuffer = targets.gbuffer.len();
    let base = images.as_mut_ptr();
    HistencilTargets {
        size: size_of::<HistencilTargets>() as u32,
        gbuffer_count: gbuffer as u32,
        gbuffer: base,
        // SAFETY: both within `images`, which holds the G-buffer's images and these two.
        depth_stencil: unsafe { base.add(gbuffer) },
        // SAFETY: as above.
        hdr: unsafe { base.add(gbuffer + 1) },
    }
}

/// Each BRDF's boxes as the C side passes them (`HistencilBrdfBounds` point into the result).
pub fn c_boxes(bounds: &[Vec<histencil::Aabb>]) -> Vec<Vec<HistencilBox>> {
    (bounds.iter())
        .map(|b| {
            b.iter()
                .map(|a| HistencilBox {
                    min: a.min,
                    max: a.max,
                })
                .collect()
        })
        .collect()
}

/// The scene, view and G-buffer every frame here lights: `brdfs-3` through histencil's
/// renderer's G-buffer pass, on the engine's images.
pub struct World {
    pub scene: histencil::scene::Scene,
    pub view: histencil::ViewDesc,
    pub names: Vec<CString>,
}

impl World {
    pub fn c_view(&self) -> HistencilView {
        let flat = |m: [[f32; 4]; 4]| {
            let mut out = [0.0; 16];
            for (c, column) in m.iter().enumerate() {
                out[c * 4..c * 4 + 4].copy_from_slice(column);
            }
            out
        };
        HistencilView {
            world_to_view: flat(self.view.world_to_view),
            view_to_clip: flat(self.view.view_to_clip),
            reversed_depth: u32::from(self.view.depth == histencil::DepthConvention::Reversed),
        }
    }

    pub fn c_lights(&self) -> Vec<HistencilLight> {
        use histencil::{Falloff, LightKind};
        (self.scene.lights.iter())
            .map(|l| {
                let (kind, direction, inner, outer) = match l.kind {
                    LightKind::Point => (HISTENCIL_LIGHT_POINT, [0.0; 3], 0.0, 0.0),
                    LightKind::Spot {
                        direction,
                        inner_angle,
                        outer_angle,
                    } => (
                        HISTENCIL_LIGHT_SPOT,
                        direction.into(),
                        inner_angle,
                        outer_angle,
                    ),
                    LightKind::Directional { direction } => {
                        (HISTENCIL_LIGHT_DIRECTIONAL, direction.into(), 0.0, 0.0)
                    }
                };
                HistencilLight {
                    kind,
                    falloff: match l.falloff {
                        Falloff::SquaredWindow => HISTENCIL_FALLOFF_SQUARED_WINDOW,
                        Falloff::Gltf => HISTENCIL_FALLOFF_GLTF,
                        Falloff::InverseSquare => HISTENCIL_FALLOFF_INVERSE_SQUARE,
                    },
                    position: l.position.into(),
                    radius: l.radius,
                    color: l.color.into(),
                    inner_angle: inner,
                    direction,
                    outer_angle: outer,
                }
            })
            .collect()
    }
}

pub const SIZE: vk::Extent2D = vk::Extent2D {
    width: 48,
    height: 32,
};

pub fn last_error() -> String {
    // SAFETY: never null, valid until the next call on this thread.
    unsafe { CStr::from_ptr(histencil_last_error()) }
        .to_string_lossy()
        .into_owned()
}

/// Holds a call's result to `expected` and its message to contain `words`.
#[track_caller]
pub fn expect(result: HistencilResult, expected: HistencilResult, words: &str) {
    let message = last_error();
    assert_eq!(result, expected, "{message}");
    assert!(message.contains(words), "`{message}` should say `{words}`");
}

/// Runs `body` with the engine, a Rust context on its device (for histencil's renderer, which
/// writes the G-buffer, and the Rust lighting compared against), a C context on the same
/// device, the engine's targets and the world; then frees all and holds the layer silent.
pub fn with_c_context(
    body: impl FnOnce(
        &Engine,
        &mut histencil::vk::Renderer,
        *mut HistencilContext,
        &EngineTargets,
        &World,
    ),
) {
    let mut scene = histencil::scene::embedded("brdfs-3").unwrap();
    scene.normalise_lights();
    let engine = Engine::start();
    {
        // SAFETY: the engine's handles outlive the context; nothing else uses its queue.
        let ctx = unsafe { Context::from_raw(engine.lend(engine.queue_family)) }.unwrap();
        let mut renderer =
            histencil::vk::Renderer::new(&ctx, scene.clone(), SIZE.width, SIZE.height).unwrap();
        let names = (renderer.brdfs().iter())
            .map(|b| CString::new(b.name()).unwrap())
            .collect();
        let world = World {
            view: scene.camera.view_desc(1.5),
            scene,
            names,
        };
        let images = engine.lighting_targets(SIZE, ctx.depth_stencil_format().vk());
        let mut c_ctx = null_mut();
        // SAFETY: a live desc of the engine's live handles; a writable out pointer.
        let made = unsafe { histencil_context_create(&device_desc(&engine), &mut c_ctx) };
        assert_eq!(made, HistencilResult::Success, "{}", last_error());
        body(&engine, &mut renderer, c_ctx, &images, &world);
        // SAFETY: a live context with no lighting left.
        let freed = unsafe { histencil_context_destroy(c_ctx) };
        assert_eq!(freed, HistencilResult::Success, "{}", last_error());
        images.free(&engine);
        drop(renderer);
    }
    engine.destroy().assert_clean();
}

pub fn c_lighting_desc(world: &World, names: &[*const c_char]) -> HistencilLightingDesc {
    HistencilLightingDesc {
        size: size_of::<HistencilLightingDesc>() as u32,
        brdf_count: names.len() as u32,
        brdf_names: names.as_ptr(),
        shaders: null(),
        engine_stencil_bits: 0,
        width: SIZE.width,
        height: SIZE.height,
        depth_stencil_format: vk::Format::D32_SFLOAT_S8_UINT,
        hdr_format: vk::Format::R16G16B16A16_SFLOAT,
        frames_in_flight: 1,
        max_lights: world.scene.lights.len() as u32,
        hi_stencil: 1,
        hooks: null(),
    }
}

/// One frame on the engine's queue, waited for: histencil's G-buffer through `renderer`, then
/// `record`, the HDR image copied into `readback` and returned as floats.
pub fn lit_frame(
    engine: &Engine,
    renderer: &histencil::vk::Renderer,
    images: &EngineTargets,
    readback: &histencil_tests::engine::EngineBuffer,
    record: &mut dyn FnMut(vk::CommandBuffer, &mut histencil::LightingTargets),
) -> Vec<f32> {
    let d = &engine.device;
    let mut targets = images.refs();
    let (pool, cmd) = engine.command_buffer();
    // SAFETY: the engine's command buffer, recorded here and waited for.
    unsafe {
        d.begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
            .unwrap();
        renderer.record_gbuffer(cmd, &mut targets).unwrap();
        record(cmd, &mut targets);
        histencil_tests::engine::copy_to_buffer(d, cmd, &mut targets.hdr, readback.buffer);
        engine.submit_and_wait(pool, cmd);
    }
    histencil_tests::engine::hdr_floats(readback.bytes())
}

/// Records `frame` through the C API into `cmd` against `targets`, and takes the HDR image's
/// state back from what the C side was handed, as a C engine does for its next barrier.
pub fn record_through_c(
    lighting: *mut HistencilLighting,
    cmd: vk::CommandBuffer,
    frame: &HistencilFrame,
    targets: &mut histencil::LightingTargets,
) {
    let mut gbuffer = Vec::new();
    let mut c_targets = c_targets_of(targets, &mut gbuffer);
    // SAFETY: a recording command buffer of the lent device; live structs.
    let r = unsafe { histencil_lighting_record(lighting, cmd, frame, &mut c_targets) };
    assert_eq!(r, HistencilResult::Success, "{}", last_error());
    let hdr = gbuffer[gbuffer.len() - 1];
    targets.hdr.state.layout = hdr.layout;
    targets.hdr.state.stage = hdr.stage;
    targets.hdr.state.access = hdr.access;
}

/// What a C engine's frame points at: the world's lights and each BRDF's boxes, in the
/// renderer's BRDF order, kept alive while frames made by [`FrameInputs::frame`] are used.
pub struct FrameInputs {
    pub lights: Vec<HistencilLight>,
    /// What `bounds` points into.
    _boxes: Vec<Vec<HistencilBox>>,
    pub bounds: Vec<HistencilBrdfBounds>,
    view: HistencilView,
}

impl FrameInputs {
    pub fn new(world: &World, brdfs: &[histencil::BrdfId]) -> Self {
        let boxes = c_boxes(&world.scene.brdf_bounds(brdfs));
        let bounds = (boxes.iter())
            .map(|b| HistencilBrdfBounds {
                boxes: b.as_ptr(),
                box_count: b.len() as u32,
            })
            .collect();
        FrameInputs {
            lights: world.c_lights(),
            _boxes: boxes,
            bounds,
            view: world.c_view(),
        }
    }

    /// Slot 0's frame of `technique` on `platform`, the HDR image cleared, no hook sets.
    pub fn frame(&self, technique: u32, platform: u32) -> HistencilFrame {
        HistencilFrame {
            size: size_of::<HistencilFrame>() as u32,
            slot: 0,
            technique,
            platform,
            view: self.view,
            light_count: self.lights.len() as u32,
            lights: self.lights.as_ptr(),
            brdf_bounds_count: self.bounds.len() as u32,
            brdf_bounds: self.bounds.as_ptr(),
            clear_hdr: 1,
            decode_set: vk::DescriptorSet::null(),
            visibility_set: vk::DescriptorSet::null(),
            timestamps: 0,
        }
    }
}

impl World {
    /// The Rust API's tiled frame of the world, as the C API records `HISTENCIL_TECHNIQUE_TILED`:
    /// slot 0, 16x16 tiles, per-BRDF mixed tiles, the context's classification, no hook sets.
    pub fn rust_tiled_frame(&self, ctx: &Context) -> histencil::TiledFrame<'_> {
        histencil::TiledFrame {
            slot: 0,
            view: &self.view,
            lights: &self.scene.lights,
            clear_hdr: true,
            side: histencil::TileSide::Sixteen,
            mixed: histencil::MixedTiles::PerBrdf,
            classify: histencil::TileClassify::for_context(ctx),
            hook_sets: histencil::HookSets::default(),
        }
    }
}
