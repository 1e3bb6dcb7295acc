//! glTF material modes on a quad, in forward and the deferred techniques alike: `doubleSided`
//! (a back face drawn and lit with its normal flipped toward the viewer, exactly like the same
//! quad turned to face the camera; single-sided it is culled) and `alphaMode: MASK` (texels
//! whose alpha times the factor's falls below `alphaCutoff` cut away).

use histencil_tests::gltf_builder::{png, self_contained, Bin};
use histencil_tests::{diff, with_validated_context};
use histencil_vk::{Readback, Renderer, Shading, Technique};
use image::RgbaImage;
use serde_json::json;

/// A unit quad in the z = 0 plane seen from +z: `facing` +1 winds it counter-clockwise from the
/// camera with its normal toward it, -1 the other way round (its back face toward the camera).
/// The material is glTF's own (view-dependent), lit by a point light beside the camera.
fn quad(facing: f32, double_sided: bool) -> histencil_scene::Scene {
    quad_with(facing, |doc| {
        doc["materials"][0]["doubleSided"] = json!(double_sided)
    })
}

/// [`quad`] with texture coordinates (u along +x, v down) and its document changed by `edit`.
fn quad_with(facing: f32, edit: impl Fn(&mut serde_json::Value)) -> histencil_scene::Scene {
    let mut bin = Bin::default();
    let positions = [
        -1.0, -1.0, 0.0, 1.0, -1.0, 0.0, 1.0, 1.0, 0.0, -1.0, 1.0, 0.0,
    ];
    let position = bin.floats(&positions, 3);
    let normal = bin.floats(&[0.0, 0.0, facing].repeat(4), 3);
    let uv = bin.floats(&[0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0], 2);
    let indices = if facing > 0.0 {
        bin.indices(&[0, 1, 2, 0, 2, 3])
    } else {
        bin.indices(&[0, 2, 1, 0, 3, 2])
    };
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "intensity": 20.0, "range": 20.0}
        ]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [
            {"mesh": 0},
            {"camera": 0, "translation": [0.3, 0.2, 3.0]},
            {"translation": [0.8, 0.6, 2.0], "extensions": {"KHR_lights_punctual": {"light": 0}}}
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.1, "zfar": 20}}],
        "meshes": [{"primitives": [{
            "attributes": {"POSITION": position, "NORMAL": normal, "TEXCOORD_0": uv},
            "indices": indices,
            "material": 0
        }]}],
        "materials": [{
            "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.5, 0.3, 1.0],
                                     "metallicFactor": 0.0, "roughnessFactor": 0.4}
        }],
        "bufferViews": bin.views,
        "accessors": bin.accessors,
        "buffers": []
    });
    let mut doc = doc;
    edit(&mut doc);
    let doc = self_contained(&doc, &bin.bytes);
    histencil_scene::import_gltf(&serde_json::to_vec(&doc).unwrap(), None, "quad").unwrap()
}

fn frames(scene: histencil_scene::Scene) -> Vec<RgbaImage> {
    with_validated_context(|ctx| {
        let mut renderer = Renderer::new(ctx, scene, 64, 64).unwrap();
        let stencil = Technique::Stencil {
            backend: histencil_vk::Backend::Native,
            flush: histencil_vk::FlushPolicy::Auto,
        };
        [Shading::Forward, Technique::DEFERRED.into(), stencil.into()]
            .into_iter()
            .map(|shading| {
                let readback = Readback {
                    ldr: true,
                    ..Readback::NONE
                };
                let images = renderer.render(shading, readback).unwrap().images;
                images.ldr.unwrap()
            })
            .collect()
    })
}

