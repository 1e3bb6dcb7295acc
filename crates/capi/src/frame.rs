//! What an engine passes per frame, as C structs, and their checked conversion to histencil's
//! own: lights, the view, each BRDF's bounds, the technique and platform, and the images.

use crate::{check_size, required, slice, Failure, Outcome};
use ash::vk;
use glam::Vec3;
use histencil::{Aabb, DepthConvention, Falloff, ImageRef, ImageState, Light, LightKind, ViewDesc};

/// `HistencilLight.kind`: a point light of radius `radius`.
pub const HISTENCIL_LIGHT_POINT: u32 = 0;
/// `HistencilLight.kind`: a spot light along `direction`, between `inner_angle` and
/// `outer_angle` (radians from its axis).
pub const HISTENCIL_LIGHT_SPOT: u32 = 1;
/// `HistencilLight.kind`: a directional light travelling along `direction`, lighting the whole
/// screen.
pub const HISTENCIL_LIGHT_DIRECTIONAL: u32 = 2;

/// `HistencilLight.falloff`: histencil's own (Unreal's and Frostbite's), the inverse square
/// times the window squared, fading smoothly into the radius.
pub const HISTENCIL_FALLOFF_SQUARED_WINDOW: u32 = 0;
/// `HistencilLight.falloff`: glTF's (`KHR_lights_punctual` with a `range`), as Khronos' glTF
/// Sample Viewer implements it.
pub const HISTENCIL_FALLOFF_GLTF: u32 = 1;
/// `HistencilLight.falloff`: the inverse square, cut at the radius (a glTF light without
/// `range`: put the radius where the light falls to 1/255).
pub const HISTENCIL_FALLOFF_INVERSE_SQUARE: u32 = 2;

/// `HistencilFrame.technique`: the talk's, each light volume drawn once per BRDF it touches
/// under stencil.
pub const HISTENCIL_TECHNIQUE_STENCIL: u32 = 0;
/// `HistencilFrame.technique`: one light shader branching on each pixel's BRDF id.
pub const HISTENCIL_TECHNIQUE_BRANCHING: u32 = 1;
/// `HistencilFrame.technique`: tiled compute lighting, 16x16 tiles, a light list per tile.
pub const HISTENCIL_TECHNIQUE_TILED: u32 = 2;
/// `HistencilFrame.technique`: the BRDF id in a depth copy, one pass per BRDF.
pub const HISTENCIL_TECHNIQUE_DEPTH_ID: u32 = 3;
/// `HistencilFrame.technique`: branching's one light shader, each BRDF read from its material's
/// look-up table (`histencil_lighting_set_lut_tables` first; the G-buffer's material index
/// names the table).
pub const HISTENCIL_TECHNIQUE_LUT: u32 = 4;

/// `HistencilFrame.platform`: plain Vulkan, no hi-stencil emulated.
pub const HISTENCIL_PLATFORM_NATIVE: u32 = 0;
/// `HistencilFrame.platform`: PS3-like hi-stencil (with a read mask), emulated; needs a
/// lighting made with `hi_stencil`.
pub const HISTENCIL_PLATFORM_PS3: u32 = 1;
/// `HistencilFrame.platform`: 360-like hi-stencil (no read mask, preserved bits zeroed as lights
/// draw, the engine's stencil bits among them: as the 360 did), emulated; needs a lighting made
/// with `hi_stencil`. `HISTENCIL_PLATFORM_X360_SAVE_RESTORE` keeps the engine's bits.
pub const HISTENCIL_PLATFORM_X360: u32 = 2;
/// `HistencilFrame.platform`: 360-like hi-stencil as `HISTENCIL_PLATFORM_X360`, with the talk's
/// fix: the engine's stencil bits are copied out before lighting and drawn back after it (the
/// depth-stencil target needs `TRANSFER_SRC`); needs a lighting made with `hi_stencil`.
pub const HISTENCIL_PLATFORM_X360_SAVE_RESTORE: u32 = 3;

/// One light, in world space.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct HistencilLight {
    /// `HISTENCIL_LIGHT_*`.
    pub kind: u32,
    /// `HISTENCIL_FALLOFF_*`.
    pub falloff: u32,
    /// Where it is (point and spot lights).
    pub position: [f32; 3],
    /// How far it reaches (point and spot lights), positive.
    pub radius: f32,
    /// Its colour times its intensity, linear.
    pub color: [f32; 3],
    /// Spot lights: the angle from the axis where the light starts to fade, in radians (0 to
    /// `outer_angle`).
    pub inner_angle: f32,
    /// Spot and directional lights: the way the light travels (need not be unit length).
    pub direction: [f32; 3],
    /// Spot lights: the angle from the axis where the light ends, in radians, above
    /// `inner_angle` and at most 80 degrees.
    pub outer_angle: f32,
}

