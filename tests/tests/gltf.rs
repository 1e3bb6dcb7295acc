//! glTF scenes: a file written here, with two BRDFs named in material `extras`, lights from
//! `KHR_lights_punctual`, a camera and a translucent (`alphaMode: BLEND`) quad, renders with the
//! stencil technique within 1/255 of the forward reference. Broken files give the documented
//! errors: a truncated JSON, a truncated buffer, an unknown BRDF name.

use histencil_scene::{load_scene, ImportError, MaterialError, Shape};
use histencil_tests::gltf_builder::{committed_scene_path, self_contained, test_gltf, write};
use histencil_tests::{assert_close, lit_fraction, output_dir, with_validated_context};
use histencil_vk::{Backend, FlushPolicy, Readback, Renderer, Technique};
use serde_json::json;

#[test]
fn a_gltf_with_two_brdfs_renders_and_matches_forward() {
    let (doc, bin) = test_gltf("blinn_phong");
    let path = write("good", &doc, &bin);
    let scene = load_scene(path.to_str().unwrap()).expect("the test glTF imports");
    assert_eq!(scene.objects.len(), 2);
    assert_eq!(scene.brdfs_in_use().len(), 2);
    assert_eq!(scene.lights.len(), 3);
    assert_eq!(scene.alpha_objects.len(), 1);
    assert!(matches!(scene.alpha_objects[0].shape, Shape::Mesh(_)));
    assert!((scene.alpha_objects[0].opacity - 0.4).abs() < 1e-6);
    let ldr = Readback {
        ldr: true,
        ..Readback::NONE
    };
    with_validated_context(|ctx| {
        let mut renderer = Renderer::new(ctx, scene, 128, 128).unwrap();
        let stencil = Technique::Stencil {
            backend: Backend::X360 {
                zero_preserved: true,
                save_restore: false,
            },
            flush: FlushPolicy::Auto,
        };
        let frame = |r: &mut Renderer, t| r.render(t, ldr).unwrap().images.ldr.unwrap();
        let deferred = frame(&mut renderer, stencil);
        let forward = frame(&mut renderer, Technique::Forward);
        assert!(lit_fraction(&forward) > 0.3, "the scene is lit");
        assert_close("gltf-stencil-vs-forward", &deferred, &forward, 1);
    });
}

#[test]
fn broken_gltf_files_give_the_documented_errors() {
    let (doc, bin) = test_gltf("blinn_phong");
    let text = serde_json::to_vec(&doc).unwrap();

    let path = write("truncated-json", &doc, &bin);
    std::fs::write(&path, &text[..text.len() / 2]).unwrap();
    let err = load_scene(path.to_str().unwrap()).unwrap_err();
    assert!(matches!(err, ImportError::Parse(_)), "{err}");

    let path = write("truncated-bin", &doc, &bin[..bin.len() - 10]);
    let err = load_scene(path.to_str().unwrap()).unwrap_err();
    assert!(matches!(err, ImportError::Buffer { index: 0, .. }), "{err}");
    assert!(err.to_string().contains("truncated"), "{err}");

    let (doc, bin) = test_gltf("velvet");
    let path = write("unknown-brdf", &doc, &bin);
    let err = load_scene(path.to_str().unwrap()).unwrap_err();
    match &err {
        ImportError::Material {
            index: 1,
            name,
            problem: MaterialError::Brdf(_),
        } => assert_eq!(name, "box"),
        other => panic!("expected the box material's unknown BRDF, got {other}"),
    }
    assert!(err.to_string().contains("unknown BRDF `velvet`"), "{err}");

    let missing = output_dir().join("gltf-none/absent.glb");
    let err = load_scene(missing.to_str().unwrap()).unwrap_err();
    assert!(matches!(err, ImportError::Io { .. }), "{err}");

    let (mut doc, bin) = test_gltf("blinn_phong");
    doc["buffers"][0]["uri"] = json!("missing.bin");
    let path = write("missing-bin", &doc, &bin);
    let err = load_scene(path.to_str().unwrap()).unwrap_err();
    assert!(err.to_string().contains("missing.bin"), "{err}");
}

/// `tests/scenes/two-brdfs.gltf`, which `tools/test` runs `histencil check` on, is the test scene
/// written here (a self-contained copy), so the check covers what these tests cover.
/// `HISTENCIL_BLESS=1` rewrites it.
#[test]
fn the_committed_check_scene_is_the_test_scene() {
    let (doc, bin) = test_gltf("blinn_phong");
    let expected = self_contained(&doc, &bin);
    let path = committed_scene_path();
    if std::env::var_os("HISTENCIL_BLESS").is_some() {
        let mut text = serde_json::to_string_pretty(&expected).unwrap();
        text.push('\n');
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, text).unwrap();
    }
    let committed: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&path).expect("tests/scenes/two-brdfs.gltf"))
            .expect("valid JSON");
    assert!(
        committed == expected,
        "{} is not the test scene: rewrite it with HISTENCIL_BLESS=1",
        path.display()
    );
    let scene = load_scene(path.to_str().unwrap()).expect("it imports");
    assert_eq!(scene.brdfs_in_use().len(), 2);
    assert_eq!(scene.alpha_objects.len(), 1);
}
