//! The planner on plain inputs, end to end on the CPU: random boxes (each with a BRDF), point and
//! directional lights, a camera in every depth convention (standard or reversed, finite or
//! infinite far) and layouts with the bits anywhere. A ray caster makes the G-buffer's depth and
//! stencil and each drawn light's footprint (a sphere a little larger than its range, as the
//! volume mesh is); the simulator runs the plan on them. Independent of the planner, the ray
//! caster knows which surfaces each light really reaches: every one of those pixels must be
//! shaded exactly once with its own BRDF, no pixel twice, and the stencil must come back as the
//! platform promises.

mod common;

use common::{backend, layout, Backend};
use histencil_model::{
    plan_frame, Aabb, DepthConvention, FarPlane, FlushPolicy, Footprint, FramePlan, LightCase,
    LightShape, Native, Perspective, PlanInputs, PlanSettings, PlatformBackend, SimResult,
    Simulator, SoftTarget, Span, StencilLayout, TechniqueChoice, View, VOLUME_OVERSHOOT,
};
use proptest::prelude::*;

const WIDTH: u32 = 40;
const HEIGHT: u32 = 28;

#[derive(Clone, Debug)]
struct Light {
    shape: LightShape,
    /// The footprint sphere's radius over the range, in `(1, VOLUME_OVERSHOOT]`.
    mesh_scale: f64,
}

#[derive(Clone, Debug)]
struct World {
    /// Boxes and their BRDF slots.
    boxes: Vec<(Aabb, u32)>,
    lights: Vec<Light>,
    camera: Perspective,
    layout: StencilLayout,
    /// The engine's own bits in every pixel with a surface.
    engine_bits: u8,
}

fn ray_box(origin: [f64; 3], dir: [f64; 3], b: &Aabb) -> Option<f64> {
    let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
    for i in 0..3 {
        let (lo, hi) = (f64::from(b.min[i]), f64::from(b.max[i]));
        if dir[i] == 0.0 {
            if origin[i] < lo || origin[i] > hi {
                return None;
            }
            continue;
        }
        let (a, c) = ((lo - origin[i]) / dir[i], (hi - origin[i]) / dir[i]);
        t0 = t0.max(a.min(c));
        t1 = t1.min(a.max(c));
    }
    (t0 <= t1).then_some(t0)
}

/// Entry and exit parameters of the ray through a sphere.
fn ray_sphere(
    origin: [f64; 3],
    dir: [f64; 3],
    centre: [f64; 3],
    radius: f64,
) -> Option<(f64, f64)> {
    let oc: Vec<f64> = (0..3).map(|i| origin[i] - centre[i]).collect();
    let a: f64 = dir.iter().map(|d| d * d).sum();
    let b: f64 = (0..3).map(|i| oc[i] * dir[i]).sum();
    let c: f64 = oc.iter().map(|o| o * o).sum::<f64>() - radius * radius;
    let disc = b * b - a * c;
    (disc > 0.0).then(|| {
        let root = disc.sqrt();
        ((-b - root) / a, (-b + root) / a)
    })
}

fn at(origin: [f64; 3], dir: [f64; 3], t: f64) -> [f64; 3] {
    [0, 1, 2].map(|i| origin[i] + dir[i] * t)
}

fn ndc(x: u32, y: u32) -> [f64; 2] {
    [
        (f64::from(x) + 0.5) / f64::from(WIDTH) * 2.0 - 1.0,
        (f64::from(y) + 0.5) / f64::from(HEIGHT) * 2.0 - 1.0,
    ]
}

/// The depth of a world point on the pixel's ray, clamped to the far depth as volume pipelines
/// clamp it.
fn depth_of(view: &View, point: [f64; 3]) -> f32 {
    let far = view.depth().far();
    let d = view.project(point).map_or(far, |p| p[2] as f32);
    if view.depth().nearer(far, d) {
        far
    } else {
        d
    }
}

struct Gbuffer {
    target: SoftTarget,
    /// The world point of each pixel's surface.
    points: Vec<Option<[f64; 3]>>,
}

