//! The lighting breakdown by the talk's pass groups, and "only what the scene needs" in the plans:
//! a one-BRDF scene gets the plain deferred passes, and a light draws only for the BRDFs it
//! touches.

use histencil_model::PassKind;
use histencil_tests::with_validated_context;
use histencil_vk::{Backend, FlushPolicy, FrameDesc, Readback, Renderer, Technique};

const STENCIL: Technique = Technique::Stencil {
    backend: Backend::Native,
    flush: FlushPolicy::Auto,
};

#[test]
fn pass_groups_are_timed_per_brdf() {
    let scene = histencil_scene::embedded("brdfs-3").unwrap();
    with_validated_context(|ctx| {
        let mut renderer = Renderer::new(ctx, scene, 96, 96).expect("renderer");
        let timed = |technique: Technique| FrameDesc {
            pass_timing: true,
            ..technique.into()
        };
        let timings = renderer
            .render_frame(&timed(STENCIL))
            .expect("frame")
            .timings;
        let lighting = timings.lighting.expect("breakdown asked for");
        for group in [
            "setup",
            "shade-lambert",
            "shade-oren_nayar_full",
            "shade-ggx",
            "cleanup",
        ] {
            let ms = lighting
                .group_ms(group)
                .unwrap_or_else(|| panic!("no {group}: {lighting:?}"));
            assert!(ms.is_finite() && ms >= 0.0, "{group}: {ms}");
        }
        assert!(lighting.group_ms("shade-branching").is_none());
        let plan = renderer.plan(STENCIL).unwrap();
        assert_eq!(lighting.per_light.len(), plan.lights.len());
        assert_eq!(
            plan.passes().count(),
            plan.steps.len(),
            "native has no flushes"
        );

        let branching = renderer
            .render_frame(&timed(Technique::DEFERRED))
            .expect("frame")
            .timings
            .lighting
            .unwrap();
        assert!(branching.group_ms("shade-branching").is_some());
        assert!(branching.group_ms("shade-ggx").is_none());

        let plain = renderer
            .render(STENCIL, Readback::NONE)
            .expect("frame")
            .timings;
        assert!(plain.lighting.is_none());
    });
}

#[test]
fn one_brdf_scene_runs_the_plain_deferred_passes() {
    let scene = histencil_scene::embedded("brdfs-1").unwrap();
    with_validated_context(|ctx| {
        let renderer = Renderer::new(ctx, scene, 64, 64).expect("renderer");
        let stencil = renderer.plan(STENCIL).unwrap();
        let deferred = renderer.plan(Technique::DEFERRED).unwrap();
        let kinds =
            |p: &histencil_model::FramePlan| p.passes().map(|p| p.kind).collect::<Vec<PassKind>>();
        assert!(!kinds(&stencil)
            .iter()
            .any(|k| matches!(k, PassKind::Mask(_))));
        assert_eq!(kinds(&stencil).len(), kinds(&deferred).len());
    });
}

#[test]
fn lights_draw_once_per_brdf_they_touch() {
    let scene = histencil_scene::embedded("brdfs-6").unwrap();
    with_validated_context(|ctx| {
        let renderer = Renderer::new(ctx, scene.clone(), 64, 64).expect("renderer");
        let plan = renderer.plan(STENCIL).unwrap();
        for (planned, light) in plan.lights.iter().enumerate() {
            let index = light.input;
            let touched = scene.brdfs_lit_by(&scene.lights[index]).len();
            let shades = plan
                .steps
                .iter()
                .filter(|s| matches!(s, histencil_model::Step::Pass { light, pass } if *light == planned && matches!(pass.kind, PassKind::Shade(_))))
                .count();
            assert_eq!(shades, touched, "light {index}");
        }
        // Lights out of every object's reach are not drawn at all.
        assert!(plan.lights.len() <= scene.lights.len());
    });
}

/// The alpha lightmap pass is timed per entity when asked for, and only when a lightmap pass
/// was recorded.
#[test]
fn lightmaps_are_timed_per_entity() {
    use histencil_vk::AlphaMode;
    let scene = histencil_scene::embedded("alpha").unwrap();
    let entities = scene.alpha_entity_names().len() as u32;
    with_validated_context(|ctx| {
        let mut renderer = Renderer::new(ctx, scene, 96, 96).expect("renderer");
        let desc = |alpha, pass_timing| FrameDesc {
            alpha,
            pass_timing,
            ..STENCIL.into()
        };
        for mode in [AlphaMode::Lightmap, AlphaMode::Directional] {
            let timings = renderer.render_frame(&desc(mode, true)).unwrap().timings;
            let lightmaps = timings.lightmaps.expect("lightmaps timed");
            assert!(lightmaps.clear_ms.is_finite() && lightmaps.clear_ms >= 0.0);
            assert!(!lightmaps.per_entity.is_empty());
            assert!(lightmaps
                .per_entity
                .iter()
                .all(|&(e, ms)| e < entities && ms.is_finite() && ms >= 0.0));
        }
        let untimed = renderer.render_frame(&desc(AlphaMode::Lightmap, false));
        assert!(untimed.unwrap().timings.lightmaps.is_none());
        // Forward-lit alpha records no lightmap pass, so there is nothing to time.
        let forward = renderer.render_frame(&desc(AlphaMode::Forward, true));
        assert!(forward.unwrap().timings.lightmaps.is_none());
    });
}