#[test]
fn a_double_sided_back_face_is_lit_like_a_front_face_and_a_single_sided_one_is_culled() {
    let front = frames(quad(1.0, false));
    let back = frames(quad(-1.0, true));
    let culled = frames(quad(-1.0, false));
    let back_forward = back[0].clone();
    let lit = front[0].pixels().filter(|p| p.0[..3] != [0; 3]).count();
    assert!(
        lit > 64 * 64 / 4,
        "the front-facing quad covers {lit} pixels"
    );
    for (k, ((front, back), culled)) in front.iter().zip(&back).zip(&culled).enumerate() {
        let d = diff(back, front);
        assert!(
            d.max <= 1,
            "frame {k}: the back face is {}/255 from the front",
            d.max
        );
        assert!(
            culled.pixels().all(|p| p.0[..3] == [0; 3]),
            "frame {k}: a single-sided back face was drawn"
        );
        let d = diff(back, &back_forward);
        assert!(d.max <= 1, "frame {k}: {}/255 from forward", d.max);
    }
}

/// A texture whose left half has alpha 0.2 and right half 1.0, as a `data:` URI image.
fn half_transparent(doc: &mut serde_json::Value) {
    use base64::Engine as _;
    let image = png(8, |x, _| [255, 255, 255, if x < 4 { 51 } else { 255 }]);
    let uri = format!(
        "data:image/png;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(image)
    );
    doc["images"] = json!([{"uri": uri}]);
    // Clamped, so that filtering at the left edge does not reach the opaque right edge.
    doc["samplers"] = json!([{"wrapS": 33071, "wrapT": 33071}]);
    doc["textures"] = json!([{"source": 0, "sampler": 0}]);
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": 0});
}

#[test]
fn mask_cuts_away_texels_below_the_cutoff() {
    let masked = |cutoff: f32, factor_alpha: f32| {
        quad_with(1.0, |doc| {
            half_transparent(doc);
            let m = &mut doc["materials"][0];
            m["alphaMode"] = json!("MASK");
            m["alphaCutoff"] = json!(cutoff);
            m["pbrMetallicRoughness"]["baseColorFactor"][3] = json!(factor_alpha);
        })
    };
    let opaque = frames(quad_with(1.0, half_transparent));
    // Cutoff 0.5: the left half (alpha 0.2) is cut, the right half (1.0) drawn as the opaque
    // quad draws it. With the factor's alpha 0.4 even the right half (0.4) is cut.
    let half = frames(masked(0.5, 1.0));
    let none = frames(masked(0.5, 0.4));
    let all = frames(masked(0.1, 1.0));
    // The quad's halves on screen (u = 0.5 is its middle column), a pixel either side of the
    // middle left out where the filtered alpha crosses the cutoff.
    let covered: Vec<(u32, u32)> = opaque[0]
        .enumerate_pixels()
        .filter(|(_, _, p)| p.0[..3] != [0; 3])
        .map(|(x, y, _)| (x, y))
        .collect();
    let (lo, hi) = covered
        .iter()
        .fold((u32::MAX, 0), |(lo, hi), &(x, _)| (lo.min(x), hi.max(x)));
    let middle = (lo + hi) / 2;
    let side = |image: &RgbaImage, left: bool| {
        covered
            .iter()
            .filter(|&&(x, _)| if left { x + 1 < middle } else { x > middle + 1 })
            .map(|&(x, y)| *image.get_pixel(x, y))
            .collect::<Vec<_>>()
    };
    for k in 0..opaque.len() {
        let covered_left = side(&opaque[k], true);
        assert!(
            covered_left.len() > 100,
            "frame {k}: the quad misses the left half"
        );
        assert!(
            side(&half[k], true).iter().all(|p| p.0[..3] == [0; 3]),
            "frame {k}: a texel below the cutoff was drawn"
        );
        assert_eq!(side(&half[k], false), side(&opaque[k], false), "frame {k}");
        assert!(none[k].pixels().all(|p| p.0[..3] == [0; 3]), "frame {k}");
        assert!(diff(&all[k], &opaque[k]).max == 0, "frame {k}");
        assert!(
            diff(&half[k], &half[0]).max <= 1,
            "frame {k} against forward"
        );
    }
}
