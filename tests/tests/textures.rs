//! Texture maps, held to what they mean: each map is rendered against an untextured scene that
//! spells out by hand what the map should do (a base colour texel and a vertex colour are a
//! tint, a metallic-roughness texel is `textured_brdf`'s parameters, a normal-map texel is a
//! bent vertex normal, `TEXCOORD_1` and `KHR_texture_transform` pick the texel they name), and
//! the textured frame of every exact technique matches forward within 1/255.

use glam::{Mat4, Vec3};
use histencil_brdf::Brdf;
use histencil_scene::{
    textured_brdf, uv_transform, Camera, Filter, Light, Material, Mesh, Object, Sampler, Scene,
    Shape, TextureImage, TextureRef, Vertex, Wrap,
};
use histencil_tests::{assert_close, lit_fraction, with_validated_context};
use histencil_vk::{srgb_to_linear, Backend, FlushPolicy, Readback, Renderer, Shading, Technique};
use image::RgbaImage;

const SIZE: u32 = 96;

/// A square in the xz plane facing +y, `[-1, 1]^2`, its tangent +x (u) and bitangent +z
/// (cross(+y, +x) = -z, so w = -1 makes it +z = +v), with `normal` as every vertex normal and
/// the given texture coordinates and colour.
fn square(normal: Vec3, uv: [[f32; 2]; 4], uv1: [[f32; 2]; 4], color: [f32; 4]) -> Mesh {
    let corners = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];
    let vertices = (0..4)
        .map(|i| {
            let [x, z] = corners[i];
            Vertex {
                uv1: uv1[i],
                tangent: [1.0, 0.0, 0.0, -1.0],
                color,
                ..Vertex::new([x, 0.0, z], normal.to_array(), uv[i])
            }
        })
        .collect();
    // Counter-clockwise seen from +y.
    Mesh {
        vertices,
        indices: vec![0, 2, 1, 0, 3, 2],
    }
}

fn uvs(u: f32, v: f32) -> [[f32; 2]; 4] {
    [[u, v]; 4]
}

/// One square lit by a point light and a sun, seen from above at an angle; `images` are the
/// scene's images.
fn scene(mesh: Mesh, material: Material, images: Vec<TextureImage>) -> Scene {
    Scene {
        name: "texture-test".into(),
        description: "a textured square".into(),
        camera: Camera {
            eye: Vec3::new(0.0, 2.2, 2.4),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_radians: 0.9,
            near: 0.1,
            far: 20.0,
        },
        objects: vec![Object {
            name: "square".into(),
            shape: Shape::Mesh(0),
            transform: Mat4::from_scale(Vec3::splat(1.5)),
            material,
        }],
        lights: vec![
            Light::point(Vec3::new(0.4, 0.8, 0.3), 4.0, Vec3::new(2.0, 1.8, 1.5)),
            Light {
                kind: histencil_scene::LightKind::Directional {
                    direction: Vec3::new(-0.3, -1.0, -0.5),
                },
                ..Light::point(Vec3::ZERO, 1.0, Vec3::splat(0.6))
            },
        ],
        alpha_objects: vec![],
        particle_systems: vec![],
        meshes: vec![mesh],
        images,
    }
}

fn solid(name: &str, rgba: [u8; 4]) -> TextureImage {
    TextureImage {
        name: name.into(),
        width: 4,
        height: 4,
        rgba8: rgba.repeat(16),
    }
}

const LDR: Readback = Readback {
    ldr: true,
    ..Readback::NONE
};

fn forward(scene: &Scene) -> RgbaImage {
    with_validated_context(|ctx| {
        let mut r = Renderer::new(ctx, scene.clone(), SIZE, SIZE).unwrap();
        r.render(Shading::Forward, LDR).unwrap().images.ldr.unwrap()
    })
}

const GGX: Brdf = Brdf::Ggx {
    alpha: 0.5,
    f0: 0.9,
    f90: 1.0,
};