impl HistencilLight {
    pub(crate) fn to_light(self, index: usize) -> Outcome<Light> {
        let direction = Vec3::from(self.direction);
        let kind = match self.kind {
            HISTENCIL_LIGHT_POINT => LightKind::Point,
            HISTENCIL_LIGHT_SPOT => LightKind::Spot {
                direction,
                inner_angle: self.inner_angle,
                outer_angle: self.outer_angle,
            },
            HISTENCIL_LIGHT_DIRECTIONAL => LightKind::Directional { direction },
            k => {
                return Err(Failure::invalid(format!(
                    "lights[{index}].kind is {k}, not a HISTENCIL_LIGHT_* value"
                )))
            }
        };
        let falloff = match self.falloff {
            HISTENCIL_FALLOFF_SQUARED_WINDOW => Falloff::SquaredWindow,
            HISTENCIL_FALLOFF_GLTF => Falloff::Gltf,
            HISTENCIL_FALLOFF_INVERSE_SQUARE => Falloff::InverseSquare,
            f => {
                return Err(Failure::invalid(format!(
                    "lights[{index}].falloff is {f}, not a HISTENCIL_FALLOFF_* value"
                )))
            }
        };
        // The light's own problems (NaN, a negative radius, ...) are the lighting's to refuse,
        // in histencil's words, with the frame.
        Ok(Light {
            kind,
            position: Vec3::from(self.position),
            radius: self.radius,
            color: Vec3::from(self.color),
            falloff,
        })
    }
}

/// The camera: column-major matrices, as GLSL and most C math libraries store them.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct HistencilView {
    /// World to view space (the camera's transform inverted), column-major.
    pub world_to_view: [f32; 16],
    /// View to Vulkan clip space (the projection), column-major.
    pub view_to_clip: [f32; 16],
    /// Non-zero when the projection maps the near plane to depth 1 (reversed Z).
    pub reversed_depth: u32,
}

impl HistencilView {
    pub(crate) fn to_view(self) -> ViewDesc {
        let columns = |m: [f32; 16]| {
            let mut out = [[0.0; 4]; 4];
            for (c, column) in out.iter_mut().enumerate() {
                column.copy_from_slice(&m[c * 4..c * 4 + 4]);
            }
            out
        };
        ViewDesc {
            world_to_view: columns(self.world_to_view),
            view_to_clip: columns(self.view_to_clip),
            depth: if self.reversed_depth != 0 {
                DepthConvention::Reversed
            } else {
                DepthConvention::Standard
            },
        }
    }
}

/// An axis-aligned box in world space.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct HistencilBox {
    /// The corner with the smallest coordinates.
    pub min: [f32; 3],
    /// The corner with the largest; no coordinate below `min`'s.
    pub max: [f32; 3],
}

/// The world boxes of what one BRDF draws: the lights that reach none of them are not drawn
/// for that BRDF.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct HistencilBrdfBounds {
    /// `box_count` boxes.
    pub boxes: *const HistencilBox,
    /// How many.
    pub box_count: u32,
}

/// One of the engine's images, and the state it is in: what histencil's barriers start from.
/// After a recording, histencil writes the state it left the image in.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct HistencilImage {
    /// The image.
    pub image: vk::Image,
    /// A view of all of it (the depth-stencil: both aspects).
    pub view: vk::ImageView,
    /// Its format.
    pub format: vk::Format,
    /// Its width, which must be the lighting's.
    pub width: u32,
    /// Its height, which must be the lighting's.
    pub height: u32,
    /// The usages it was created with.
    pub usage: vk::ImageUsageFlags,
    /// The layout it is in when the recorded commands run.
    pub layout: vk::ImageLayout,
    /// The stages of the last commands before them that touched it.
    pub stage: vk::PipelineStageFlags2,
    /// The accesses of those commands.
    pub access: vk::AccessFlags2,
}

impl HistencilImage {
    pub(crate) fn to_ref(self, what: impl Fn() -> String) -> Outcome<ImageRef> {
        if self.image == vk::Image::null() || self.view == vk::ImageView::null() {
            return Err(Failure::invalid(format!(
                "{}: its image or view is VK_NULL_HANDLE",
                what()
            )));
        }
        Ok(ImageRef {
            image: self.image,
            view: self.view,
            format: self.format,
            extent: vk::Extent2D {
                width: self.width,
                height: self.height,
            },
            usage: self.usage,
            state: ImageState {
                layout: self.layout,
                stage: self.stage,
                access: self.access,
            },
        })
    }

