//! How many slices and how many texels an alpha entity needs: a CPU estimate of the error its
//! lightmap makes against per-pixel lighting, from its geometry, the lights that reach it and the
//! camera, and the cheapest parameters that keep the estimate under a target.
//!
//! The estimate replays what the GPU does at a few hundred sample points on the entity (points
//! on sprites for a particle system; texels of a finer bake for a mesh): the lighting there
//! (the forward reference, through [`histencil_scene::shade`]) against the lightmap's
//! reconstruction (probes where `lightmap.frag` puts them, bilinear inside a tile and linear
//! between slices as `lightmap_sample.glsl` reads them). Each sample's error is counted in 8-bit
//! steps after the tonemap, as if the layer were opaque over black: a translucent layer changes
//! the frame by its opacity times as much, and the tonemap's difference grows with that factor,
//! so the opaque layer bounds it. (Layers with errors of one sign add up, but the weights of
//! "over" sum to at most one.) Measured against `histencil sweep`, the estimate stays above the
//! error over the alpha pixels at every slice count and side tried (the book's measurements,
//! `docs/src/measurements/alpha.md`, "The estimate against the measurement").
//!
//! The choice is the cheapest one whose estimate stays under the target: for a mesh the smallest
//! side; for a particle system the (slices, side) pair with the fewest texels to light, never
//! beyond what screen coverage can show. Failing that, the most accurate parameters tried.

use crate::entity::{AlphaEntity, AlphaEntityKind};
use crate::layout::{bounding_sphere, projected_diameter, Viewer};
use crate::probes::{fit_frame, ProbeFrame};
use crate::{bake_probes, side_for_coverage, MIN_SIDE};
use glam::{Mat3, Vec3};
use histencil_scene::{shade, Light, Material, ParticleLayout, MAX_SLICES};
use std::collections::HashMap;

/// The default target: the estimated mean error over an entity's samples, in 8-bit steps.
pub const DEFAULT_TARGET: f32 = 2.0;

/// The slice counts tried, fewest first (1 is a billboard).
const SLICE_COUNTS: [u32; 10] = [1, 2, 3, 4, 6, 8, 12, 16, 24, 32];

/// The largest side an object's lightmap is baked at for an estimate: a forced side beyond it
/// is estimated at it.
const ESTIMATED_SIDE_LIMIT: u32 = 256;

/// At most this many sample points per entity: every sprite of a system of 400 (five points
/// each). Fewer miss the few sprites next to a light that carry most of the error: at 256 the
/// estimate fell to half the measured error on `volume`.
const MAX_SAMPLES: usize = 2048;

/// An estimate of a lightmap's error against per-pixel lighting, in 8-bit steps after the
/// tonemap: the coverage-weighted mean and the largest over the entity's samples.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Estimate {
    /// Mean over the samples, weighted by coverage.
    pub mean: f32,
    /// The largest over the samples.
    pub max: f32,
}

/// What kind of lightmap an entity has, as far as its parameters go.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParameterKind {
    /// A mesh's UV layout: a side is chosen.
    Surface,
    /// Camera-facing slices (one: a billboard): their count and side are chosen.
    Slices,
    /// One texel per mote: nothing to choose.
    Dust,
    /// A line of texels along the ribbon, from its length on screen: nothing estimated.
    Ribbon,
}

/// What an entity's lightmap was given and why.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Parameters {
    /// Which of the parameters there were to choose.
    pub kind: ParameterKind,
    /// Camera-facing slices (1: a billboard). 1 for objects, dust and ribbons.
    pub slices: u32,
    /// Texels a side of each tile (a ribbon: texels along it; dust: the grid's width).
    pub side: u32,
    /// The estimated error with these parameters.
    pub estimate: Estimate,
    /// The side screen coverage allows (one texel per 4 pixels): the most the choice may take.
    pub coverage_side: u32,
    /// Whether the author forced the slices or the side (the estimate then only reports).
    pub forced_slices: bool,
    /// Whether the author forced the side.
    pub forced_side: bool,
}

/// The 8-bit value of linear radiance `x` after histencil's tonemap (exposure 1, Reinhard,
/// sRGB), unrounded.
fn tonemapped(x: f32) -> f32 {
    let c = x.max(0.0);
    let c = c / (1.0 + c);
    let s = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    255.0 * s
}

