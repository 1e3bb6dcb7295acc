//! Plan building and simulation of 1000 lights on a 256x256 frame, per backend.
//!
//! `cargo bench -p histencil-model --bench plan_and_simulate`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use histencil_model::{
    FlushPolicy, FramePlan, Native, PlatformBackend, Ps3Like, Simulator, StencilLayout,
    SyntheticDesc, SyntheticFrame, X360Like,
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

criterion_group!(benches, bench);
criterion_main!(benches);
