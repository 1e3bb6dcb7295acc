//! The glTF test scene, written from code: a cube and a floor in two BRDFs named in material
//! `extras`, three `KHR_lights_punctual` lights, a camera and a translucent (`alphaMode: BLEND`)
//! pane, with an external `.bin`. Shared by the glTF tests and the hostile-input generator.

use crate::output_dir;
use serde_json::{json, Value};
use std::f32::consts::FRAC_1_SQRT_2 as H;
use std::path::PathBuf;

/// Binary data and the accessors that address it.
#[derive(Default)]
pub struct Bin {
    pub bytes: Vec<u8>,
    pub views: Vec<Value>,
    pub accessors: Vec<Value>,
}

impl Bin {
    /// Appends float vectors of `width` components; returns the accessor index.
    pub fn floats(&mut self, data: &[f32], width: usize) -> usize {
        let (kind, count) = (["", "SCALAR", "VEC2", "VEC3"][width], data.len() / width);
        let mut accessor = json!({"componentType": 5126, "count": count, "type": kind});
        if width == 3 {
            let axis =
                |k: usize, f: fn(f32, f32) -> f32| data.chunks(3).map(|v| v[k]).fold(data[k], f);
            accessor["min"] = json!([0, 1, 2].map(|k| axis(k, f32::min)));
            accessor["max"] = json!([0, 1, 2].map(|k| axis(k, f32::max)));
        }
        self.push(
            data.iter().flat_map(|f| f.to_le_bytes()).collect(),
            accessor,
        )
    }

    pub fn indices(&mut self, data: &[u32]) -> usize {
        let accessor = json!({"componentType": 5125, "count": data.len(), "type": "SCALAR"});
        self.push(
            data.iter().flat_map(|i| i.to_le_bytes()).collect(),
            accessor,
        )
    }

    pub fn push(&mut self, bytes: Vec<u8>, mut accessor: Value) -> usize {
        self.views
            .push(json!({"buffer": 0, "byteOffset": self.bytes.len(), "byteLength": bytes.len()}));
        accessor["bufferView"] = json!(self.views.len() - 1);
        self.bytes.extend(bytes);
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }
}

/// A cube of half-size 1 with 24 vertices (flat normals), counter-clockwise from outside.
pub fn cube(bin: &mut Bin) -> Value {
    let (mut p, mut n, mut idx) = (vec![], vec![], vec![]);
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let mut normal = [0.0; 3];
            normal[axis] = sign;
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let base = (p.len() / 3) as u32;
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                let mut q = normal;
                q[u] = a;
                q[v] = b;
                p.extend(q);
                n.extend(normal);
            }
            let quad = if sign > 0.0 {
                [0, 1, 2, 0, 2, 3]
            } else {
                [0, 2, 1, 0, 3, 2]
            };
            idx.extend(quad.map(|k| base + k));
        }
    }
    json!({"attributes": {"POSITION": bin.floats(&p, 3), "NORMAL": bin.floats(&n, 3)},
           "indices": bin.indices(&idx)})
}

/// A quad in the XZ plane facing +Y, half-size 1, without normals (the importer makes them
/// flat), with texture coordinates.
pub fn quad(bin: &mut Bin) -> Value {
    let p = [
        -1.0, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0, 0.0, -1.0, -1.0, 0.0, -1.0,
    ];
    let uv = [0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0];
    json!({"attributes": {"POSITION": bin.floats(&p, 3), "TEXCOORD_0": bin.floats(&uv, 2)},
           "indices": bin.indices(&[0, 1, 2, 0, 2, 3])})
}