fn gbuffer(world: &World, view: &View) -> Gbuffer {
    let far = view.depth().far();
    let mut target = SoftTarget {
        width: WIDTH,
        height: HEIGHT,
        depth: vec![far; (WIDTH * HEIGHT) as usize],
        stencil: vec![0; (WIDTH * HEIGHT) as usize],
    };
    let mut points = vec![None; (WIDTH * HEIGHT) as usize];
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            let (origin, dir) = view.ray(ndc(x, y));
            let hit = world
                .boxes
                .iter()
                .filter_map(|(b, slot)| ray_box(origin, dir, b).map(|t| (t, *slot)))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            let Some((t, slot)) = hit else { continue };
            let point = at(origin, dir, t);
            let depth = depth_of(view, point);
            // Beyond a finite far plane the G-buffer pass clips the surface: sky.
            if !view.depth().nearer(depth, far) {
                continue;
            }
            let i = target.index(x, y);
            target.depth[i] = depth;
            target.stencil[i] = world.layout.brdf_reference(slot)
                | (world.engine_bits & world.layout.engine_mask());
            points[i] = Some(point);
        }
    }
    Gbuffer { target, points }
}

fn footprint(view: &View, light: &Light) -> Footprint {
    let LightShape::Point { position, range } = light.shape else {
        return Footprint::full_screen(WIDTH, HEIGHT).in_convention(view.depth());
    };
    let centre = position.map(f64::from);
    let radius = f64::from(range) * light.mesh_scale;
    Footprint::from_fn_in(view.depth(), (0, 0, WIDTH, HEIGHT), |x, y| {
        let (origin, dir) = view.ray(ndc(x, y));
        let (t0, t1) = ray_sphere(origin, dir, centre, radius)?;
        (t1 > 0.0).then(|| Span {
            front: (t0 > 0.0).then(|| depth_of(view, at(origin, dir, t0))),
            back: depth_of(view, at(origin, dir, t1)),
        })
    })
}

/// Whether the light really reaches the surface point (its falloff is zero at its range), with
/// a relative margin so that f32 depths cannot disagree.
fn reaches(light: &Light, point: [f64; 3]) -> bool {
    match light.shape {
        LightShape::Point { position, range } => {
            let d2: f64 = (0..3)
                .map(|i| (point[i] - f64::from(position[i])).powi(2))
                .sum();
            d2.sqrt() < f64::from(range) * (1.0 - 1e-3)
        }
        _ => true,
    }
}

fn check(
    world: &World,
    backend: &Backend,
    technique: TechniqueChoice,
) -> Result<(), TestCaseError> {
    let view = View::new(&world.camera.desc()).unwrap();
    let slots = world.layout.brdfs_in_use() as usize;
    let mut brdf_bounds = vec![Vec::new(); slots];
    for (b, slot) in &world.boxes {
        brdf_bounds[*slot as usize].push(*b);
    }
    let shapes: Vec<LightShape> = world.lights.iter().map(|l| l.shape).collect();
    let inputs = PlanInputs {
        lights: &shapes,
        brdf_bounds: &brdf_bounds,
        view: &view,
    };
    let settings = PlanSettings {
        technique,
        caps: backend.boxed().caps(),
        flush: FlushPolicy::Auto,
    };
    let plan: FramePlan = plan_frame(&world.layout, &inputs, &settings).unwrap();
    prop_assert_eq!(plan.depth, world.camera.depth);
    let gbuffer = gbuffer(world, &view);
    let footprints: Vec<Footprint> = plan
        .lights
        .iter()
        .map(|l| footprint(&view, &world.lights[l.input]))
        .collect();
    for (planned, fp) in plan.lights.iter().zip(&footprints) {
        if planned.request.case == LightCase::ViewerInside {
            prop_assert_eq!(
                fp.case(),
                LightCase::ViewerInside,
                "light {}",
                planned.input
            );
            prop_assert_eq!(fp.covered_pixels(), (WIDTH * HEIGHT) as usize);
        }
    }
    let mut target = gbuffer.target.clone();
    let result: SimResult = Simulator {
        layout: world.layout,
        tile_size: 4,
    }
    .run(&mut target, &plan, &footprints);

    for (input, light) in world.lights.iter().enumerate() {
        let drawn = plan.lights.iter().position(|l| l.input == input);
        for y in 0..HEIGHT {
            for x in 0..WIDTH {
                let i = gbuffer.target.index(x, y);
                let slot = world.layout.brdf_slot(gbuffer.target.stencil[i]);
                let count = drawn.map_or(0, |d| result.lights[d].count[i]);
                let must = gbuffer.points[i].is_some_and(|p| reaches(light, p));
                prop_assert!(
                    count <= 1,
                    "light {} shaded ({}, {}) {} times",
                    input,
                    x,
                    y,
                    count
                );
                prop_assert!(
                    !must || count == 1,
                    "light {} (drawn as {:?}) missed ({}, {}) of BRDF {}",
                    input,
                    drawn.map(|d| &plan.lights[d]),
                    x,
                    y,
                    slot
                );
                if count == 1 {
                    let d = drawn.unwrap();
                    prop_assert_eq!(u32::from(result.lights[d].brdf[i]), slot);
                    // Branching shades whatever the volume covers; the light adds nothing
                    // beyond its range. Per-BRDF passes only shade the BRDFs it reaches.
                    if technique == TechniqueChoice::Stencil {
                        prop_assert!(plan.lights[d].request.affected.contains(&slot));
                    }
                }
            }
        }
    }
    prop_assert!(result.culling_bit_left.iter().all(|left| !left));
    let kept = match backend {
        Backend::Native | Backend::Ps3 => 0xFF,
        Backend::X360 {
            save_restore: true, ..
        } => !(world.layout.preserved_mask() & !world.layout.engine_mask()),
        Backend::X360 { .. } => !world.layout.preserved_mask(),
    };
    for (after, before) in target.stencil.iter().zip(&gbuffer.target.stencil) {
        prop_assert_eq!(after & kept, before & kept);
    }
    Ok(())
}

