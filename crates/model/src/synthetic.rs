//! A reproducible synthetic frame (random depths, BRDF slots, preserved bits and ellipsoid
//! lights) for benchmarks and oracle tests. Same seed, same frame, on every machine.

use crate::footprint::Footprint;
use crate::layout::StencilLayout;
use crate::plan::{LightRequest, LightTechnique};
use crate::sim::SoftTarget;

/// Parameters of a synthetic frame.
#[derive(Clone, Copy, Debug)]
pub struct SyntheticDesc {
    /// Side of the square frame, in pixels.
    pub size: u32,
    /// How many ellipsoid lights.
    pub lights: usize,
    /// The layout the BRDF slots are drawn from and written with.
    pub layout: StencilLayout,
    /// OR-ed into every pixel's stencil; masked to the layout's preserved bits.
    pub preserved: u8,
    /// Light radii are drawn from `[min, max)` pixels.
    pub radius_px: (f32, f32),
    /// Same seed, same frame.
    pub seed: u64,
}

/// A frame and its lights, every light requesting all BRDFs with the stencil technique.
#[derive(Clone, Debug)]
pub struct SyntheticFrame {
    /// Depth and stencil after a random G-buffer pass: a random depth and BRDF slot per pixel.
    pub target: SoftTarget,
    /// Each light's coverage, in light order.
    pub footprints: Vec<Footprint>,
    /// Each light's request: its footprint's case, every BRDF, the stencil technique.
    pub requests: Vec<LightRequest>,
}

/// xorshift64: tiny, deterministic, good enough for test data.
struct XorShift(u64);

impl XorShift {
    fn unit(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

impl SyntheticFrame {
    /// Draws the frame `desc` describes, the same on every machine for the same desc.
    pub fn generate(desc: &SyntheticDesc) -> Self {
        let mut rng = XorShift(desc.seed | 1);
        let n = (desc.size * desc.size) as usize;
        let brdfs = desc.layout.brdfs_in_use();
        let preserved = desc.preserved & desc.layout.preserved_mask();
        let depth = (0..n).map(|_| rng.unit()).collect();
        let stencil = (0..n)
            .map(|_| {
                let slot = ((rng.unit() * brdfs as f32) as u32).min(brdfs - 1);
                desc.layout.brdf_reference(slot) | preserved
            })
            .collect();
        let size = desc.size as f32;
        let (min, max) = desc.radius_px;
        let footprints: Vec<Footprint> = (0..desc.lights)
            .map(|_| {
                let center = (rng.unit() * size, rng.unit() * size);
                let radius = min + rng.unit() * (max - min);
                let depth = rng.unit();
                let depth_radius = 0.05 + rng.unit() * 0.3;
                Footprint::ellipsoid((desc.size, desc.size), center, radius, depth, depth_radius)
            })
            .collect();
        let requests = footprints
            .iter()
            .map(|fp| LightRequest {
                case: fp.case(),
                affected: (0..brdfs).collect(),
                technique: LightTechnique::Stencil,
            })
            .collect();
        Self {
            target: SoftTarget {
                width: desc.size,
                height: desc.size,
                depth,
                stencil,
            },
            footprints,
            requests,
        }
    }
}