#[test]
fn a_base_colour_texel_and_a_vertex_colour_are_a_tint() {
    let texel = [200, 120, 40, 255];
    let color = [0.5, 1.0, 0.8, 1.0];
    let mut textured = Material::new(Brdf::Lambert { rho: 1.0 }, Vec3::new(0.9, 0.8, 1.0));
    textured.maps.base_color = Some(TextureRef::new(0));
    let mesh = square(Vec3::Y, uvs(0.3, 0.6), uvs(0.0, 0.0), color);
    let by_texture = forward(&scene(mesh.clone(), textured, vec![solid("orange", texel)]));
    let tint = textured.tint
        * Vec3::new(
            srgb_to_linear(texel[0]),
            srgb_to_linear(texel[1]),
            srgb_to_linear(texel[2]),
        )
        * Vec3::new(color[0], color[1], color[2]);
    let untextured = Material::new(textured.brdf, tint);
    let white = square(Vec3::Y, uvs(0.3, 0.6), uvs(0.0, 0.0), [1.0; 4]);
    let by_hand = forward(&scene(white, untextured, vec![]));
    assert!(lit_fraction(&by_hand) > 0.2);
    assert_close("base-colour-as-tint", &by_texture, &by_hand, 1);
}

#[test]
fn a_metallic_roughness_texel_is_textured_brdf() {
    let (g, b) = (128u8, 40u8);
    let mut textured = Material::new(GGX, Vec3::ONE);
    textured.maps.metallic_roughness = Some(TextureRef::new(0));
    let mesh = square(Vec3::Y, uvs(0.5, 0.5), uvs(0.0, 0.0), [1.0; 4]);
    let images = vec![solid("mr", [255, g, b, 255])];
    let by_texture = forward(&scene(mesh.clone(), textured, images));
    let brdf = textured_brdf(GGX, f32::from(g) / 255.0, f32::from(b) / 255.0);
    assert_ne!(brdf, GGX);
    let by_hand = forward(&scene(mesh.clone(), Material::new(brdf, Vec3::ONE), vec![]));
    assert_close("metallic-roughness-as-params", &by_texture, &by_hand, 1);
    // And the texture did something: the untouched GGX differs.
    let plain = forward(&scene(mesh, Material::new(GGX, Vec3::ONE), vec![]));
    assert!(histencil_tests::diff(&plain, &by_hand).max > 8);
}

#[test]
fn a_normal_map_texel_is_a_bent_normal() {
    // Tangent space (0.6, -0.3, 0.74), scaled by 0.8 in x and y.
    let texel = [204, 89, 222, 255];
    let scale = 0.8;
    let decode = |c: u8| f32::from(c) / 255.0 * 2.0 - 1.0;
    let m = Vec3::new(
        decode(texel[0]) * scale,
        decode(texel[1]) * scale,
        decode(texel[2]),
    );
    // The square's frame: T = +x, B = +z, N = +y.
    let bent = (Vec3::X * m.x + Vec3::Z * m.y + Vec3::Y * m.z).normalize();
    let mut textured = Material::new(GGX, Vec3::ONE);
    textured.maps.normal = Some(TextureRef::new(0));
    textured.maps.normal_scale = scale;
    let mesh = square(Vec3::Y, uvs(0.5, 0.5), uvs(0.0, 0.0), [1.0; 4]);
    let by_texture = forward(&scene(mesh, textured, vec![solid("normal", texel)]));
    let bent_mesh = square(bent, uvs(0.5, 0.5), uvs(0.0, 0.0), [1.0; 4]);
    let by_hand = forward(&scene(bent_mesh, Material::new(GGX, Vec3::ONE), vec![]));
    assert!(lit_fraction(&by_hand) > 0.2);
    assert_close("normal-map-as-normal", &by_texture, &by_hand, 1);
}

