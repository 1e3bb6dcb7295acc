//! The Khronos sample models in `../shared/gltf-sample-models` (read there, never copied into
//! the repository), where what a correct import gives can be checked without a picture.
//! Where the folder is absent the tests say so and check nothing.

use histencil_scene::{import_gltf, Scene};
use std::collections::HashMap;
use std::path::PathBuf;

fn models() -> Option<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/gltf-sample-models");
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!("SKIPPED: no sample models at {}", dir.display());
        None
    }
}

/// Imports `model/file` after `edit` changed its JSON.
fn import_edited(model: &str, file: &str, edit: impl Fn(&mut serde_json::Value)) -> Scene {
    let dir = models().expect("checked by the caller").join(model);
    let mut json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join(file)).unwrap()).unwrap();
    edit(&mut json);
    import_gltf(&serde_json::to_vec(&json).unwrap(), Some(&dir), model).unwrap()
}

/// Tangents histencil generates (MikkTSpace) have the handedness of the tangents the model's
/// exporter wrote: NormalTangentMirrorTest imported with its `TANGENT` attributes and without
/// them gives, at every vertex both have, the same sign `w` and nearly the same direction.
#[test]
fn generated_tangents_have_the_handedness_of_supplied_ones() {
    if models().is_none() {
        return;
    }
    let model = "NormalTangentMirrorTest";
    let file = "NormalTangentMirrorTest.gltf";
    let supplied = import_edited(model, file, |_| {});
    let generated = import_edited(model, file, |json| {
        for mesh in json["meshes"].as_array_mut().unwrap() {
            for primitive in mesh["primitives"].as_array_mut().unwrap() {
                primitive["attributes"]
                    .as_object_mut()
                    .unwrap()
                    .remove("TANGENT");
            }
        }
    });
    assert_eq!(supplied.meshes.len(), generated.meshes.len());
    let (mut compared, mut flipped, mut worst_cos) = (0, 0, 1.0f32);
    for (a, b) in supplied.meshes.iter().zip(&generated.meshes) {
        let key = |v: &histencil_scene::Vertex| {
            let bits = |x: &[f32]| x.iter().map(|c| c.to_bits()).collect::<Vec<_>>();
            (bits(&v.position), bits(&v.normal), bits(&v.uv))
        };
        let made: HashMap<_, _> = b.vertices.iter().map(|v| (key(v), v.tangent)).collect();
        for v in &a.vertices {
            let Some(t) = made.get(&key(v)) else {
                continue;
            };
            compared += 1;
            if t[3] != v.tangent[3] {
                flipped += 1;
            }
            let cos: f32 = t[..3].iter().zip(&v.tangent[..3]).map(|(x, y)| x * y).sum();
            worst_cos = worst_cos.min(cos);
        }
    }
    assert!(compared > 1000, "only {compared} vertices matched");
    assert_eq!(
        flipped, 0,
        "{flipped} of {compared} generated tangents flipped"
    );
    assert!(
        worst_cos > 0.9,
        "a generated tangent is {worst_cos} (cosine) from its supplied one"
    );
}

/// Avocado is a textured metal-rough dielectric (`metallicFactor` 1 scaled by a texture's blue
/// near 0): with glTF's own BRDF it is lit like the object it is. It rendered at a mean of
/// 7/255 over its pixels when metal-rough materials were forced onto GGX without a diffuse term.
#[test]
fn a_metal_rough_dielectric_is_lit_like_one() {
    let Some(dir) = models() else {
        return;
    };
    let scene = histencil_scene::load_gltf(&dir.join("Avocado/Avocado.gltf")).unwrap();
    let (scene, rigged) =
        histencil_scene::with_default_lights(scene, histencil_scene::DefaultLights::IfNone);
    assert!(rigged, "Avocado has no lights of its own");
    let frames = histencil_tests::with_validated_context(|ctx| {
        let mut renderer = histencil_vk::Renderer::new(ctx, scene, 128, 128).unwrap();
        [
            histencil_vk::Shading::Forward,
            histencil_vk::Technique::DEFERRED.into(),
        ]
        .map(|shading| {
            let readback = histencil_vk::Readback {
                ldr: true,
                ..histencil_vk::Readback::NONE
            };
            renderer
                .render(shading, readback)
                .unwrap()
                .images
                .ldr
                .unwrap()
        })
    });
    let [forward, deferred] = &frames;
    let covered: Vec<&image::Rgba<u8>> = forward.pixels().filter(|p| p.0[..3] != [0; 3]).collect();
    let mean = covered
        .iter()
        .map(|p| p.0[..3].iter().map(|c| f64::from(*c)).sum::<f64>() / 3.0)
        .sum::<f64>()
        / covered.len() as f64;
    assert!(covered.len() > 1000, "{} pixels covered", covered.len());
    assert!(mean > 40.0, "Avocado's pixels average {mean:.1}/255");
    let d = histencil_tests::diff(deferred, forward);
    assert!(d.max <= 1, "deferred is {}/255 from forward", d.max);
}

