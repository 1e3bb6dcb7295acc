//! What the C API's tests and benchmark share: the engine's handles, images, camera and lights
//! as a C engine passes them.

#![allow(dead_code)]

use ash::vk;
use histencil_capi::*;
use histencil_tests::engine::Engine;
use std::ffi::CString;

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
