//! Textured glTF, end to end: images from an external file, a `data:` URI and a buffer view,
//! `KHR_texture_transform`, a sampler, generated tangents and vertex colours import and render
//! within 1/255 of forward; every class of bad image is a clear error naming the image.

use histencil_scene::{load_scene, Filter, ImportError};
use histencil_tests::gltf_builder::{png, textured_gltf, write};
use histencil_tests::{assert_close, diff, lit_fraction, with_validated_context};
use histencil_vk::{Backend, FlushPolicy, Readback, Renderer, Shading, Technique};
use serde_json::{json, Value};
use std::path::PathBuf;

/// Writes the textured scene (with `doc` changed by `edit`) and its external image.
fn write_textured(name: &str, edit: impl FnOnce(&mut Value)) -> PathBuf {
    let (mut doc, bin, checker) = textured_gltf();
    edit(&mut doc);
    let path = write(name, &doc, &bin);
    std::fs::write(path.with_file_name("checker.png"), checker).unwrap();
    path
}

const LDR: Readback = Readback {
    ldr: true,
    ..Readback::NONE
};

#[test]
fn a_textured_gltf_imports_every_kind_of_image_and_matches_forward() {
    let path = write_textured("textured", |_| {});
    let scene = load_scene(path.to_str().unwrap()).expect("the textured glTF imports");
    assert_eq!(scene.images.len(), 3);
    let floor = scene
        .objects
        .iter()
        .find(|o| o.name.starts_with("floor"))
        .unwrap();
    let maps = floor.material.maps;
    let base = maps.base_color.expect("a base colour map");
    assert_eq!(base.transform, [[4.0, 0.0, 0.0], [0.0, 4.0, 0.0]]);
    assert_eq!(base.sampler.mag, Filter::Nearest);
    assert!(maps.normal.is_some() && maps.metallic_roughness.is_some());
    assert!((maps.normal_scale - 0.8).abs() < 1e-6);
    let floor_mesh = match floor.shape {
        histencil_scene::Shape::Mesh(i) => &scene.meshes[i as usize],
        _ => unreachable!(),
    };
    // Generated tangents: unit, in the surface.
    for v in &floor_mesh.vertices {
        let t = glam::Vec3::from_slice(&v.tangent[..3]);
        assert!((t.length() - 1.0).abs() < 1e-3, "{t}");
        assert!(t.dot(glam::Vec3::from(v.normal)).abs() < 1e-3);
    }
    let untextured = write_textured("untextured", |doc| {
        doc["materials"][0]["pbrMetallicRoughness"] = json!({});
        doc["materials"][0]
            .as_object_mut()
            .unwrap()
            .remove("normalTexture");
    });
    let plain = load_scene(untextured.to_str().unwrap()).unwrap();
    with_validated_context(|ctx| {
        let plain = Renderer::new(ctx, plain, 128, 128)
            .unwrap()
            .render(Shading::Forward, LDR)
            .unwrap()
            .images
            .ldr
            .unwrap();
        let mut r = Renderer::new(ctx, scene, 128, 128).unwrap();
        let mut frame = |t| r.render(t, LDR).unwrap().images.ldr.unwrap();
        let forward = frame(Shading::Forward);
        assert!(lit_fraction(&forward) > 0.3);
        assert!(diff(&forward, &plain).max > 64, "the textures show");
        for backend in [Backend::Ps3, Backend::Native] {
            let flush = FlushPolicy::Auto;
            let stencil = frame(Technique::Stencil { backend, flush }.into());
            assert_close("gltf-textured-stencil", &stencil, &forward, 1);
        }
        let branching = frame(
            Technique::Branching {
                backend: Backend::Native,
                flush: FlushPolicy::Auto,
            }
            .into(),
        );
        assert_close("gltf-textured-branching", &branching, &forward, 1);
    });
}