/// The emulated backends time the emulator's bookkeeping apart from the platform's technique:
/// present, positive and inside the lighting pass for PS3-like and 360-like, every frame, and
/// absent on native, which emulates nothing.
#[test]
fn emulated_backends_time_their_bookkeeping_apart() {
    let scene = histencil_scene::embedded("brdfs-3").unwrap();
    with_validated_context(|ctx| {
        let mut renderer = Renderer::new(ctx, scene, 96, 96).expect("renderer");
        let x360 = Backend::X360 {
            zero_preserved: true,
            save_restore: false,
        };
        let flush = FlushPolicy::Auto;
        for backend in [Backend::Ps3, x360] {
            let technique = Technique::Stencil { backend, flush };
            let timings = renderer
                .render(technique, Readback::NONE)
                .expect("frame")
                .timings;
            let lighting = timings.pass_ms("lighting").unwrap();
            let bookkeeping = timings
                .bookkeeping_ms
                .unwrap_or_else(|| panic!("{backend:?}: no bookkeeping time"));
            assert!(
                bookkeeping > 0.0 && bookkeeping < lighting,
                "{backend:?}: bookkeeping {bookkeeping} ms of lighting {lighting} ms"
            );
            let technique_ms = timings.technique_ms(&["lighting"]);
            assert!((technique_ms + bookkeeping - lighting).abs() < 1e-9);
            // Median over frames keeps it.
            let median = renderer.measure(technique, 3).expect("frames");
            assert!(median.bookkeeping_ms.is_some_and(|b| b > 0.0));
        }
        let native = renderer.render(STENCIL, Readback::NONE).expect("frame");
        assert_eq!(native.timings.bookkeeping_ms, None);
        assert_eq!(
            Some(native.timings.technique_ms(&["lighting"])),
            native.timings.pass_ms("lighting")
        );
    });
}

/// While a frame runs, the wait tells the step observer how far the GPU has got, from the
/// frame's own timestamps (each written once everything before it has finished): what a
/// runner keeps of a hung worker names the GPU's step, not only the CPU's. Every progress line
/// names the passes finished in the frame's order, each line further than the last, and a
/// frame that outlasts the first 50 ms slice has at least one (the frame here takes most of a
/// second on lavapipe; reading the timestamps of a pending frame is validation-clean).
/// lavapipe's fence wait returns only once its queue thread has processed the whole frame,
/// so there the one line says every pass is finished; a GPU shows the passes in between.
#[test]
fn a_running_frame_tells_the_observer_which_passes_the_gpu_finished() {
    use std::sync::{Arc, Mutex};
    let scene = histencil_scene::embedded("huge-lights").unwrap();
    with_validated_context(|ctx| {
        let mut renderer = Renderer::new(ctx, scene, 1280, 720).expect("renderer");
        renderer.render(STENCIL, Readback::NONE).expect("warm-up");
        let lines = Arc::new(Mutex::new(Vec::new()));
        let seen = Arc::clone(&lines);
        ctx.observe_steps(Some(Box::new(move |step: &str| {
            seen.lock().unwrap().push(step.to_owned());
        })));
        let x360 = Technique::Stencil {
            backend: Backend::X360 {
                zero_preserved: true,
                save_restore: false,
            },
            flush: FlushPolicy::Auto,
        };
        let start = std::time::Instant::now();
        let frame = renderer.render(x360, Readback::NONE).expect("frame");
        let took = start.elapsed();
        ctx.observe_steps(None);
        let lines = lines.lock().unwrap().clone();
        let wait = "waiting on the GPU for gbuffer, lighting, tonemap";
        let progress: Vec<&str> = lines
            .iter()
            .filter_map(|l| l.strip_prefix(wait)?.strip_prefix(": "))
            .collect();
        if took > std::time::Duration::from_millis(200) {
            assert!(!progress.is_empty(), "no progress in {took:?}: {lines:?}");
        }
        let passes: Vec<&str> = frame.timings.passes.iter().map(|(name, _)| *name).collect();
        let mut finished_before = 0;
        for line in &progress {
            let finished = match line.strip_prefix("the GPU has finished ") {
                Some("every pass of the frame") => passes.len(),
                Some(rest) => {
                    let (done, next) = rest.split_once(", not ").expect("a next pass");
                    let done: Vec<&str> = done.split(", ").collect();
                    assert_eq!(done, passes[..done.len()], "{line}");
                    assert_eq!(next, passes[done.len()], "{line}");
                    done.len()
                }
                None => {
                    assert!(line.starts_with("the GPU has begun") || line.contains("not begun"));
                    0
                }
            };
            assert!(finished >= finished_before, "{progress:?}");
            finished_before = finished;
        }
        println!("{progress:#?}");
    });
}