/// A 2x1 image, red on the left and green on the right, read with nearest filtering: which
/// texel a material sees says which coordinates it read and how it transformed them.
#[test]
fn texcoord_sets_and_transforms_pick_their_texel() {
    let image = TextureImage {
        name: "red-green".into(),
        width: 2,
        height: 1,
        rgba8: vec![255, 0, 0, 255, 0, 255, 0, 255],
    };
    let nearest = Sampler {
        wrap_u: Wrap::ClampToEdge,
        wrap_v: Wrap::ClampToEdge,
        mag: Filter::Nearest,
        min: Filter::Nearest,
        mip: None,
    };
    // TEXCOORD_0 says red, TEXCOORD_1 green.
    let mesh = square(Vec3::Y, uvs(0.25, 0.5), uvs(0.75, 0.5), [1.0; 4]);
    let green = forward(&scene(
        mesh.clone(),
        Material::new(Brdf::Lambert { rho: 1.0 }, Vec3::Y),
        vec![],
    ));
    let map = |texcoord, transform| {
        let mut m = Material::new(Brdf::Lambert { rho: 1.0 }, Vec3::ONE);
        m.maps.base_color = Some(TextureRef {
            image: 0,
            sampler: nearest,
            texcoord,
            transform,
        });
        m
    };
    let second_set = map(1, histencil_scene::UV_IDENTITY);
    let shifted = map(0, uv_transform([0.5, 0.0], 0.0, [1.0, 1.0]));
    let first_set = map(0, histencil_scene::UV_IDENTITY);
    for (name, material) in [("texcoord-1", second_set), ("transform-offset", shifted)] {
        let image = forward(&scene(mesh.clone(), material, vec![image.clone()]));
        assert_close(name, &image, &green, 1);
    }
    let red = forward(&scene(mesh, first_set, vec![image]));
    assert!(
        histencil_tests::diff(&red, &green).max > 64,
        "texcoord 0 reads red"
    );
}