fn depth_convention() -> impl Strategy<Value = (DepthConvention, FarPlane)> {
    prop_oneof![
        Just((DepthConvention::Standard, FarPlane::Finite(40.0))),
        Just((DepthConvention::Standard, FarPlane::Infinite)),
        Just((DepthConvention::Reversed, FarPlane::Finite(40.0))),
        Just((DepthConvention::Reversed, FarPlane::Infinite)),
    ]
}

fn light(eye: [f32; 3]) -> impl Strategy<Value = Light> {
    (
        0u32..12,
        prop::array::uniform3(-8.0f32..8.0),
        prop::array::uniform3(-1.0f32..1.0),
        0.3f32..6.0,
        1.001f64..=VOLUME_OVERSHOOT,
    )
        .prop_map(move |(kind, position, near_eye, range, mesh_scale)| {
            let shape = match kind {
                0 => LightShape::Directional,
                // Around the eye: viewer inside or crossing the near plane.
                1..=3 => LightShape::Point {
                    position: [0, 1, 2].map(|i| eye[i] + near_eye[i] * range),
                    range,
                },
                _ => LightShape::Point { position, range },
            };
            Light { shape, mesh_scale }
        })
}

fn world() -> impl Strategy<Value = World> {
    (
        1u32..=6,
        depth_convention(),
        -1.0f32..1.0,
        3.0f32..12.0,
        prop_oneof![Just(0.05f32), Just(0.1f32), Just(0.5f32)],
        any::<u8>(),
    )
        .prop_flat_map(
            |(brdfs, (depth, far), angle, distance, near, engine_bits)| {
                let eye = [distance * angle.sin(), 1.5, distance * angle.cos()];
                let boxes = proptest::collection::vec(
                    (
                        prop::array::uniform3(-6.0f32..6.0),
                        prop::array::uniform3(0.2f32..3.0),
                        0..brdfs,
                    ),
                    1..6,
                )
                .prop_map(|boxes| {
                    let floor = Aabb {
                        min: [-20.0, -1.5, -20.0],
                        max: [20.0, -1.0, 20.0],
                    };
                    std::iter::once((floor, 0))
                        .chain(boxes.into_iter().map(|(c, h, slot)| {
                            let b = Aabb {
                                min: [0, 1, 2].map(|i| c[i] - h[i]),
                                max: [0, 1, 2].map(|i| c[i] + h[i]),
                            };
                            (b, slot)
                        }))
                        .collect::<Vec<_>>()
                });
                (
                    boxes,
                    proptest::collection::vec(light(eye), 1..6),
                    layout(brdfs),
                )
                    .prop_map(move |(boxes, lights, layout)| World {
                        boxes,
                        lights,
                        camera: Perspective {
                            eye,
                            target: [0.0, 0.0, 0.0],
                            up: [0.0, 1.0, 0.0],
                            fov_y_radians: 1.0,
                            aspect: WIDTH as f32 / HEIGHT as f32,
                            near,
                            far,
                            depth,
                        },
                        layout,
                        engine_bits,
                    })
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn planned_frames_light_every_reached_pixel_once(
        world in world(),
        backend in backend(),
        branching in any::<bool>(),
    ) {
        let technique = if branching { TechniqueChoice::Branching } else { TechniqueChoice::Stencil };
        check(&world, &backend, technique)?;
    }
}

/// The planner's cases on a fixed camera, in every convention: a light around the eye is drawn
/// full-screen, one grazing the near plane crosses it, one ahead is outside, one behind the
/// camera or beyond a finite far plane is not drawn, one that reaches no object is not drawn.
#[test]
fn cases_culling_and_reach_in_every_convention() {
    for (depth, far) in [
        (DepthConvention::Standard, FarPlane::Finite(40.0)),
        (DepthConvention::Standard, FarPlane::Infinite),
        (DepthConvention::Reversed, FarPlane::Finite(40.0)),
        (DepthConvention::Reversed, FarPlane::Infinite),
    ] {
        let camera = Perspective {
            eye: [0.0, 0.0, 10.0],
            target: [0.0; 3],
            up: [0.0, 1.0, 0.0],
            fov_y_radians: 1.0,
            aspect: 1.0,
            near: 0.1,
            far,
            depth,
        };
        let view = View::new(&camera.desc()).unwrap();
        let layout = StencilLayout::new(2, 0).unwrap();
        let wall = Aabb {
            min: [-100.0, -100.0, -90.0],
            max: [100.0, 100.0, 9.8],
        };
        let bounds = vec![vec![wall], vec![]];
        let point = |position: [f32; 3], range| LightShape::Point { position, range };
        let lights = [
            point([0.0, 0.0, 10.0], 1.0),
            point([0.3, 0.0, 9.9], 0.3),
            point([0.0, 0.0, 0.0], 1.0),
            point([0.0, 0.0, 20.0], 1.0),
            point([0.0, 0.0, -60.0], 1.0),
            point([0.0, 0.0, -200.0], 1.0),
            LightShape::Spot {
                position: [0.0, 0.0, 10.0],
                direction: [0.0, 0.0, -1.0],
                range: 5.0,
                outer_angle: 0.5,
            },
            LightShape::Directional,
        ];
        let plan = plan_frame(
            &layout,
            &PlanInputs {
                lights: &lights,
                brdf_bounds: &bounds,
                view: &view,
            },
            &PlanSettings {
                technique: TechniqueChoice::Stencil,
                caps: Native.caps(),
                flush: FlushPolicy::Auto,
            },
        )
        .unwrap();
        let cases: Vec<(usize, LightCase)> = plan
            .lights
            .iter()
            .map(|l| (l.input, l.request.case))
            .collect();
        let mut expected = vec![
            (0, LightCase::ViewerInside),
            (1, LightCase::CrossesNear),
            (2, LightCase::Outside),
        ];
        // At 70 units: beyond a finite far plane of 40, visible with an infinite one. The one
        // at 210 is beyond the wall every object lies in front of: it reaches nothing.
        if far == FarPlane::Infinite {
            expected.push((4, LightCase::Outside));
        }
        expected.push((6, LightCase::CrossesNear));
        expected.push((7, LightCase::FullScreen));
        assert_eq!(cases, expected, "{depth:?} {far:?}");
        let outside = &plan.lights[2];
        assert!(outside.coverage.unwrap() > 0.0 && outside.coverage.unwrap() < 0.1);
        assert!(plan.lights.iter().all(|l| l.request.affected == [0]));
    }
}
