//! The CPU simulator's inputs, captured from the GPU: the depth and stencil the G-buffer pass
//! left, and each planned light's footprint as the rasteriser produced it (the depth of its
//! front and back faces per pixel, drawn with the light pipelines' vertex shader and depth
//! clamp). Running `histencil_model::Simulator` on them predicts the GPU frame exactly: its
//! final stencil and its hi-stencil statistics (`tests/tests/hi_stencil.rs` holds it to that).

use crate::gpu::device::context::Context;
use crate::gpu::device::error::{Error, Result};
use crate::gpu::device::pipelines::{create_pipeline, Blend, PipelineDesc, VertexInput};
use crate::gpu::device::resources::{Buffer, Image};
use crate::gpu::encoder::recording::Recording;
use crate::gpu::frame::attachments::begin_cleared;
use crate::passes::light_passes::LightDrawPush;
use crate::passes::light_volumes::LightVolumes;
use crate::shaders;
use ash::vk;
use histencil_model::{
    CullMode, DepthConvention, DepthState, Footprint, FramePlan, PassState, SimResult, Simulator,
    SoftTarget, Span, StencilLayout,
};
use histencil_scene::Light;

/// Everything `histencil_model::Simulator` needs to predict a frame.
#[derive(Clone, Debug)]
pub struct SimulatorInputs {
    /// The renderer's stencil layout, which the plan's stencil states use.
    pub layout: StencilLayout,
    /// The hi-stencil tile side in pixels, as the GPU emulation uses.
    pub tile_size: u32,
    /// Depth and stencil after the G-buffer pass.
    pub target: SoftTarget,
    /// The lighting plan the GPU frame records.
    pub plan: FramePlan,
    /// Per planned light (the plan's light indices).
    pub footprints: Vec<Footprint>,
}

impl SimulatorInputs {
    /// Runs the simulator: what the GPU frame's lighting will do, and the stencil it leaves.
    pub fn predict(&self) -> (SimResult, SoftTarget) {
        self.predict_plan(&self.plan)
    }

    /// [`SimulatorInputs::predict_plan`] of `plan` on `backend`: on the AMD platforms, with
    /// the model of the GPU's own hierarchy ([`SimulatorInputs::predict_with`]), GFX9-11's
    /// pretests chosen from the captured stencil as the renderer chooses them
    /// (`Renderer::amd_pretests`).
    pub fn predict_on(&self, plan: &FramePlan, backend: crate::Backend) -> (SimResult, SoftTarget) {
        use histencil_model::amd::{AndOrTiles, PretestTiles};
        match backend {
            crate::Backend::AmdAndOr => self.predict_with(plan, &mut AndOrTiles::new()),
            crate::Backend::AmdAndOrUnmasked => {
                self.predict_with(plan, &mut AndOrTiles::unmasked())
            }
            crate::Backend::AmdPretest => {
                let mut tiles = PretestTiles::new(self.amd_pretests());
                self.predict_with(plan, &mut tiles)
            }
            _ => self.predict_plan(plan),
        }
    }

    /// The pretests a GFX9-11 frame of this G-buffer binds (`histencil_model::amd`).
    pub fn amd_pretests(
        &self,
    ) -> [Option<histencil_model::amd::Pretest>; histencil_model::amd::PRETEST_SLOTS] {
        use histencil_model::amd::{choose_pretests, slot_tile_counts};
        let t = &self.target;
        let tiles = histencil_model::TileSurface::new(t.width, t.height, self.tile_size);
        let counts = slot_tile_counts(&self.layout, &t.stencil, t.width, &tiles);
        choose_pretests(&self.layout, &counts)
    }