fn error_8bit(a: Vec3, b: Vec3) -> f32 {
    (0..3)
        .map(|i| (tonemapped(a[i]) - tonemapped(b[i])).abs())
        .fold(0.0, f32::max)
}

/// Particles face the viewer: their shading normal points at the eye (alpha.glsl).
fn facing(eye: Vec3, p: Vec3) -> Vec3 {
    (eye - p).try_normalize().unwrap_or(Vec3::Z)
}

/// One sample point: where, its weight (coverage), and its lighting.
struct Sample {
    position: Vec3,
    /// Object samples: the lightmap uv (fine texel centre).
    uv: (f32, f32),
    weight: f32,
    truth: Vec3,
}

/// The lights whose range reaches the entity's bounds: the only ones that light it.
fn reaching(entity: &AlphaEntity, lights: &[Light]) -> Vec<Light> {
    entity
        .lights_reaching(lights)
        .into_iter()
        .map(|l| lights[l as usize])
        .collect()
}

/// The side screen coverage allows for `entity` seen by `viewer` on a `viewport_height` view.
pub fn coverage_side(entity: &AlphaEntity, viewer: &Viewer, viewport_height: u32) -> u32 {
    let (centre, radius) = bounding_sphere(entity.world_bounds());
    side_for_coverage(projected_diameter(viewer, centre, radius, viewport_height))
}

/// A particle system's samples: the centre of each sprite and four points half way to its rim
/// (coverage 3/4 there), from at most [`MAX_SAMPLES`] / 5 sprites spread over the system.
fn particle_samples(
    particles: &[histencil_scene::Particle],
    viewer: &Viewer,
    shade_at: &dyn Fn(Vec3) -> Vec3,
) -> Vec<Sample> {
    let stride = particles.len().div_ceil(MAX_SAMPLES / 5).max(1);
    let mut out = Vec::new();
    for p in particles.iter().step_by(stride) {
        let half = p.size * 0.5;
        for (dx, dy, weight) in [
            (0.0, 0.0, 1.0),
            (half, 0.0, 0.75),
            (-half, 0.0, 0.75),
            (0.0, half, 0.75),
            (0.0, -half, 0.75),
        ] {
            let position = p.position + viewer.right * dx + viewer.up * dy;
            out.push(Sample {
                position,
                uv: (0.0, 0.0),
                weight,
                truth: shade_at(position),
            });
        }
    }
    out
}

/// Bilinear inside a `side x side` tile at `(u, v)`, clamped to the tile, from `texel(i, j)`
/// (lightmap_sample.glsl's `lightmap_tile`).
fn bilinear(side: u32, (u, v): (f32, f32), texel: &mut dyn FnMut(u32, u32) -> Vec3) -> Vec3 {
    let size = side as f32;
    let tx = (u * size - 0.5).clamp(0.0, size - 1.0);
    let ty = (v * size - 0.5).clamp(0.0, size - 1.0);
    let (i0, j0) = (tx.floor() as u32, ty.floor() as u32);
    let (fx, fy) = (tx - i0 as f32, ty - j0 as f32);
    let (i1, j1) = ((i0 + 1).min(side - 1), (j0 + 1).min(side - 1));
    let a = texel(i0, j0);
    let b = texel(i1, j0);
    let c = texel(i0, j1);
    let d = texel(i1, j1);
    a.lerp(b, fx).lerp(c.lerp(d, fx), fy)
}

fn summarise(samples: &[Sample], values: impl Iterator<Item = Vec3>) -> Estimate {
    let (mut sum, mut weights, mut max) = (0.0f32, 0.0f32, 0.0f32);
    for (s, v) in samples.iter().zip(values) {
        let e = error_8bit(s.truth, v);
        sum += e * s.weight;
        weights += s.weight;
        max = max.max(e);
    }
    Estimate {
        mean: if weights > 0.0 { sum / weights } else { 0.0 },
        max,
    }
}

