//! Alpha (translucent) entities: objects and particle systems that the deferred pass cannot light
//! because they are not in the G-buffer. The renderer lights them through per-entity lightmaps
//! (histencil-alpha decides their layout); these types are only what the scene says.

use crate::{Material, Shape};
use glam::{Mat4, Vec3};

/// A translucent object: a shape whose surface is lit with its own BRDF and blended over what
/// lies behind it with `opacity`.
#[derive(Clone, Debug)]
pub struct AlphaObject {
    /// Names the object in reports and errors.
    pub name: String,
    /// The object's shape in object space.
    pub shape: Shape,
    /// Object to world.
    pub transform: Mat4,
    /// Its BRDF and tint, lit through its lightmap.
    pub material: Material,
    /// Coverage in `[0, 1]`: 0 invisible, 1 opaque.
    pub opacity: f32,
}

impl AlphaObject {
    /// The world-space box containing the object (the transformed unit cube's corners).
    pub fn world_bounds(&self) -> (Vec3, Vec3) {
        transformed_unit_cube(self.transform)
    }
}

/// The corners of `[-1, 1]^3` under `transform`, as a world-space box.
pub(crate) fn transformed_unit_cube(transform: Mat4) -> (Vec3, Vec3) {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for corner in 0..8 {
        let unit = Vec3::new(
            if corner & 1 == 0 { -1.0 } else { 1.0 },
            if corner & 2 == 0 { -1.0 } else { 1.0 },
            if corner & 4 == 0 { -1.0 } else { 1.0 },
        );
        let p = transform.transform_point3(unit);
        lo = lo.min(p);
        hi = hi.max(p);
    }
    (lo, hi)
}

/// How a particle system's light probes are laid out (the talk's parameterisations).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParticleLayout {
    /// One camera-facing quad fitted around the system and centred on it, its texels holding
    /// interpolated positions; each particle reads the texel under its own position.
    Billboard,
    /// `count` such quads stacked along the view direction through the system's depth; a
    /// particle interpolates between the two slices around its depth. For thick systems.
    Slices {
        /// How many quads, 2 to [`MAX_SLICES`] (one is a [`ParticleLayout::Billboard`]).
        count: u32,
    },
    /// Camera-facing quads as above, as many as the lighting needs: the planner estimates the
    /// error along the view direction from the lights that reach the system and picks the
    /// fewest slices that keep it small (one, a billboard, far from every light).
    Auto,
    /// One texel per mote: the mote's own position is its probe.
    Dust,
    /// The particles are the control points of one ribbon (a camera-facing strip through them,
    /// in order); a line of texels along it holds the probes.
    Ribbon,
}

/// One particle: a camera-facing sprite of half-width `size` centred on `position` (for a
/// ribbon, a control point and the strip's half-width there).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Particle {
    /// World position of the sprite's centre.
    pub position: Vec3,
    /// Half-width of the sprite, world units.
    pub size: f32,
}

/// A particle system: sprites of one material, lit together through one layout of probes.
/// Sprites face the camera, and their shading normal points at the eye.
#[derive(Clone, Debug)]
pub struct ParticleSystem {
    /// Names the system in reports and errors.
    pub name: String,
    /// How its probes are laid out.
    pub layout: ParticleLayout,
    /// The sprites (for [`ParticleLayout::Ribbon`], the strip's control points, in order).
    pub particles: Vec<Particle>,
    /// The sprites' BRDF and tint.
    pub material: Material,
    /// Peak coverage of one sprite (at its centre; it falls to zero at its rim).
    pub opacity: f32,
}

/// The most slices a system may ask for: each is a full lightmap region.
pub const MAX_SLICES: u32 = 32;

impl ParticleSystem {
    /// The world-space box containing every sprite.
    pub fn world_bounds(&self) -> (Vec3, Vec3) {
        self.particles.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(p.position - p.size), hi.max(p.position + p.size)),
        )
    }

    /// What is wrong with the system, if anything.
    pub(crate) fn problem(&self) -> Option<&'static str> {
        if self.particles.is_empty() {
            return Some("a particle system needs at least one particle");
        }
        if self
            .particles
            .iter()
            .any(|p| !p.position.is_finite() || !p.size.is_finite() || p.size <= 0.0)
        {
            return Some("particle positions must be finite and sizes finite and positive");
        }
        match self.layout {
            ParticleLayout::Ribbon if self.particles.len() < 2 => {
                Some("a ribbon needs at least two control points")
            }
            ParticleLayout::Slices { count } if !(2..=MAX_SLICES).contains(&count) => {
                Some("slices need 2 to 32 slices (one slice is ParticleLayout::Billboard)")
            }
            _ => None,
        }
    }
}

/// What is wrong with `opacity` and `material` shared by both kinds of entity, if anything.
pub(crate) fn alpha_problem(opacity: f32, material: &Material) -> Option<String> {
    if !(0.0..=1.0).contains(&opacity) {
        return Some("opacity must lie in [0, 1]".to_owned());
    }
    crate::types::material_problem(material)
}
