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

/// A white Lambert floor (rho 1) under one `KHR_lights_punctual` light, held pixel by pixel to
/// glTF's own equations in f64 (not to histencil's forward): radiance `I * F(d) * cone * N.L / pi`
/// with `F = w / d^2`, `w = clamp(1 - (d / range)^4, 0, 1)` for a light with a `range`; `1 / d^2`
/// up to the 1/255 cut for one without; a spot's cone the squared linear ramp of the Sample
/// Viewer's `punctual.glsl`. Forward, stencil and tiled each, read back in HDR (f16: 2^-11
/// relative), within 2e-3 of the value plus 2e-4 absolute (the floor's position, which this test
/// recasts from the camera, against the rasteriser's). Before glTF's falloff, the squared window
/// was 20 % darker at two thirds of the range.
#[test]
fn gltf_lights_fall_off_as_gltf_says() {
    use glam::{DVec3, DVec4};
    use histencil_tests::gltf_builder::{quad, Bin};
    use std::f64::consts::PI;
    const SIZE: (u32, u32) = (96, 96);
    let h = std::f32::consts::FRAC_1_SQRT_2;
    // (light, its node's position): the spot points straight down.
    let cases = [
        (
            json!({"type": "point", "color": [1.0, 1.0, 1.0], "intensity": 10.0, "range": 6.0}),
            [0.0, 1.0, 0.0],
        ),
        (
            json!({"type": "point", "color": [1.0, 1.0, 1.0], "intensity": 10.0}),
            [0.5, 1.0, -0.5],
        ),
        (
            json!({"type": "spot", "color": [1.0, 1.0, 1.0], "intensity": 30.0, "range": 8.0,
                   "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.7}}),
            [0.0, 3.0, 0.0],
        ),
    ];
    with_validated_context(|ctx| {
        for (light, at) in &cases {
            let mut bin = Bin::default();
            let mut floor = quad(&mut bin);
            floor["material"] = json!(0);
            let doc = json!({
                "asset": {"version": "2.0"},
                "extensionsUsed": ["KHR_lights_punctual"],
                "extensions": {"KHR_lights_punctual": {"lights": [light]}},
                "materials": [{"name": "white", "extras": {"brdf": "lambert", "rho": 1.0},
                               "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0]}}],
                "meshes": [{"name": "floor", "primitives": [floor]}],
                "cameras": [{"type": "perspective",
                             "perspective": {"yfov": 1.3, "znear": 0.5, "zfar": 20.0}}],
                "nodes": [
                    {"name": "floor", "mesh": 0, "scale": [4.0, 1.0, 4.0]},
                    {"name": "light", "extensions": {"KHR_lights_punctual": {"light": 0}},
                     "translation": at, "rotation": [-h, 0.0, 0.0, h]},
                    {"name": "camera", "camera": 0, "translation": [0.0, 6.0, 0.0],
                     "rotation": [-h, 0.0, 0.0, h]}
                ],
                "scenes": [{"nodes": [0, 1, 2]}],
                "scene": 0,
                "bufferViews": bin.views,
                "accessors": bin.accessors,
                "buffers": [{"uri": "scene.bin", "byteLength": bin.bytes.len()}]
            });
            let text = serde_json::to_vec(&self_contained(&doc, &bin.bytes)).unwrap();
            let scene = histencil_scene::import_gltf(&text, None, "falloff").unwrap();
            let l = &scene.lights[0];
            let (position, range) = (l.position.as_dvec3(), f64::from(l.radius));
            let intensity = f64::from(l.color.x);
            let unlimited = light.get("range").is_none();
            let spot = light.get("spot").map(|s| {
                let angle = |k: &str| s[k].as_f64().unwrap().cos();
                (angle("outerConeAngle"), angle("innerConeAngle"))
            });
            let expected = |p: DVec3| -> f64 {
                let to_light = position - p;
                let d = to_light.length();
                if d >= range {
                    return 0.0;
                }
                let falloff = if unlimited {
                    1.0 / (d * d)
                } else {
                    (1.0 - (d / range).powi(4)).clamp(0.0, 1.0) / (d * d)
                };
                let cone = spot.map_or(1.0, |(cos_outer, cos_inner)| {
                    let c = (-to_light / d).dot(DVec3::NEG_Y);
                    ((c - cos_outer) / (cos_inner - cos_outer))
                        .clamp(0.0, 1.0)
                        .powi(2)
                });
                let n_dot_l = (to_light.y / d).max(0.0);
                intensity * falloff * cone * n_dot_l / PI
            };
            let aspect = SIZE.0 as f32 / SIZE.1 as f32;
            let clip_to_world = (scene.camera.projection(aspect) * scene.camera.view())
                .as_dmat4()
                .inverse();
            let unproject = |x: f64, y: f64, z: f64| {
                let w: DVec4 = clip_to_world * DVec4::new(x, y, z, 1.0);
                w.truncate() / w.w
            };
            let on_floor = |px: u32, py: u32| -> Option<DVec3> {
                let x = (f64::from(px) + 0.5) / f64::from(SIZE.0) * 2.0 - 1.0;
                let y = (f64::from(py) + 0.5) / f64::from(SIZE.1) * 2.0 - 1.0;
                let (a, b) = (unproject(x, y, 0.2), unproject(x, y, 0.8));
                let t = a.y / (a.y - b.y);
                let p = a + (b - a) * t;
                (p.x.abs() < 3.95 && p.z.abs() < 3.95).then_some(p)
            };
            let mut renderer = Renderer::new(ctx, scene.clone(), SIZE.0, SIZE.1).unwrap();
            let techniques: [(&str, Shading); 3] = [
                ("forward", Shading::Forward),
                (
                    "stencil",
                    Technique::Stencil {
                        backend: Backend::Native,
                        flush: FlushPolicy::Auto,
                    }
                    .into(),
                ),
                (
                    "tiled",
                    Technique::Tiled {
                        mixed: histencil_vk::MixedTiles::PerBrdf,
                        side: histencil_vk::TileSide::Eight,
                    }
                    .into(),
                ),
            ];
            for (name, shading) in techniques {
                let readback = Readback {
                    hdr: true,
                    ..Readback::NONE
                };
                let hdr = renderer
                    .render(shading, readback)
                    .unwrap()
                    .images
                    .hdr
                    .unwrap();
                let (mut relative, mut lit, mut brightest) = (0f64, 0, 0f64);
                for (px, py, got) in hdr.enumerate_pixels() {
                    let Some(p) = on_floor(px, py) else {
                        continue;
                    };
                    let want = expected(p);
                    let got = f64::from(got[0]);
                    let error = (got - want).abs() - (2e-3 * want + 2e-4);
                    if want > 1e-2 {
                        relative = relative.max((got / want - 1.0).abs());
                    }
                    lit += usize::from(want > 1e-3);
                    brightest = brightest.max(want);
                    assert!(
                        error <= 0.0,
                        "{light}, {name}: pixel ({px}, {py}) at {p:.3}: {got} where glTF gives {want}"
                    );
                }
                assert!(
                    lit > 2000 && brightest > 0.5,
                    "{light}: {lit} lit, {brightest}"
                );
                println!("{light}, {name}: {lit} pixels lit, {relative:.1e} relative at most");
            }
        }
    });
}