    /// The depth-id technique's statistics as the model predicts them from the captured
    /// G-buffer (each pixel's id from its stencil's BRDF slot, none where its depth is far):
    /// one full-screen pass per BRDF slot of the layout, as `Technique::DepthId` draws, against
    /// 8x8 tiles of hierarchical depth (`histencil_model::depth_id`). A depth-id frame's
    /// `Frame::tile_stats`, the same model on the GPU's own id image, must agree.
    pub fn predict_depth_id(&self) -> histencil_model::TileStats {
        use histencil_model::depth_id::{depth_id_stats, pixel_ids, slot_id};
        let target = &self.target;
        let slots = target.stencil.iter().map(|s| self.layout.brdf_slot(*s));
        let ids = pixel_ids(slots, &target.depth, self.plan.depth.far());
        let tiles = histencil_model::TileSurface::new(target.width, target.height, self.tile_size);
        let passes: Vec<u16> = (0..self.layout.brdfs_in_use()).map(slot_id).collect();
        depth_id_stats(&ids, target.width, &tiles, &passes)
    }

    /// [`SimulatorInputs::predict`] for another plan of the same lights (the same planned light
    /// indices, e.g. another backend or flush policy): the captured footprints serve every plan
    /// of a frame, so one capture answers for all of them.
    pub fn predict_plan(&self, plan: &FramePlan) -> (SimResult, SoftTarget) {
        let simulator = Simulator {
            layout: self.layout,
            tile_size: self.tile_size,
        };
        let mut target = self.target.clone();
        let result = simulator.run(&mut target, plan, &self.footprints);
        (result, target)
    }

    /// [`SimulatorInputs::predict_plan`] on a GPU whose own hierarchical stencil rejects tiles
    /// (`histencil_model::amd`; built from the captured G-buffer stencil): what it would cull of
    /// `plan`, the native plan.
    pub fn predict_with(
        &self,
        plan: &FramePlan,
        hierarchy: &mut dyn histencil_model::amd::TileHierarchy,
    ) -> (SimResult, SoftTarget) {
        let simulator = Simulator {
            layout: self.layout,
            tile_size: self.tile_size,
        };
        let mut target = self.target.clone();
        let result = simulator.run_with(&mut target, plan, &self.footprints, hierarchy);
        (result, target)
    }
}

/// "No face here" in the captured depth images.
const NO_FACE: f32 = -1.0;
const DEPTH_FORMAT: vk::Format = vk::Format::R32_SFLOAT;

/// The capture pipeline, its two depth images (front faces, back faces) and their readbacks.
pub(crate) struct FootprintCapture {
    extent: vk::Extent2D,
    pipeline: vk::Pipeline,
    faces: [Image; 2],
    readback: [Buffer; 2],
}

impl FootprintCapture {
    pub fn new(ctx: &Context, layout: vk::PipelineLayout, extent: vk::Extent2D) -> Result<Self> {
        if ctx.depth_stencil_format != vk::Format::D32_SFLOAT_S8_UINT {
            return Err(Error::MissingFormat(
                "simulator inputs need a 32-bit float depth buffer (D32_SFLOAT_S8_UINT)".into(),
            ));
        }
        let formats = [DEPTH_FORMAT];
        let pipeline = create_pipeline(
            ctx,
            &PipelineDesc {
                name: "footprint-capture-pipeline",
                vertex: ("light_volume.vert", shaders::LIGHT_VOLUME_VERT),
                fragment: Some(("footprint.frag", shaders::FOOTPRINT_FRAG)),
                layout,
                vertex_input: VertexInput::Position,
                color_formats: &formats,
                color_writes: true,
                blend: Blend::Off,
                depth_stencil_format: vk::Format::UNDEFINED,
                depth_clamp: true,
                specialization: &[],
            },
        )?;
        let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
        let image = |name| Image::new(ctx, name, DEPTH_FORMAT, extent, usage);
        let bytes = u64::from(extent.width) * u64::from(extent.height) * 4;
        let buffer = |name| Buffer::readback(ctx, name, bytes);
        Ok(Self {
            extent,
            pipeline,
            faces: [image("footprint-front")?, image("footprint-back")?],
            readback: [
                buffer("footprint-front-readback")?,
                buffer("footprint-back-readback")?,
            ],
        })
    }