/// Each class of bad image or texture reference, through each way a glTF holds an image: the
/// import fails with an error that names the image (or the primitive) and says why.
#[test]
fn bad_images_are_refused_naming_the_image() {
    let not_png = b"this is a text file, not an image".to_vec();
    let truncated = png(32, |_, _| [1, 2, 3, 255])[..40].to_vec();
    type Edit = Box<dyn FnOnce(&mut Value, &std::path::Path)>;
    let cases: Vec<(&str, Edit, &str)> = vec![
        (
            "missing-file",
            Box::new(|d, _| d["images"][0]["uri"] = json!("absent.png")),
            "absent.png",
        ),
        (
            "outside-folder",
            Box::new(|d, dir| {
                let outside = dir.parent().unwrap().join("outside-the-scene.png");
                std::fs::write(outside, png(2, |_, _| [0; 4])).unwrap();
                d["images"][0]["uri"] = json!("../outside-the-scene.png");
            }),
            "outside the glTF's folder",
        ),
        (
            "not-an-image",
            Box::new(move |d, dir| {
                std::fs::write(dir.join("notes.png"), &not_png).unwrap();
                d["images"][0]["uri"] = json!("notes.png");
            }),
            "neither a PNG nor a JPEG",
        ),
        (
            "truncated-file",
            Box::new(move |d, dir| {
                std::fs::write(dir.join("cut.png"), &truncated).unwrap();
                d["images"][0]["uri"] = json!("cut.png");
            }),
            "corrupt",
        ),
        (
            "bad-base64",
            Box::new(|d, _| d["images"][1]["uri"] = json!("data:image/png;base64,@@@")),
            "bad base64",
        ),
        (
            "wrong-mime-type",
            Box::new(|d, _| d["images"][2]["mimeType"] = json!("image/jpeg")),
            "declares mimeType image/jpeg but holds image/png",
        ),
        (
            "missing-texcoord",
            Box::new(|d, _| {
                d["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["texCoord"] = json!(1)
            }),
            "TEXCOORD_1, which it lacks",
        ),
        (
            "bad-transform",
            Box::new(|d, _| {
                d["materials"][0]["normalTexture"]["extensions"] =
                    json!({"KHR_texture_transform": {"scale": "big"}})
            }),
            "KHR_texture_transform `scale`",
        ),
    ];
    for (name, edit, why) in cases {
        let (mut doc, bin, checker) = textured_gltf();
        let path = write(&format!("bad-image-{name}"), &doc, &bin);
        let dir = path.parent().unwrap().to_path_buf();
        std::fs::write(dir.join("checker.png"), &checker).unwrap();
        edit(&mut doc, &dir);
        std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
        let Err(err) = load_scene(path.to_str().unwrap()) else {
            panic!("{name}: imported");
        };
        let text = err.to_string();
        assert!(text.contains(why), "{name}: {text}");
        if matches!(err, ImportError::Image { .. }) {
            assert!(text.starts_with("image "), "{name}: {text}");
        }
    }
}

/// `emissiveFactor` times `KHR_materials_emissive_strength`, with its `emissiveTexture`, is
/// what the material emits; the textured scene with it renders within 1/255 of forward and
/// brighter than without; a negative or non-finite emission is refused, naming the object.
#[test]
fn emission_imports_with_its_strength_and_map() {
    let emissive = |factor: Value, strength: Value| {
        move |doc: &mut Value| {
            let m = &mut doc["materials"][0];
            m["emissiveFactor"] = factor;
            m["emissiveTexture"] = json!({"index": 0});
            m["extensions"] =
                json!({"KHR_materials_emissive_strength": {"emissiveStrength": strength}});
            doc["extensionsUsed"]
                .as_array_mut()
                .unwrap()
                .push(json!("KHR_materials_emissive_strength"));
        }
    };
    let path = write_textured("emissive", emissive(json!([0.5, 0.25, 0.125]), json!(4.0)));
    let scene = load_scene(path.to_str().unwrap()).expect("the emissive glTF imports");
    let floor = scene
        .objects
        .iter()
        .find(|o| o.name.starts_with("floor"))
        .unwrap();
    assert_eq!(floor.material.emissive, glam::Vec3::new(2.0, 1.0, 0.5));
    assert!(floor.material.maps.emissive.is_some());
    let plain = load_scene(write_textured("not-emissive", |_| {}).to_str().unwrap()).unwrap();
    with_validated_context(|ctx| {
        let frame = |scene: &histencil_scene::Scene, t| {
            let mut r = Renderer::new(ctx, scene.clone(), 96, 96).unwrap();
            r.render(t, LDR).unwrap().images.ldr.unwrap()
        };
        let forward = frame(&scene, Shading::Forward);
        let unlit = frame(&plain, Shading::Forward);
        let brighter = forward
            .pixels()
            .zip(unlit.pixels())
            .filter(|(a, b)| a.0[0] > b.0[0])
            .count();
        assert!(brighter > 96 * 96 / 4, "{brighter} pixels brighter");
        let stencil = Technique::Stencil {
            backend: Backend::Ps3,
            flush: FlushPolicy::Auto,
        };
        assert_close("gltf-emissive", &frame(&scene, stencil.into()), &forward, 1);
    });
    for (factor, strength) in [
        (json!([0.5, -0.25, 0.0]), json!(1.0)),
        (json!([0.5, 0.25, 0.0]), json!(1e38)),
    ] {
        let path = write_textured("bad-emissive", emissive(factor, strength));
        let err = load_scene(path.to_str().unwrap()).expect_err("refused");
        let message = err.to_string();
        assert!(message.contains("emissive"), "{message}");
    }
}