    pub(crate) fn left_as(&mut self, image: &ImageRef) {
        self.layout = image.state.layout;
        self.stage = image.state.stage;
        self.access = image.state.access;
    }
}

/// The images a lighting records against, each the engine's own `HistencilImage`, read before
/// the recording and written after it with the state the commands leave it in (so the engine's
/// next barrier starts from there):
/// - `gbuffer`: histencil's G-buffer (`histencil_gbuffer_formats`, in that order), or with
///   `HistencilHooks` the images the decode reads (`surface_formats`, in that order), made with
///   `SAMPLED` usage; its stencil-carrying depth image written by the engine's G-buffer pass
///   with each surface's BRDF slot (`histencil_lighting_stencil_reference`), the BRDF bits
///   cleared to 0 everywhere else first.
/// - `depth_stencil`: `DEPTH_STENCIL_ATTACHMENT`, and `SAMPLED` for the PS3-like and 360-like
///   platforms (the hi-stencil emulation reads it), `TRANSFER_SRC` for
///   `HISTENCIL_PLATFORM_X360_SAVE_RESTORE` (it copies the engine's stencil bits out).
/// - `hdr`: `COLOR_ATTACHMENT`, and `STORAGE` for the tiled and depth-id techniques (which take
///   `VK_FORMAT_R16G16B16A16_SFLOAT` only).
///
/// A usage a frame needs and an image lacks is refused with `BAD_FRAME`, naming it.
#[repr(C)]
#[derive(Debug)]
pub struct HistencilTargets {
    /// `sizeof(HistencilTargets)`.
    pub size: u32,
    /// How many G-buffer images.
    pub gbuffer_count: u32,
    /// The G-buffer images.
    pub gbuffer: *mut HistencilImage,
    /// The depth-stencil image.
    pub depth_stencil: *mut HistencilImage,
    /// The HDR image.
    pub hdr: *mut HistencilImage,
}

/// The G-buffer's most images: histencil's own has three.
const MAX_GBUFFER_IMAGES: u32 = 8;

impl HistencilTargets {
    pub(crate) fn to_targets(&self) -> Outcome<histencil::LightingTargets> {
        check_size::<HistencilTargets>("HistencilTargets", self.size)?;
        if self.gbuffer_count > MAX_GBUFFER_IMAGES {
            return Err(Failure::invalid(format!(
                "HistencilTargets.gbuffer_count is {}, past {MAX_GBUFFER_IMAGES}",
                self.gbuffer_count
            )));
        }
        // SAFETY: the header's contract: `gbuffer_count` images at `gbuffer`.
        let gbuffer =
            unsafe { slice(self.gbuffer, self.gbuffer_count, "HistencilTargets.gbuffer") }?;
        let gbuffer = (gbuffer.iter().enumerate())
            .map(|(i, g)| g.to_ref(|| format!("gbuffer[{i}]")))
            .collect::<Outcome<Vec<_>>>()?;
        // SAFETY: the header's contract: null or a live image each.
        let (depth_stencil, hdr) = unsafe {
            (
                required(self.depth_stencil, "HistencilTargets.depth_stencil")?,
                required(self.hdr, "HistencilTargets.hdr")?,
            )
        };
        Ok(histencil::LightingTargets {
            gbuffer,
            depth_stencil: depth_stencil.to_ref(|| "depth_stencil".into())?,
            hdr: hdr.to_ref(|| "hdr".into())?,
        })
    }

    /// Writes back the states a recording left the images in.
    pub(crate) fn left_as(&mut self, targets: &histencil::LightingTargets) {
        // SAFETY: checked by `to_targets` before the recording: `gbuffer_count` images at
        // `gbuffer` (none when the count is 0), and live `depth_stencil` and `hdr`.
        unsafe {
            if self.gbuffer_count > 0 {
                let count = self.gbuffer_count as usize;
                let gbuffer = std::slice::from_raw_parts_mut(self.gbuffer, count);
                for (g, t) in gbuffer.iter_mut().zip(&targets.gbuffer) {
                    g.left_as(t);
                }
            }
            (*self.depth_stencil).left_as(&targets.depth_stencil);
            (*self.hdr).left_as(&targets.hdr);
        }
    }
}