/// The test scene as glTF JSON and its binary buffer; `box_brdf` is the cube's BRDF name.
pub fn test_gltf(box_brdf: &str) -> (Value, Vec<u8>) {
    let mut bin = Bin::default();
    let (cube, floor) = (cube(&mut bin), quad(&mut bin));
    let mut glass = floor.clone();
    glass["material"] = json!(2);
    let mut floor_prim = floor;
    floor_prim["material"] = json!(0);
    let mut cube_prim = cube;
    cube_prim["material"] = json!(1);
    let doc = json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1.0, 0.9, 0.8], "intensity": 12.0, "range": 6.0},
            {"type": "point", "color": [0.4, 0.6, 1.0], "intensity": 8.0, "range": 5.0},
            {"type": "spot", "color": [1.0, 1.0, 1.0], "intensity": 30.0, "range": 9.0,
             "spot": {"innerConeAngle": 0.3, "outerConeAngle": 0.6}}
        ]}},
        "materials": [
            {"name": "floor", "extras": {"brdf": "oren_nayar_full", "rho": 0.9, "sigma": 0.3},
             "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.7, 1.0]}},
            {"name": "box", "extras": {"brdf": box_brdf, "n": 32, "tint": [0.9, 0.3, 0.2]}},
            {"name": "glass", "alphaMode": "BLEND",
             "pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.8, 1.0, 0.4],
                                      "metallicFactor": 0.0, "roughnessFactor": 0.8}}
        ],
        "meshes": [{"name": "cube", "primitives": [cube_prim]},
                   {"name": "floor", "primitives": [floor_prim]},
                   {"name": "pane", "primitives": [glass]}],
        "cameras": [{"type": "perspective",
                     "perspective": {"yfov": 0.9, "znear": 0.1, "zfar": 50.0}}],
        "nodes": [
            {"name": "box", "mesh": 0, "translation": [0.0, 0.6, 0.0], "scale": [0.6, 0.6, 0.6],
             "rotation": [0.0, 0.3826834, 0.0, 0.9238795]},
            {"name": "floor", "mesh": 1, "scale": [5.0, 1.0, 5.0]},
            {"name": "pane", "mesh": 2, "translation": [1.2, 1.0, 1.2],
             "rotation": [H, 0.0, 0.0, H], "scale": [0.5, 1.0, 0.5]},
            {"name": "warm", "extensions": {"KHR_lights_punctual": {"light": 0}},
             "translation": [1.5, 2.0, 1.0]},
            {"name": "cool", "extensions": {"KHR_lights_punctual": {"light": 1}},
             "translation": [-1.5, 1.5, 0.5]},
            {"name": "spot", "extensions": {"KHR_lights_punctual": {"light": 2}},
             "translation": [0.0, 5.0, 0.0], "rotation": [-H, 0.0, 0.0, H]},
            {"name": "camera", "camera": 0, "translation": [0.0, 3.0, 6.0],
             "rotation": [-0.2297529, 0.0, 0.0, 0.9732489]}
        ],
        "scenes": [{"nodes": [0, 1, 2, 3, 4, 5, 6]}],
        "scene": 0,
        "bufferViews": bin.views,
        "accessors": bin.accessors,
        "buffers": [{"uri": "scene.bin", "byteLength": bin.bytes.len()}]
    });
    (doc, bin.bytes)
}

/// `doc` with `bin` inlined as a base64 `data:` URI: one self-contained `.gltf` file.
pub fn self_contained(doc: &Value, bin: &[u8]) -> Value {
    use base64::Engine as _;
    let mut doc = doc.clone();
    doc["buffers"] = json!([{
        "uri": format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(bin)
        ),
        "byteLength": bin.len()
    }]);
    doc
}

/// The committed copy of the test scene that `histencil check` runs in `tools/test`
/// (`tests/scenes/two-brdfs.gltf`); `tests/tests/gltf.rs` holds it equal to [`test_gltf`].
pub fn committed_scene_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/two-brdfs.gltf")
}

/// Writes `doc` and `bin` into a fresh directory; returns the `.gltf` path.
pub fn write(name: &str, doc: &Value, bin: &[u8]) -> PathBuf {
    let dir = output_dir().join(format!("gltf-{name}"));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("scene.bin"), bin).unwrap();
    let path = dir.join("scene.gltf");
    std::fs::write(&path, serde_json::to_vec_pretty(doc).unwrap()).unwrap();
    path
}

/// PNG bytes of a `side` x `side` RGBA image whose texel `(x, y)` is `f(x, y)`.
pub fn png(side: u32, f: impl Fn(u32, u32) -> [u8; 4]) -> Vec<u8> {
    let image = image::RgbaImage::from_fn(side, side, |x, y| image::Rgba(f(x, y)));
    let mut out = std::io::Cursor::new(Vec::new());
    image
        .write_to(&mut out, image::ImageFormat::Png)
        .expect("encode a PNG in memory");
    out.into_inner()
}