    /// Records the front and back face depths of scene light `light` and their copies. The
    /// frame descriptor set must be bound.
    pub fn record(
        &mut self,
        rec: &Recording,
        pipeline_layout: vk::PipelineLayout,
        volumes: &LightVolumes,
        light: (u32, &Light),
    ) {
        rec.step(&format!("capture-footprint-{}", light.0), |rec| {
            for (face, cull) in [CullMode::Back, CullMode::Front].into_iter().enumerate() {
                let clear = vk::ClearValue {
                    color: vk::ClearColorValue {
                        float32: [NO_FACE; 4],
                    },
                };
                let image = &mut self.faces[face];
                begin_cleared(rec, image, clear);
                let push = LightDrawPush {
                    light_index: light.0,
                    ..Default::default()
                };
                // SAFETY: the recording is the caller's (`Renderer::simulator_inputs` began it),
                // inside the rendering `begin_cleared` began above; the pipeline was made by
                // `new` with `pipeline_layout`, from this device, and lives until `destroy`; the
                // push is `LightDrawPush` at offset 0, within the layout's graphics-stage range.
                unsafe {
                    rec.bind_pipeline(vk::PipelineBindPoint::GRAPHICS, self.pipeline);
                    let stages = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
                    rec.push(pipeline_layout, stages, 0, bytemuck::bytes_of(&push));
                }
                rec.apply(&PassState {
                    cull,
                    depth: DepthState::OFF,
                    front: None,
                    back: None,
                    color_write: true,
                    hi_stencil: None,
                    depth_bounds: false,
                });
                volumes.draw(rec, &light.1.kind);
                rec.end_rendering();
                rec.copy_image_to_buffer(image, vk::ImageAspectFlags::COLOR, &self.readback[face]);
            }
            rec.host_readable(vk::PipelineStageFlags2::COPY);
        });
    }

    /// The footprint of the last recorded light, once the commands have completed, its depths
    /// in `depth`'s convention (the one the frame uniforms projected the volume with).
    pub fn footprint(&self, depth: DepthConvention) -> Result<Footprint> {
        let [front, back] = &self.readback;
        let front: &[f32] = bytemuck::cast_slice(front.read());
        let back: &[f32] = bytemuck::cast_slice(back.read());
        let width = self.extent.width;
        let mut bounds: Option<(u32, u32, u32, u32)> = None;
        for (i, (&f, &b)) in front.iter().zip(back).enumerate() {
            if b == NO_FACE && f != NO_FACE {
                return Err(Error::Unsupported(
                    "a light volume whose front face covers a pixel its back face does not",
                ));
            }
            if b != NO_FACE {
                let (x, y) = (i as u32 % width, i as u32 / width);
                bounds = Some(match bounds {
                    None => (x, y, x, y),
                    Some((x0, y0, x1, y1)) => (x0.min(x), y0.min(y), x1.max(x), y1.max(y)),
                });
            }
        }
        let rect = bounds.map_or((0, 0, 0, 0), |(x0, y0, x1, y1)| {
            (x0, y0, x1 - x0 + 1, y1 - y0 + 1)
        });
        Ok(Footprint::from_fn_in(depth, rect, |x, y| {
            let i = (y * width + x) as usize;
            (back[i] != NO_FACE).then(|| Span {
                front: (front[i] != NO_FACE).then_some(front[i]),
                back: back[i],
            })
        }))
    }

    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the pipeline was made by `new` from this device. Its one user,
        // `Renderer::simulator_inputs`, destroys the capture after `submit_and_wait` waited for
        // the frames that drew with it, or after an error before their submit (a failed fence
        // wait aside: the frame may then still be pending).
        unsafe { ctx.device.destroy_pipeline(self.pipeline, None) };
        for image in &mut self.faces {
            image.destroy(ctx);
        }
        for buffer in &mut self.readback {
            buffer.destroy(ctx);
        }
    }
}