/// A sliced (or billboard) system's lightmap at `slices x side`: probes at texel centres of
/// each slice, lit facing the eye; each sample reads its two slices bilinearly.
fn sliced_estimate(
    samples: &[Sample],
    frame: &ProbeFrame,
    (slices, side): (u32, u32),
    shade_at: &dyn Fn(Vec3) -> Vec3,
) -> Estimate {
    let mut probes: HashMap<(u32, u32, u32), Vec3> = HashMap::new();
    let mut probe = |i: u32, j: u32, k: u32| {
        *probes.entry((i, j, k)).or_insert_with(|| {
            let (u, v) = (
                (i as f32 + 0.5) / side as f32,
                (j as f32 + 0.5) / side as f32,
            );
            shade_at(frame.probe(u, v, k, slices))
        })
    };
    let values: Vec<Vec3> = samples
        .iter()
        .map(|s| {
            let (u, v, depth) = frame.locate(s.position, slices);
            let k0 = depth.floor() as u32;
            let k1 = (k0 + 1).min(slices - 1);
            let a = bilinear(side, (u, v), &mut |i, j| probe(i, j, k0));
            let b = bilinear(side, (u, v), &mut |i, j| probe(i, j, k1));
            a.lerp(b, depth - k0 as f32)
        })
        .collect();
    summarise(samples, values.into_iter())
}

/// An object's samples: covered texels of a bake twice as fine as the largest side tried (at
/// most 256) on an even sub-grid of at most about [`MAX_SAMPLES`], those facing the eye (the
/// alpha pass culls back faces), each weighted by the screen area it covers (its world area,
/// foreshortened, over its squared distance), as the error over screen pixels weighs it.
fn object_samples(
    mesh: &histencil_scene::Mesh,
    fine: u32,
    eye: Vec3,
    shade_at: &dyn Fn(Vec3, Vec3) -> Vec3,
    to_world: &dyn Fn(Vec3, Vec3) -> (Vec3, Vec3),
) -> Vec<Sample> {
    let baked = bake_probes(mesh, fine, fine);
    let at = |x: u32, y: u32| {
        let p = baked.probes.get((y * fine + x) as usize)?;
        (x < fine && p.position[3] == 1.0).then(|| {
            to_world(
                Vec3::from_slice(&p.position[..3]),
                Vec3::from_slice(&p.normal[..3]),
            )
        })
    };
    let covered = baked.probes.iter().filter(|p| p.position[3] == 1.0).count();
    let step = ((covered as f32 / MAX_SAMPLES as f32).sqrt().ceil() as u32).max(1);
    let mut out = Vec::new();
    for y in (step / 2..fine).step_by(step as usize) {
        for x in (step / 2..fine).step_by(step as usize) {
            let Some((position, normal)) = at(x, y) else {
                continue;
            };
            let to_eye = eye - position;
            let distance = to_eye.length();
            let facing = normal.dot(to_eye) / distance.max(1e-6);
            if facing <= 0.0 {
                continue;
            }
            // The texel's world area from its neighbours (either side).
            let along = |dx: i32, dy: i32| {
                let n = at(x.wrapping_add_signed(dx), y.wrapping_add_signed(dy))
                    .or_else(|| at(x.wrapping_add_signed(-dx), y.wrapping_add_signed(-dy)))?;
                Some(n.0 - position)
            };
            let (Some(du), Some(dv)) = (along(1, 0), along(0, 1)) else {
                continue;
            };
            let area = du.cross(dv).length();
            out.push(Sample {
                position,
                uv: (
                    (x as f32 + 0.5) / fine as f32,
                    (y as f32 + 0.5) / fine as f32,
                ),
                weight: area * facing / (distance * distance).max(1e-6),
                truth: shade_at(position, normal),
            });
        }
    }
    out
}

/// An object's lightmap at `side`: probes baked at that side, lit where covered and black where
/// not (as `lightmap.frag` leaves them), read bilinearly at each sample's uv.
fn object_estimate(
    samples: &[Sample],
    mesh: &histencil_scene::Mesh,
    side: u32,
    shade_at: &dyn Fn(Vec3, Vec3) -> Vec3,
    to_world: &dyn Fn(Vec3, Vec3) -> (Vec3, Vec3),
) -> Estimate {
    let baked = bake_probes(mesh, side, side);
    let mut lit: HashMap<(u32, u32), Vec3> = HashMap::new();
    let mut texel = |i: u32, j: u32| {
        *lit.entry((i, j)).or_insert_with(|| {
            let p = baked.probes[(j * side + i) as usize];
            if p.position[3] == 0.0 {
                return Vec3::ZERO;
            }
            let (position, normal) = to_world(
                Vec3::from_slice(&p.position[..3]),
                Vec3::from_slice(&p.normal[..3]),
            );
            shade_at(position, normal)
        })
    };
    let values: Vec<Vec3> = samples
        .iter()
        .map(|s| bilinear(side, s.uv, &mut texel))
        .collect();
    summarise(samples, values.into_iter())
}