/// One frame's lighting: its slot, camera, lights, where each BRDF is drawn, and how to light.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct HistencilFrame {
    /// `sizeof(HistencilFrame)`.
    pub size: u32,
    /// The frame-in-flight slot, below the lighting's `frames_in_flight`: the engine's frame
    /// number modulo it.
    pub slot: u32,
    /// `HISTENCIL_TECHNIQUE_*`.
    pub technique: u32,
    /// `HISTENCIL_PLATFORM_*` (the stencil and branching techniques; ignored by the others).
    pub platform: u32,
    /// The camera.
    pub view: HistencilView,
    /// How many lights.
    pub light_count: u32,
    /// The lights, at most the lighting's `max_lights`.
    pub lights: *const HistencilLight,
    /// One entry per BRDF of the lighting, in its `brdf_names` order (stencil and branching).
    pub brdf_bounds_count: u32,
    /// Each BRDF's boxes.
    pub brdf_bounds: *const HistencilBrdfBounds,
    /// Non-zero to clear the HDR image first; zero to add to what it holds.
    pub clear_hdr: u32,
    /// The engine's descriptor set for its decode hook (set 1): required when the lighting was
    /// made with `HistencilLightingDesc.hooks`, else `VK_NULL_HANDLE`.
    pub decode_set: vk::DescriptorSet,
    /// The engine's descriptor set for its visibility hook (set 4): required exactly when
    /// `HistencilHooks.visibility_layout` was given, else `VK_NULL_HANDLE`.
    pub visibility_set: vk::DescriptorSet,
    /// Non-zero to write a GPU timestamp after every step of the stencil, branching and LUT
    /// techniques (`histencil_lighting_step_timings` reads them once the frame has finished).
    /// Opt-in: on some drivers a timestamp between draws serialises them.
    pub timestamps: u32,
}

/// One group of a frame's lighting steps and its GPU time (`histencil_lighting_step_timings`).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct HistencilStepTime {
    /// The group's name, NUL-terminated (`setup`, `mask-ggx`, `shade-ggx`, `cleanup`, ...): valid
    /// until the next call on the lighting.
    pub group: *const std::ffi::c_char,
    /// Its time summed over the frame's lights, in milliseconds.
    pub ms: f64,
}

/// Most lights a frame may pass: far past any lighting's `max_lights`, a bound on what is read.
const MAX_LIGHTS: u32 = 1 << 20;

/// `count` lights at `lights`, converted into `out`; `what` names the struct in messages.
///
/// # Safety
/// `lights` is null or points at `count` lights.
pub(crate) unsafe fn lights_into(
    lights: *const HistencilLight,
    count: u32,
    what: &str,
    out: &mut Vec<Light>,
) -> Outcome {
    if count > MAX_LIGHTS {
        return Err(Failure::invalid(format!(
            "{what}.light_count is {count}, past {MAX_LIGHTS}"
        )));
    }
    // SAFETY: this fn's # Safety.
    let lights = unsafe { slice(lights, count, &format!("{what}.lights")) }?;
    out.clear();
    for (i, l) in lights.iter().enumerate() {
        out.push(l.to_light(i)?);
    }
    Ok(())
}

impl HistencilFrame {
    /// The frame's lights, converted into `out` (a lighting's own, reused frame after frame so
    /// that a frame through C allocates nothing the Rust API's does not).
    pub(crate) fn lights_into(&self, out: &mut Vec<Light>) -> Outcome {
        // SAFETY: the header's contract: `light_count` lights at `lights`.
        unsafe { lights_into(self.lights, self.light_count, "HistencilFrame", out) }
    }

    /// Each BRDF's boxes, converted into `out` (reused as `lights_into`'s).
    pub(crate) fn bounds_into(&self, brdfs: usize, out: &mut Vec<Vec<Aabb>>) -> Outcome {
        if self.brdf_bounds_count as usize != brdfs {
            return Err(Failure::invalid(format!(
                "HistencilFrame.brdf_bounds_count is {}, and the lighting has {brdfs} BRDFs: one \
                 entry per BRDF, in its brdf_names order",
                self.brdf_bounds_count
            )));
        }
        // SAFETY: the header's contract: `brdf_bounds_count` entries at `brdf_bounds`.
        let all = unsafe { slice(self.brdf_bounds, self.brdf_bounds_count, "brdf_bounds") }?;
        out.resize_with(all.len(), Vec::new);
        for (b, (bounds, boxes_out)) in all.iter().zip(out.iter_mut()).enumerate() {
            if bounds.boxes.is_null() && bounds.box_count > 0 {
                return Err(Failure::invalid(format!(
                    "brdf_bounds[{b}].boxes is null with a count of {}",
                    bounds.box_count
                )));
            }
            // SAFETY: the header's contract: `box_count` boxes at a non-null `boxes`.
            let boxes = unsafe { slice(bounds.boxes, bounds.box_count, "boxes") }?;
            boxes_out.clear();
            boxes_out.extend(boxes.iter().map(|b| Aabb {
                min: b.min,
                max: b.max,
            }));
        }
        Ok(())
    }
}
