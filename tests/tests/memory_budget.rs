//! Creation that fails half way frees what it made. A context's memory budget makes every
//! allocation a renderer makes (targets, meshes, textures, descriptors' buffers, the lazily
//! made alpha lightmaps and LUT tables) fail in turn: swept from nothing to what a frame needs,
//! each failure is a clear allocation error, the renderer's memory goes back to zero, and the
//! validation layer's object tracker finds nothing left at device teardown.

use histencil_scene::load_scene;
use histencil_tests::gltf_builder::{textured_gltf, write};
use histencil_vk::{
    Backend, Context, ContextDesc, Error, FlushPolicy, Readback, Renderer, Technique,
};

const SIZE: u32 = 48;

fn techniques() -> [Technique; 2] {
    let (backend, flush) = (Backend::Ps3, FlushPolicy::Auto);
    [
        Technique::Stencil { backend, flush },
        Technique::Lut { backend, flush },
    ]
}

/// Where a renderer under a budget stopped.
#[derive(Debug, PartialEq)]
enum Outcome {
    FailedCreating,
    FailedRendering,
    Rendered,
}

/// Makes a renderer of `scene` on a context with `budget` and renders every technique; the
/// memory in use once the renderer is gone, and where it stopped. Any validation message fails.
fn attempt(scene: &histencil_scene::Scene, budget: Option<u64>) -> (Outcome, u64, u64) {
    let _turn = histencil_tests::instance_turn();
    let ctx = Context::new(ContextDesc {
        memory_budget: budget,
        ..ContextDesc::validated()
    })
    .expect("a validated context");
    let log = ctx.validation_log();
    let allocation_error = |e: Error| {
        assert!(
            matches!(e, Error::Allocation { .. }),
            "budget {budget:?}: not an allocation error: {e}"
        );
        assert!(e.to_string().contains("memory budget"), "{e}");
    };
    let outcome = match Renderer::new(&ctx, scene.clone(), SIZE, SIZE) {
        Err(e) => {
            allocation_error(e);
            Outcome::FailedCreating
        }
        Ok(mut renderer) => {
            let mut outcome = Outcome::Rendered;
            for technique in techniques() {
                match renderer.render(technique, Readback::NONE) {
                    Ok(_) => {}
                    Err(e) => {
                        allocation_error(e);
                        outcome = Outcome::FailedRendering;
                        break;
                    }
                }
            }
            outcome
        }
    };
    let left = ctx.memory_in_use();
    let peak = ctx.memory_peak();
    drop(ctx);
    log.assert_clean();
    (outcome, left, peak)
}

#[test]
fn every_allocation_failure_frees_what_was_made() {
    let (mut doc, bin, checker) = textured_gltf();
    // The LUT technique (whose tables are made lazily, and swept here) refuses a roughness map.
    doc["materials"][0]["pbrMetallicRoughness"]
        .as_object_mut()
        .unwrap()
        .remove("metallicRoughnessTexture");
    let path = write("memory-budget", &doc, &bin);
    std::fs::write(path.with_file_name("checker.png"), checker).unwrap();
    let scene = load_scene(path.to_str().unwrap()).expect("the textured glTF imports");
    assert!(
        !scene.alpha_objects.is_empty(),
        "the lazily made lightmaps are swept too"
    );

    let (outcome, left, full) = attempt(&scene, None);
    assert_eq!((outcome, left), (Outcome::Rendered, 0));
    assert!(full > 0);

    let steps = 20;
    let mut seen = Vec::new();
    for k in 0..steps {
        let budget = full * k / steps;
        let (outcome, left, _) = attempt(&scene, Some(budget));
        assert_eq!(
            left, 0,
            "budget {budget}: {left} bytes still held ({outcome:?})"
        );
        assert_ne!(
            outcome,
            Outcome::Rendered,
            "budget {budget} < {full} was enough"
        );
        seen.push(outcome);
    }
    // The sweep reached both the creation and the first frame's lazy resources.
    assert!(seen.contains(&Outcome::FailedCreating), "{seen:?}");
    assert!(seen.contains(&Outcome::FailedRendering), "{seen:?}");
    let (outcome, left, _) = attempt(&scene, Some(full));
    assert_eq!((outcome, left), (Outcome::Rendered, 0));
}