/// The sides tried, smallest first: powers of two from [`MIN_SIDE`] to `max`.
fn sides_up_to(max: u32) -> impl Iterator<Item = u32> {
    std::iter::successors(Some(MIN_SIDE.min(max)), move |s| {
        (s * 2 <= max).then_some(s * 2)
    })
}

/// What an estimate replays for one entity, set up once: its sample points and their lighting,
/// and how its lightmap reconstructs them.
enum Replay<'a> {
    /// A mesh: probes baked from its UV layout, carried to the world by its transform.
    Surface {
        mesh: &'a histencil_scene::Mesh,
        samples: Vec<Sample>,
        shade_at: Box<dyn Fn(Vec3, Vec3) -> Vec3 + 'a>,
        to_world: Box<dyn Fn(Vec3, Vec3) -> (Vec3, Vec3) + 'a>,
    },
    /// Camera-facing slices around a particle system.
    Sliced {
        samples: Vec<Sample>,
        frame: ProbeFrame,
        shade_at: Box<dyn Fn(Vec3) -> Vec3 + 'a>,
    },
    /// Dust and ribbons: nothing to choose.
    Nothing,
}

impl<'a> Replay<'a> {
    /// The replay of `entity` seen by `viewer`, lit by `lights` (those that reach it) with
    /// `material`; a mesh's samples from a bake `fine` texels a side.
    fn new<'e: 'a>(
        entity: &AlphaEntity<'e>,
        viewer: &Viewer,
        lights: &'a [Light],
        material: &'a Material,
        fine: u32,
    ) -> Self {
        let eye = viewer.eye;
        match entity.kind {
            AlphaEntityKind::Object {
                probe_mesh,
                transform,
                ..
            } => {
                let normal_matrix = Mat3::from_mat4(transform).inverse().transpose();
                let shade_at = Box::new(move |p, n| shade(lights, material, p, n, eye));
                let to_world = Box::new(move |p, n: Vec3| {
                    (
                        transform.transform_point3(p),
                        (normal_matrix * n).try_normalize().unwrap_or(Vec3::Z),
                    )
                });
                let samples = object_samples(probe_mesh, fine, eye, &shade_at, &to_world);
                Replay::Surface {
                    mesh: probe_mesh,
                    samples,
                    shade_at,
                    to_world,
                }
            }
            AlphaEntityKind::Particles { layout, particles } => match layout {
                ParticleLayout::Dust | ParticleLayout::Ribbon => Replay::Nothing,
                _ => {
                    let shade_at =
                        Box::new(move |p: Vec3| shade(lights, material, p, facing(eye, p), eye));
                    Replay::Sliced {
                        samples: particle_samples(particles, viewer, &shade_at),
                        frame: fit_frame(viewer, particles),
                        shade_at,
                    }
                }
            },
        }
    }

    /// The estimate at `slices x side` (a mesh ignores `slices`; beyond
    /// [`ESTIMATED_SIDE_LIMIT`] texels the estimate there stands for it, as more texels never
    /// raise the error, so a forced huge side costs no huge bake).
    fn estimate(&self, slices: u32, side: u32) -> Estimate {
        match self {
            Replay::Surface {
                mesh,
                samples,
                shade_at,
                to_world,
            } => {
                let side = side.min(ESTIMATED_SIDE_LIMIT);
                object_estimate(samples, mesh, side, shade_at, to_world)
            }
            Replay::Sliced {
                samples,
                frame,
                shade_at,
            } => sliced_estimate(samples, frame, (slices.max(1), side), shade_at),
            Replay::Nothing => Estimate::default(),
        }
    }
}

