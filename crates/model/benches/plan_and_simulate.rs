//! Plan building and simulation of 1000 lights on a 256x256 frame, per backend; and what the
//! lighting's per-frame check that a plan was made for the frame's view and lights costs, next
//! to planning those 1000 lights with `plan_frame`.
//!
//! `cargo bench -p histencil-model --bench plan_and_simulate`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use histencil_model::{
    plan_frame, Aabb, DepthConvention, FarPlane, FlushPolicy, FramePlan, LightShape, Native,
    Perspective, PlanInputs, PlanSettings, PlatformBackend, Ps3Like, Simulator, StencilLayout,
    SyntheticDesc, SyntheticFrame, TechniqueChoice, View, X360Like,
};
use std::hint::black_box;

const SIZE: u32 = 256;
const LIGHTS: usize = 1000;

/// 4 BRDFs, 2 preserved bits in use, lights of 2 to 34 px radius.
fn scene() -> (StencilLayout, SyntheticFrame) {
    let layout = StencilLayout::new(4, 2).unwrap();
    let frame = SyntheticFrame::generate(&SyntheticDesc {
        size: SIZE,
        lights: LIGHTS,
        layout,
        preserved: 0x40,
        radius_px: (2.0, 34.0),
        seed: 0x9E37_79B9_7F4A_7C15,
    });
    (layout, frame)
}

fn bench(c: &mut Criterion) {
    let (layout, scene) = scene();
    let backends: [(&str, Box<dyn PlatformBackend>); 3] = [
        ("360-like", Box::new(X360Like::default())),
        ("ps3-like", Box::new(Ps3Like)),
        ("native", Box::new(Native)),
    ];
    let mut group = c.benchmark_group("1000-lights-256x256");
    group.sample_size(10);
    for (name, backend) in &backends {
        group.bench_function(BenchmarkId::new("plan", name), |b| {
            b.iter(|| {
                FramePlan::from_requests(
                    &layout,
                    &**backend,
                    black_box(&scene.requests),
                    FlushPolicy::Auto,
                )
                .unwrap()
            })
        });
        let plan =
            FramePlan::from_requests(&layout, &**backend, &scene.requests, FlushPolicy::Auto)
                .unwrap();
        let sim = Simulator {
            layout,
            tile_size: 8,
        };
        group.bench_function(BenchmarkId::new("simulate", name), |b| {
            b.iter(|| {
                let mut target = scene.target.clone();
                sim.run(&mut target, black_box(&plan), &scene.footprints)
            })
        });
    }
    group.finish();
}

/// `plan_frame` on 1000 point lights over a 20 m square of boxes, then the check every recorded
/// frame makes (`PlannedFor::difference`, all 1000 lights equal: its longest path).
fn bench_plan_check(c: &mut Criterion) {
    let layout = StencilLayout::new(4, 0).unwrap();
    let lights: Vec<LightShape> = (0..LIGHTS)
        .map(|i| LightShape::Point {
            position: [
                (i % 40) as f32 * 0.5 - 10.0,
                1.0,
                (i / 40) as f32 * 0.8 - 10.0,
            ],
            range: 1.5,
        })
        .collect();
    let bounds: Vec<Vec<Aabb>> = (0..4)
        .map(|slot| {
            vec![Aabb {
                min: [-10.0 + 5.0 * slot as f32, 0.0, -10.0],
                max: [-5.0 + 5.0 * slot as f32, 2.0, 10.0],
            }]
        })
        .collect();
    let desc = Perspective {
        eye: [0.0, 8.0, 16.0],
        target: [0.0; 3],
        up: [0.0, 1.0, 0.0],
        fov_y_radians: 1.0,
        aspect: 1.0,
        near: 0.1,
        far: FarPlane::Finite(100.0),
        depth: DepthConvention::Standard,
    }
    .desc();
    let view = View::new(&desc).unwrap();
    let inputs = PlanInputs {
        lights: &lights,
        brdf_bounds: &bounds,
        view: &view,
    };
    let settings = PlanSettings {
        technique: TechniqueChoice::Stencil,
        caps: Native.caps(),
        flush: FlushPolicy::Auto,
    };
    let mut group = c.benchmark_group("1000-lights-per-frame");
    group.sample_size(20);
    group.bench_function("plan_frame", |b| {
        b.iter(|| plan_frame(&layout, black_box(&inputs), &settings).unwrap())
    });
    let plan = plan_frame(&layout, &inputs, &settings).unwrap();
    let made_for = plan.made_for.as_deref().unwrap();
    group.bench_function("check the frame against its plan", |b| {
        b.iter(|| {
            let same = made_for.difference(black_box(&desc), lights.iter().copied(), &layout);
            assert!(same.is_none());
        })
    });
    group.finish();
}

criterion_group!(benches, bench, bench_plan_check);
criterion_main!(benches);
