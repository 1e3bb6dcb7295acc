//! glTF scenes: a file written here, with two BRDFs named in material `extras`, lights from
//! `KHR_lights_punctual`, a camera and a translucent (`alphaMode: BLEND`) quad, renders with the
//! stencil technique within 1/255 of the forward reference. Broken files give the documented
//! errors: a truncated JSON, a truncated buffer, an unknown BRDF name.

use histencil_scene::{load_scene, ImportError, MaterialError, Shape};
use histencil_tests::gltf_builder::{committed_scene_path, self_contained, test_gltf, write};
use histencil_tests::{assert_close, lit_fraction, output_dir, with_validated_context};
use histencil_vk::{Backend, FlushPolicy, Readback, Renderer, Shading, Technique};
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
        let frame = |r: &mut Renderer, t: Shading| r.render(t, ldr).unwrap().images.ldr.unwrap();
        let deferred = frame(&mut renderer, stencil.into());
        let forward = frame(&mut renderer, Shading::Forward);
        assert!(lit_fraction(&forward) > 0.3, "the scene is lit");
        assert_close("gltf-stencil-vs-forward", &deferred, &forward, 1);
    });
}

/// A glTF whose only mesh is translucent, lit by one point light: the renderer's stencil layout
/// keeps one BRDF slot with no surfaces, and the planner gets one empty list for it (an error
/// before: "brdf_bounds has 0 entries, but the stencil layout has 1 BRDFs"). Every technique
/// renders it, alike to forward.
#[test]
fn a_translucent_only_gltf_renders_with_every_technique() {
    let (mut doc, bin) = test_gltf("blinn_phong");
    // The pane, the warm point light (moved in front of the pane's lit side) and the camera:
    // no box, no floor.
    doc["scenes"][0]["nodes"] = json!([2, 3, 6]);
    doc["nodes"][3]["translation"] = json!([1.2, 1.2, 2.4]);
    let path = write("translucent-only", &doc, &bin);
    let scene = load_scene(path.to_str().unwrap()).expect("it imports");
    assert_eq!(
        (
            scene.objects.len(),
            scene.alpha_objects.len(),
            scene.lights.len()
        ),
        (0, 1, 1)
    );
    let ldr = Readback {
        ldr: true,
        ..Readback::NONE
    };
    with_validated_context(|ctx| {
        let mut renderer = Renderer::new(ctx, scene, 64, 64).unwrap();
        let frame = |r: &mut Renderer, t: Shading| r.render(t, ldr).unwrap().images.ldr.unwrap();
        let forward = frame(&mut renderer, Shading::Forward);
        assert!(lit_fraction(&forward) > 0.01, "the pane is lit");
        for backend in [Backend::Ps3, Backend::Native] {
            let stencil = Technique::Stencil {
                backend,
                flush: FlushPolicy::Auto,
            };
            let deferred = frame(&mut renderer, stencil.into());
            assert_close("translucent-only-vs-forward", &deferred, &forward, 1);
        }
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

/// A sparse accessor (glTF's "these elements differ from the base") as the floor's `POSITION`:
/// with a base view, and without one (zeros); its substitutions land where its indices say.
/// Indices that do not rise, or point past the count, are refused with the accessor named.
#[test]
fn sparse_positions_import_and_bad_ones_are_refused() {
    // Raise the floor quad's corner 2 to y = 0.5, as a sparse substitution of one element.
    let sparse_doc = |indices: &[u32], base_view: bool| {
        let (mut doc, mut bin) = test_gltf("blinn_phong");
        let floor_positions = doc["meshes"][1]["primitives"][0]["attributes"]["POSITION"]
            .as_u64()
            .unwrap() as usize;
        let index_offset = bin.len();
        bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
        let value_offset = bin.len();
        for _ in indices {
            bin.extend([1.0f32, 0.5, -1.0].iter().flat_map(|f| f.to_le_bytes()));
        }
        let views = doc["bufferViews"].as_array_mut().unwrap();
        views.push(json!({"buffer": 0, "byteOffset": index_offset,
                          "byteLength": indices.len() * 4}));
        views.push(json!({"buffer": 0, "byteOffset": value_offset,
                          "byteLength": indices.len() * 12}));
        let (iv, vv) = (views.len() - 2, views.len() - 1);
        let accessor = &mut doc["accessors"][floor_positions];
        accessor["sparse"] = json!({"count": indices.len(),
            "indices": {"bufferView": iv, "componentType": 5125},
            "values": {"bufferView": vv}});
        accessor["max"] = json!([1.0, 0.5, 1.0]);
        if !base_view {
            accessor.as_object_mut().unwrap().remove("bufferView");
        }
        doc["buffers"][0]["byteLength"] = json!(bin.len());
        (doc, bin)
    };
    for base_view in [true, false] {
        let (doc, bin) = sparse_doc(&[2], base_view);
        let path = write(&format!("sparse-{base_view}"), &doc, &bin);
        let scene = load_scene(path.to_str().unwrap()).expect("a sparse accessor imports");
        let floor = scene
            .objects
            .iter()
            .find(|o| o.name.starts_with("floor"))
            .unwrap();
        let Shape::Mesh(mesh) = floor.shape else {
            unreachable!()
        };
        let world: Vec<glam::Vec3> = scene.meshes[mesh as usize]
            .vertices
            .iter()
            .map(|v| floor.transform.transform_point3(v.position.into()))
            .collect();
        let raised = world.iter().filter(|p| (p.y - 0.5).abs() < 1e-4).count();
        // The quad has no normals, so each triangle has its own corners: corner 2 is in both.
        assert_eq!(raised, 2, "base view {base_view}: {world:?}");
        let (lo, hi) = world.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| {
            (lo.min(p.y), hi.max(p.y))
        });
        assert!(lo.abs() < 1e-4 && (hi - 0.5).abs() < 1e-4, "{lo} {hi}");
    }
    for (name, indices) in [("unsorted", &[3u32, 1][..]), ("past-count", &[4][..])] {
        let (doc, bin) = sparse_doc(indices, true);
        let path = write(&format!("sparse-{name}"), &doc, &bin);
        let Err(err) = load_scene(path.to_str().unwrap()) else {
            panic!("{name}: imported");
        };
        assert!(
            err.to_string()
                .contains("must rise strictly and stay below"),
            "{name}: {err}"
        );
    }
}