/// A checkerboard base colour, a bumpy normal map and a roughness gradient on every exact
/// technique: each matches forward within 1/255, and the textures show (the frame is not the
/// untextured one).
#[test]
fn textured_surfaces_light_the_same_in_every_exact_technique() {
    let side = 64u32;
    let pixels = |f: &dyn Fn(u32, u32) -> [u8; 4]| -> Vec<u8> {
        (0..side * side)
            .flat_map(|i| f(i % side, i / side))
            .collect()
    };
    let checker = pixels(&|x, y| {
        if (x / 8 + y / 8) % 2 == 0 {
            [230, 220, 200, 255]
        } else {
            [60, 90, 160, 255]
        }
    });
    let bumps = pixels(&|x, y| {
        let (fx, fy) = ((x as f32 / 8.0).sin(), (y as f32 / 5.0).cos());
        let n = Vec3::new(0.5 * fx, 0.5 * fy, 1.0).normalize();
        let c = |v: f32| ((v * 0.5 + 0.5) * 255.0).round() as u8;
        [c(n.x), c(n.y), c(n.z), 255]
    });
    let roughness = pixels(&|x, _| [0, (40 + x * 3) as u8, 200, 255]);
    let image = |name: &str, rgba8| TextureImage {
        name: name.into(),
        width: side,
        height: side,
        rgba8,
    };
    let mut material = Material::new(GGX, Vec3::ONE);
    material.maps.base_color = Some(TextureRef::new(0));
    material.maps.normal = Some(TextureRef::new(1));
    material.maps.normal_scale = 1.0;
    material.maps.metallic_roughness = Some(TextureRef {
        texcoord: 1,
        ..TextureRef::new(2)
    });
    let corners = [[0.0, 0.0], [3.0, 0.0], [3.0, 3.0], [0.0, 3.0]];
    let mesh = square(
        Vec3::Y,
        corners,
        [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
        [1.0; 4],
    );
    let images = vec![
        image("checker", checker),
        image("bumps", bumps),
        image("roughness", roughness),
    ];
    let textured = scene(mesh.clone(), material, images);
    let untextured = forward(&scene(mesh, Material::new(GGX, Vec3::ONE), vec![]));
    let stencil = |backend| Technique::Stencil {
        backend,
        flush: FlushPolicy::Auto,
    };
    with_validated_context(|ctx| {
        let mut r = Renderer::new(ctx, textured, SIZE, SIZE).unwrap();
        let mut frame = |t| r.render(t, LDR).unwrap().images.ldr.unwrap();
        let reference = frame(Shading::Forward);
        assert!(histencil_tests::diff(&reference, &untextured).max > 64);
        let techniques = [
            (
                "branching",
                Technique::Branching {
                    backend: Backend::Native,
                    flush: FlushPolicy::Auto,
                },
            ),
            ("stencil-native", stencil(Backend::Native)),
            ("stencil-ps3", stencil(Backend::Ps3)),
            (
                "stencil-360",
                stencil(Backend::X360 {
                    zero_preserved: true,
                    save_restore: false,
                }),
            ),
        ];
        for (name, technique) in techniques {
            let image = frame(technique.into());
            assert_close(&format!("textured-{name}"), &image, &reference, 1);
        }
    });
}

/// Emission is added once per pixel: with no lights, the HDR frame of every technique is the
/// emitted radiance times the emissive map's texel (decoded from sRGB), and with lights it is
/// that plus the lit surface, the deferred techniques within 1/255 of forward.
#[test]
fn emission_is_added_once_and_read_from_its_map() {
    let texel = [180, 90, 30, 255];
    let mut material = Material::new(Brdf::Lambert { rho: 1.0 }, Vec3::splat(0.5));
    material.emissive = Vec3::new(0.4, 0.6, 0.8);
    material.maps.emissive = Some(TextureRef::new(0));
    let mesh = square(Vec3::Y, uvs(0.5, 0.5), uvs(0.0, 0.0), [1.0; 4]);
    let lit = scene(mesh, material, vec![solid("ember", texel)]);
    let dark = Scene {
        lights: vec![],
        ..lit.clone()
    };
    let expected = material.emissive
        * Vec3::new(
            srgb_to_linear(texel[0]),
            srgb_to_linear(texel[1]),
            srgb_to_linear(texel[2]),
        );
    let flush = FlushPolicy::Auto;
    let techniques = [
        Shading::Forward,
        Technique::Stencil {
            backend: Backend::Ps3,
            flush,
        }
        .into(),
        Technique::Branching {
            backend: Backend::Native,
            flush,
        }
        .into(),
    ];
    with_validated_context(|ctx| {
        let hdr = Readback {
            hdr: true,
            ..Readback::NONE
        };
        let mut renderer = Renderer::new(ctx, dark, SIZE, SIZE).unwrap();
        let mut reference = None;
        for technique in techniques {
            let image = renderer.render(technique, hdr).unwrap().images.hdr.unwrap();
            let centre = image.get_pixel(SIZE / 2, SIZE / 2).0;
            // The device's sRGB decode is good to about 2 % at the darkest channel.
            for c in 0..3 {
                assert!(
                    (centre[c] - expected[c]).abs() <= 0.02 * expected[c] + 1e-4,
                    "{technique:?}: {centre:?} against {expected}"
                );
            }
            // Every technique emits exactly what forward does, once.
            let forward = *reference.get_or_insert(centre);
            assert_eq!(centre, forward, "{technique:?}");
        }
        let mut renderer = Renderer::new(ctx, lit, SIZE, SIZE).unwrap();
        let mut frame = |t| renderer.render(t, LDR).unwrap().images.ldr.unwrap();
        let forward = frame(Shading::Forward);
        for technique in &techniques[1..] {
            assert_close("emissive-lit", &frame(*technique), &forward, 1);
        }
    });
}