/// Duck-Quantized (`KHR_mesh_quantization`, as gltfpack writes it: u16 positions dequantized by
/// the node's transform, i8 normalised normals, u16 texture coordinates) renders as Duck does:
/// the same picture, within quantization's error on the shading and the silhouette.
#[test]
fn a_quantized_mesh_renders_as_its_float_original() {
    let Some(dir) = models() else {
        return;
    };
    let render = |file: &str| {
        let scene = histencil_scene::load_gltf(&dir.join(file)).unwrap();
        let (scene, _) =
            histencil_scene::with_default_lights(scene, histencil_scene::DefaultLights::IfNone);
        histencil_tests::with_validated_context(|ctx| {
            let mut renderer = histencil_vk::Renderer::new(ctx, scene, 128, 128).unwrap();
            let readback = histencil_vk::Readback {
                ldr: true,
                ..histencil_vk::Readback::NONE
            };
            let images = renderer.render(histencil_vk::Technique::DEFERRED, readback);
            images.unwrap().images.ldr.unwrap()
        })
    };
    let quantized = render("Duck-Quantized/Duck.gltf");
    let original = render("Duck/Duck.glb");
    let lit = original.pixels().filter(|p| p.0[..3] != [0; 3]).count();
    assert!(lit > 1000, "the duck covers {lit} pixels");
    let d = histencil_tests::diff(&quantized, &original);
    println!("quantized against float: {d:?}");
    // Measured: mean 0.016/255, max 41/255 on silhouette pixels.
    assert!(d.mean < 0.1, "{d:?}");
}

/// The mean colour of each of the eight rows of TextureSettingsTest's "Test" and "Sample pass"
/// columns, at 256x256 under the default rig (the board is framed the same way every time).
fn texture_settings_columns(edit: impl Fn(&mut Scene)) -> Vec<([f64; 3], [f64; 3])> {
    let dir = models().expect("checked by the caller");
    let file = dir.join("TextureSettingsTest/TextureSettingsTest.gltf");
    let (mut scene, _) = histencil_scene::with_default_lights(
        histencil_scene::load_gltf(&file).unwrap(),
        histencil_scene::DefaultLights::IfNone,
    );
    edit(&mut scene);
    let frame = histencil_tests::with_validated_context(|ctx| {
        let mut renderer = histencil_vk::Renderer::new(ctx, scene, 256, 256).unwrap();
        let readback = histencil_vk::Readback {
            ldr: true,
            ..histencil_vk::Readback::NONE
        };
        let images = renderer.render(histencil_vk::Shading::Forward, readback);
        images.unwrap().images.ldr.unwrap()
    });
    let mean = |x0: u32, y0: u32, x1: u32, y1: u32| {
        let mut sum = [0.0; 3];
        for y in y0..y1 {
            for x in x0..x1 {
                for (s, c) in sum.iter_mut().zip(frame.get_pixel(x, y).0) {
                    *s += f64::from(c);
                }
            }
        }
        sum.map(|s| s / f64::from((x1 - x0) * (y1 - y0)))
    };
    // Row bands and the two columns, measured on the render.
    let rows = [68, 86, 103, 119, 135, 150, 165, 179, 194];
    rows.windows(2)
        .map(|band| {
            (
                mean(127, band[0], 147, band[1]),
                mean(161, band[0], 181, band[1]),
            )
        })
        .collect()
}