/// The bake a mesh's samples come from: twice as fine as the largest side tried, within
/// 64..=[`ESTIMATED_SIDE_LIMIT`].
fn fine_side(largest: u32) -> u32 {
    (2 * largest.min(ESTIMATED_SIDE_LIMIT)).clamp(64, ESTIMATED_SIDE_LIMIT)
}

/// The material the estimate shades with: the entity's own, or for an engine's BRDF (which has
/// no CPU spelling, `histencil_brdf::Brdf::Engine`) a white Lambert surface of its tint. The
/// estimate then follows how the incident light varies over the entity, which is what a
/// lightmap's resolution and slices must follow, but not the BRDF's own angular detail: an
/// engine BRDF's estimate is a guide, not the bound a built-in's is.
fn estimated_material(material: Material) -> Material {
    if material.brdf.id().is_builtin() {
        return material;
    }
    Material {
        brdf: histencil_brdf::Brdf::Lambert { rho: 1.0 },
        ..material
    }
}

/// The estimated error of `entity`'s lightmap at `slices x side`, lit by `lights` and seen by
/// `viewer`. Dust and ribbons have nothing to choose and estimate to zero.
pub fn estimate(
    entity: &AlphaEntity,
    viewer: &Viewer,
    lights: &[Light],
    slices: u32,
    side: u32,
) -> Estimate {
    let lights = reaching(entity, lights);
    let material = estimated_material(entity.material);
    let replay = Replay::new(entity, viewer, &lights, &material, fine_side(side));
    replay.estimate(slices, side)
}

