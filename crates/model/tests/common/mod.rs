//! A random frame for the simulator: surface depths, BRDF slots, preserved bits and lights.
// Each test binary uses its own part of this module.
#![allow(dead_code)]

use histencil_model::{
    DepthConvention, FlushPolicy, Footprint, FramePlan, LightRequest, LightTechnique, Native,
    PlannedLight, PlatformBackend, Ps3Like, SimResult, Simulator, SoftTarget, StencilBits,
    StencilLayout, X360Like,
};
use proptest::prelude::*;

#[derive(Clone, Debug)]
pub enum Backend {
    Native,
    Ps3,
    X360 { zero: bool, save_restore: bool },
}

impl Backend {
    pub fn boxed(&self) -> Box<dyn PlatformBackend> {
        match *self {
            Backend::Native => Box::new(Native),
            Backend::Ps3 => Box::new(Ps3Like),
            Backend::X360 { zero, save_restore } => Box::new(X360Like {
                zero_preserved: zero,
                save_restore,
            }),
        }
    }
}

#[derive(Clone, Debug)]
pub struct LightSpec {
    pub footprint: Footprint,
    pub branching: bool,
}

#[derive(Clone, Debug)]
pub struct Frame {
    pub layout: StencilLayout,
    pub depth: DepthConvention,
    pub target: SoftTarget,
    pub lights: Vec<LightSpec>,
}

/// Depths on a grid of 1/4096, which `1 - d` maps exactly onto itself.
fn on_grid(d: f32) -> f32 {
    (d * 4096.0).round() / 4096.0
}

impl Frame {
    pub fn slot(&self, i: usize) -> u32 {
        self.layout.brdf_slot(self.target.stencil[i])
    }

    /// The BRDF slots of the surfaces inside light `light`'s volume: what an engine's object
    /// bounds test would find, made exact.
    pub fn affected(&self, light: usize) -> Vec<u32> {
        let fp = &self.lights[light].footprint;
        let mut slots = Vec::new();
        for y in fp.y0..fp.y0 + fp.height {
            for x in fp.x0..fp.x0 + fp.width {
                let i = self.target.index(x, y);
                if fp.shades(x, y, self.target.depth[i]) {
                    slots.push(self.slot(i));
                }
            }
        }
        slots.sort_unstable();
        slots.dedup();
        slots
    }

    pub fn requests(&self) -> Vec<LightRequest> {
        (0..self.lights.len())
            .map(|i| LightRequest {
                case: self.lights[i].footprint.case(),
                affected: self.affected(i),
                technique: if self.lights[i].branching {
                    LightTechnique::Branching
                } else {
                    LightTechnique::Stencil
                },
            })
            .collect()
    }

    pub fn footprints(&self) -> Vec<Footprint> {
        self.lights.iter().map(|l| l.footprint.clone()).collect()
    }

    pub fn plan(&self, backend: &Backend, policy: FlushPolicy) -> FramePlan {
        let lights = PlannedLight::numbered(self.requests());
        let caps = backend.boxed().caps();
        FramePlan::build(&self.layout, &caps, self.depth, lights, policy).unwrap()
    }

    /// The same frame with every depth `d` on the grid, then, with `Reversed`, as `1 - d`.
    pub fn in_convention(&self, depth: DepthConvention) -> Frame {
        let mirror = |d: f32| match depth {
            DepthConvention::Standard => on_grid(d),
            DepthConvention::Reversed => 1.0 - on_grid(d),
        };
        let mut frame = self.clone();
        frame.depth = depth;
        frame.target.depth = self.target.depth.iter().map(|&d| mirror(d)).collect();
        for light in &mut frame.lights {
            light.footprint = light
                .footprint
                .clone()
                .map_depths(on_grid)
                .in_convention(depth);
        }
        frame
    }

    /// Runs `plan`; returns the result and the final stencil.
    pub fn simulate(&self, plan: &FramePlan, tile_size: u32) -> (SimResult, Vec<u8>) {
        let mut target = self.target.clone();
        let sim = Simulator {
            layout: self.layout,
            tile_size,
        };
        let result = sim.run(&mut target, plan, &self.footprints());
        (result, target.stencil)
    }
}

fn light(width: u32, height: u32) -> impl Strategy<Value = LightSpec> {
    let w = width as f32;
    let h = height as f32;
    (
        0u32..10,
        -0.25f32..1.25,
        -0.25f32..1.25,
        1.0f32..(w.max(h)),
        -0.2f32..1.3,
        0.01f32..0.7,
        any::<bool>(),
    )
        .prop_map(
            move |(kind, cx, cy, radius, depth, depth_radius, branching)| {
                let footprint = if kind == 0 {
                    Footprint::full_screen(width, height)
                } else {
                    Footprint::ellipsoid(
                        (width, height),
                        (cx * w, cy * h),
                        radius,
                        depth,
                        depth_radius,
                    )
                };
                LightSpec {
                    footprint,
                    branching,
                }
            },
        )
}

/// A layout for `brdfs` BRDFs: the talk's, or the culling bit and BRDF field at random
/// positions with a random subset of the other bits declared the engine's.
pub fn layout(brdfs: u32) -> impl Strategy<Value = StencilLayout> {
    (any::<bool>(), 0u32..8, 0u32..8, any::<u8>()).prop_map(
        move |(talks, culling_bit, brdf_shift, engine)| {
            let talks_layout = StencilLayout::new(brdfs, 0).unwrap();
            if talks {
                return talks_layout;
            }
            let brdf_bits = talks_layout.brdf_bits();
            let brdf_shift = brdf_shift % (9 - brdf_bits);
            let field = (((1u32 << brdf_bits) - 1) << brdf_shift) as u8;
            // The first bit outside the field from `culling_bit` on; 8 bits, at most 3 taken.
            let culling_bit = (0..8)
                .map(|i| (culling_bit + i) % 8)
                .find(|b| field & (1 << b) == 0)
                .unwrap();
            let bits = StencilBits {
                culling_bit,
                brdf_shift,
                engine_mask: engine & !(field | 1 << culling_bit),
            };
            StencilLayout::with_positions(brdfs, bits).unwrap()
        },
    )
}

/// Frames up to 40x40 with 1-8 BRDFs in any layout, random preserved bits and 1-8 lights.
pub fn frame() -> impl Strategy<Value = Frame> {
    (4u32..40, 4u32..40, 1u32..=8).prop_flat_map(|(width, height, brdfs)| {
        let n = (width * height) as usize;
        (
            layout(brdfs),
            proptest::collection::vec(0..brdfs, n),
            proptest::collection::vec(any::<u8>(), n),
            proptest::collection::vec(prop_oneof![3 => 0.0f32..1.0, 1 => Just(1.0f32)], n),
            proptest::collection::vec(light(width, height), 1..8),
        )
            .prop_map(move |(layout, slots, preserved, depth, lights)| {
                let stencil = slots
                    .iter()
                    .zip(&preserved)
                    .map(|(&slot, &bits)| {
                        layout.brdf_reference(slot) | (bits & layout.preserved_mask())
                    })
                    .collect();
                Frame {
                    layout,
                    depth: DepthConvention::Standard,
                    target: SoftTarget {
                        width,
                        height,
                        depth,
                        stencil,
                    },
                    lights,
                }
            })
    })
}

pub fn backend() -> impl Strategy<Value = Backend> {
    prop_oneof![
        Just(Backend::Native),
        Just(Backend::Ps3),
        (any::<bool>()).prop_map(|save_restore| Backend::X360 {
            zero: true,
            save_restore
        }),
    ]
}