/// TextureSettingsTest's "Test" column (single- and double-sided, clamp, repeat and mirror in s
/// and t) looks like its "Sample pass" column, row by row: a failed setting shows a red X
/// where the sample shows a green check. The double-sided row failed while back faces were
/// culled.
#[test]
fn texture_settings_test_matches_its_sample_pass_column() {
    if models().is_none() {
        return;
    }
    let assert_rows = |rows: &[([f64; 3], [f64; 3])]| {
        for (row, (test, sample)) in rows.iter().enumerate() {
            let off = test
                .iter()
                .zip(sample)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(
                off < 8.0,
                "row {row}: test {test:?} against sample {sample:?}"
            );
        }
    };
    assert_rows(&texture_settings_columns(|_| {}));
    // The check can fail: culling the double-sided row's back face again shows its red X.
    let culled = texture_settings_columns(|scene| {
        for object in &mut scene.objects {
            object.material.double_sided = false;
        }
    });
    let caught = std::panic::catch_unwind(|| assert_rows(&culled));
    assert!(
        caught.is_err(),
        "single-sided rendering passed the double-sided row"
    );
}

/// The vertical shading gradient (upper half minus lower half, 8-bit luminance) of each of
/// NormalTangentTest's 15 cell pairs, geometry cell then normal-mapped cell, lit by the
/// default rig from the upper left, with every material made Lambert so the metal column
/// shades too, at 256x256. `edit` changes the imported scene first.
fn normal_tangent_gradients(edit: impl Fn(&mut Scene)) -> Vec<(f64, f64)> {
    let dir = models().expect("checked by the caller");
    let file = dir.join("NormalTangentTest/NormalTangentTest.gltf");
    let (mut scene, _) = histencil_scene::with_default_lights(
        histencil_scene::load_gltf(&file).unwrap(),
        histencil_scene::DefaultLights::IfNone,
    );
    for object in &mut scene.objects {
        object.material.brdf = histencil_brdf::Brdf::Lambert { rho: 1.0 };
    }
    edit(&mut scene);
    let frame = histencil_tests::with_validated_context(|ctx| {
        let mut renderer = histencil_vk::Renderer::new(ctx, scene, 256, 256).unwrap();
        let readback = histencil_vk::Readback {
            ldr: true,
            ..histencil_vk::Readback::NONE
        };
        let images = renderer.render(histencil_vk::Shading::Forward, readback);
        images.unwrap().images.ldr.unwrap()
    });
    let luminance = |x: u32, y: u32| {
        let p = frame.get_pixel(x, y).0;
        0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2])
    };
    let mean = |(x0, x1): (u32, u32), (y0, y1): (u32, u32)| {
        let sum: f64 = (x0..x1)
            .flat_map(|x| (y0..y1).map(move |y| (x, y)))
            .map(|(x, y)| luminance(x, y))
            .sum();
        sum / f64::from((x1 - x0) * (y1 - y0))
    };
    let gradient = |xs: (u32, u32), (y0, y1): (u32, u32)| {
        let middle = (y0 + y1) / 2;
        mean(xs, (y0, middle)) - mean(xs, (middle, y1))
    };
    // Cells measured on the render: three column groups of pairs, five rows.
    let pairs = [
        ((41, 63), (67, 90)),
        ((105, 124), (131, 150)),
        ((165, 187), (191, 214)),
    ];
    let rows = [(46, 66), (79, 97), (109, 126), (138, 153), (164, 178)];
    pairs
        .iter()
        .flat_map(|&(geometry, mapped)| rows.iter().map(move |&row| (geometry, mapped, row)))
        .map(|(geometry, mapped, row)| (gradient(geometry, row), gradient(mapped, row)))
        .collect()
}

/// NormalTangentTest (no TANGENT: histencil generates them) lights each normal-mapped cell as
/// its geometry cell: both brighter at the top, toward the light. The README's "flipped Y"
/// failure lights the mapped cells from below; flipping the generated tangents' handedness
/// reproduces it, and the check catches that.
#[test]
fn normal_mapped_cells_are_lit_like_their_geometry_cells() {
    if models().is_none() {
        return;
    }
    let lit_alike = |pairs: &[(f64, f64)]| {
        pairs
            .iter()
            .all(|&(geometry, mapped)| geometry > 5.0 && mapped > 5.0)
    };
    let pairs = normal_tangent_gradients(|_| {});
    assert!(lit_alike(&pairs), "{pairs:?}");
    let flipped = normal_tangent_gradients(|scene| {
        for mesh in &mut scene.meshes {
            for v in &mut mesh.vertices {
                v.tangent[3] = -v.tangent[3];
            }
        }
    });
    assert!(!lit_alike(&flipped), "flipped tangents pass: {flipped:?}");
    println!("correct {pairs:.0?}\nflipped {flipped:.0?}");
}