/// The cheapest parameters whose estimate stays under `target` (8-bit steps, mean), within
/// what coverage allows; a forced side (`forced_side`) or a forced layout (a billboard or
/// `Slices`) is kept and only estimated. `ParticleLayout::Auto` systems get their slices here.
pub fn choose_parameters(
    entity: &AlphaEntity,
    viewer: &Viewer,
    lights: &[Light],
    viewport_height: u32,
    forced_side: Option<u32>,
    target: f32,
) -> Parameters {
    let coverage = coverage_side(entity, viewer, viewport_height);
    let lights = reaching(entity, lights);
    let material = estimated_material(entity.material);
    let base = Parameters {
        kind: ParameterKind::Surface,
        slices: 1,
        side: forced_side.unwrap_or(coverage),
        estimate: Estimate::default(),
        coverage_side: coverage,
        forced_slices: true,
        forced_side: forced_side.is_some(),
    };
    let forced_slices = match entity.kind {
        AlphaEntityKind::Object { .. } => Some(1),
        AlphaEntityKind::Particles { layout, .. } => match layout {
            ParticleLayout::Dust => {
                return Parameters {
                    kind: ParameterKind::Dust,
                    ..base
                }
            }
            ParticleLayout::Ribbon => {
                return Parameters {
                    kind: ParameterKind::Ribbon,
                    ..base
                }
            }
            ParticleLayout::Billboard => Some(1),
            ParticleLayout::Slices { count } => Some(count),
            ParticleLayout::Auto => None,
        },
    };
    let replay = Replay::new(entity, viewer, &lights, &material, fine_side(coverage));
    let sides: Vec<u32> = match forced_side {
        Some(side) => vec![side],
        None => sides_up_to(coverage).collect(),
    };
    if let Replay::Surface { .. } = replay {
        // The smallest side under the target; failing that, the largest tried.
        let mut last = None;
        for &side in &sides {
            let e = replay.estimate(1, side);
            last = Some((side, e));
            if e.mean <= target {
                break;
            }
        }
        let (side, estimate) = last.expect("at least one side");
        return Parameters {
            side,
            estimate,
            ..base
        };
    }
    let counts: Vec<u32> = match forced_slices {
        Some(n) => vec![n],
        None => SLICE_COUNTS
            .into_iter()
            .filter(|&n| n <= MAX_SLICES)
            .collect(),
    };
    // The cheapest (slices x side^2 texels to light) pair under the target; failing that, the
    // most accurate one tried.
    let mut best: Option<(u64, u32, u32, Estimate)> = None;
    let mut fallback: Option<(u32, u32, Estimate)> = None;
    for &n in &counts {
        for &side in &sides {
            let cost = u64::from(n) * u64::from(side) * u64::from(side);
            if best.is_some_and(|b| b.0 <= cost) {
                break;
            }
            let e = replay.estimate(n, side);
            if fallback.is_none_or(|f| e.mean < f.2.mean) {
                fallback = Some((n, side, e));
            }
            if e.mean <= target {
                best = Some((cost, n, side, e));
                break;
            }
        }
    }
    let (slices, side, estimate) = match (best, fallback) {
        (Some((_, n, side, e)), _) => (n, side, e),
        (None, Some(f)) => f,
        (None, None) => unreachable!("at least one pair is tried"),
    };
    Parameters {
        kind: ParameterKind::Slices,
        slices,
        side,
        estimate,
        forced_slices: forced_slices.is_some(),
        ..base
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{scene_alpha_entities, ProbeMeshes};

    fn viewer_of(scene: &histencil_scene::Scene) -> Viewer {
        Viewer::from_camera(&scene.camera)
    }

    /// Far from every light (the scene's ambient directional light aside): one quad and the
    /// smallest side. Lights inside: slices.
    #[test]
    fn a_system_buys_slices_only_around_a_light() {
        let scene = histencil_scene::embedded("volume").unwrap();
        let meshes = ProbeMeshes::new(&scene);
        let mut entities = scene_alpha_entities(&scene, &meshes);
        let system = scene.alpha_objects.len();
        if let AlphaEntityKind::Particles { layout, .. } = &mut entities[system].kind {
            *layout = ParticleLayout::Auto;
        }
        let viewer = viewer_of(&scene);
        let lit = choose_parameters(&entities[system], &viewer, &scene.lights, 720, None, 2.0);
        assert!(lit.slices >= 3, "{lit:?}");
        assert!(lit.estimate.mean <= 2.0, "{lit:?}");
        // The same system with its lights moved far away: nothing to resolve.
        let far: Vec<Light> = scene
            .lights
            .iter()
            .map(|l| Light {
                position: l.position + Vec3::new(0.0, 1000.0, 0.0),
                ..*l
            })
            .collect();
        let dark = choose_parameters(&entities[system], &viewer, &far, 720, None, 1.0);
        assert_eq!((dark.slices, dark.side), (1, MIN_SIDE), "{dark:?}");
        assert!(dark.estimate.mean <= 1.0, "{dark:?}");
    }

    /// More texels and more slices never make the estimate worse by much, and the chosen
    /// parameters are the cheapest that meet the target along each axis.
    #[test]
    fn estimates_fall_as_resolution_grows() {
        let scene = histencil_scene::embedded("alpha").unwrap();
        let meshes = ProbeMeshes::new(&scene);
        let entities = scene_alpha_entities(&scene, &meshes);
        let viewer = viewer_of(&scene);
        let sphere = &entities[0];
        let coarse = estimate(sphere, &viewer, &scene.lights, 1, 8);
        let fine = estimate(sphere, &viewer, &scene.lights, 1, 64);
        assert!(fine.mean < coarse.mean, "{coarse:?} {fine:?}");
        let chosen = choose_parameters(sphere, &viewer, &scene.lights, 720, None, 1.0);
        assert!(chosen.side <= chosen.coverage_side);
        assert!(chosen.estimate.mean <= 1.0 || chosen.side == chosen.coverage_side);
        if chosen.side > MIN_SIDE {
            let half = estimate(sphere, &viewer, &scene.lights, 1, chosen.side / 2);
            assert!(half.mean > 1.0, "{chosen:?} {half:?}");
        }
        let forced = choose_parameters(sphere, &viewer, &scene.lights, 720, Some(16), 1.0);
        assert_eq!((forced.side, forced.forced_side), (16, true));
    }

    #[test]
    fn bilinear_reads_like_the_shader() {
        // A 2x2 tile: texel centres at 0.25 and 0.75; the middle is the average.
        let mut t = |i: u32, j: u32| Vec3::splat((i + 2 * j) as f32);
        assert_eq!(bilinear(2, (0.5, 0.5), &mut t), Vec3::splat(1.5));
        assert_eq!(bilinear(2, (0.0, 0.0), &mut t), Vec3::ZERO);
        assert_eq!(bilinear(2, (1.0, 1.0), &mut t), Vec3::splat(3.0));
    }
}