/// The test scene with textures as glTF ships them, one image per way a glTF holds one:
/// the floor's base colour is a checkerboard in an external `checker.png` (repeated 4 times
/// by `KHR_texture_transform`, nearest-filtered through a sampler), its normal map a ripple
/// in a `data:` URI (tangents generated), its metallic-roughness a gradient in a buffer view;
/// the box has vertex colours (`COLOR_0`). Returns the document, its buffer and the external
/// image's bytes.
pub fn textured_gltf() -> (Value, Vec<u8>, Vec<u8>) {
    use base64::Engine as _;
    let (mut doc, bin) = test_gltf("blinn_phong");
    let mut bin = Bin {
        bytes: bin,
        views: serde_json::from_value(doc["bufferViews"].clone()).unwrap(),
        accessors: serde_json::from_value(doc["accessors"].clone()).unwrap(),
    };
    let checker = png(32, |x, y| {
        if (x / 4 + y / 4) % 2 == 0 {
            [240, 230, 210, 255]
        } else {
            [70, 100, 170, 255]
        }
    });
    let ripple = png(32, |x, _| {
        let slope = (x as f32 * 0.6).sin() * 0.5;
        let n = [slope, 0.0, 1.0];
        let len = (n[0] * n[0] + 1.0f32).sqrt();
        let c = |v: f32| ((v / len * 0.5 + 0.5) * 255.0).round() as u8;
        [c(n[0]), c(n[1]), c(n[2]), 255]
    });
    let gradient = png(16, |x, _| [0, (60 + x * 12) as u8, 0, 255]);
    // The gradient's bytes in a buffer view of its own (4-byte aligned, as views should be).
    while !bin.bytes.len().is_multiple_of(4) {
        bin.bytes.push(0);
    }
    bin.views
        .push(json!({"buffer": 0, "byteOffset": bin.bytes.len(), "byteLength": gradient.len()}));
    let gradient_view = bin.views.len() - 1;
    bin.bytes.extend(&gradient);
    // Vertex colours on the cube: one per vertex, warm above and cool below.
    let cube_accessor = doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
        .as_u64()
        .unwrap() as usize;
    let count = doc["accessors"][cube_accessor]["count"].as_u64().unwrap() as usize;
    let colors: Vec<f32> = (0..count)
        .flat_map(|i| {
            if i % 2 == 0 {
                [1.0, 0.7, 0.4, 1.0]
            } else {
                [0.5, 0.8, 1.0, 1.0]
            }
        })
        .collect();
    let color_accessor = bin.push(
        colors.iter().flat_map(|f| f.to_le_bytes()).collect(),
        json!({"componentType": 5126, "count": count, "type": "VEC4"}),
    );
    doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = json!(color_accessor);
    doc["extensionsUsed"] = json!(["KHR_lights_punctual", "KHR_texture_transform"]);
    doc["images"] = json!([
        {"uri": "checker.png"},
        {"uri": format!("data:image/png;base64,{}",
                        base64::engine::general_purpose::STANDARD.encode(&ripple))},
        {"bufferView": gradient_view, "mimeType": "image/png", "name": "gradient"}
    ]);
    doc["samplers"] = json!([{"magFilter": 9728, "minFilter": 9986}]);
    doc["textures"] = json!([
        {"source": 0, "sampler": 0}, {"source": 1}, {"source": 2}
    ]);
    doc["materials"][0] = json!({
        "name": "floor", "extras": {"brdf": "ggx", "alpha": 0.4, "f0": 0.5, "f90": 1.0},
        "pbrMetallicRoughness": {
            "baseColorFactor": [1.0, 1.0, 1.0, 1.0],
            "baseColorTexture": {"index": 0, "extensions": {
                "KHR_texture_transform": {"scale": [4.0, 4.0]}}},
            "metallicRoughnessTexture": {"index": 2}
        },
        "normalTexture": {"index": 1, "scale": 0.8}
    });
    doc["bufferViews"] = json!(bin.views);
    doc["accessors"] = json!(bin.accessors);
    doc["buffers"][0]["byteLength"] = json!(bin.bytes.len());
    (doc, bin.bytes, checker)
}
