//! glTF's `doubleSided`: a double-sided quad seen from behind is drawn, its back face lit with
//! the normal flipped toward the viewer, exactly like the same quad turned to face the camera;
//! a single-sided one seen from behind is culled. Forward and the deferred techniques alike.

use histencil_tests::gltf_builder::{self_contained, Bin};
use histencil_tests::{diff, with_validated_context};
use histencil_vk::{Readback, Renderer, Shading, Technique};
use image::RgbaImage;
use serde_json::json;

/// A unit quad in the z = 0 plane seen from +z: `facing` +1 winds it counter-clockwise from the
/// camera with its normal toward it, -1 the other way round (its back face toward the camera).
/// The material is glTF's own (view-dependent), lit by a point light beside the camera.
fn quad(facing: f32, double_sided: bool) -> histencil_scene::Scene {
    let mut bin = Bin::default();
    let positions = [
        -1.0, -1.0, 0.0, 1.0, -1.0, 0.0, 1.0, 1.0, 0.0, -1.0, 1.0, 0.0,
    ];
    let position = bin.floats(&positions, 3);
    let normal = bin.floats(&[0.0, 0.0, facing].repeat(4), 3);
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
            "attributes": {"POSITION": position, "NORMAL": normal},
            "indices": indices,
            "material": 0
        }]}],
        "materials": [{
            "doubleSided": double_sided,
            "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.5, 0.3, 1.0],
                                     "metallicFactor": 0.0, "roughnessFactor": 0.4}
        }],
        "bufferViews": bin.views,
        "accessors": bin.accessors,
        "buffers": []
    });
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
