//! An engine's own BRDFs through every technique (histencil_brdf::BrdfSet, compiled at run time
//! by histencil_vk::compile_brdf_set), under the validation layer.
//!
//! An engine BRDF has no f64 reference, so what can be proven is that the engine's function is
//! what every technique evaluates: an engine BRDF that spells Lambert with histencil's own GLSL
//! gives the built-in Lambert's frames bit for bit, technique by technique (the same expression
//! reaches every shader, only through the set's generated switch); and the example folder's
//! BRDFs (`examples/brdfs`: a toon ramp, glTF's Charlie sheen with a white part) are held to
//! the forward reference that shades with the same function.

use histencil_brdf::{Brdf, BrdfId, BrdfSet, EngineBrdfSpec, EngineParam, Range};
use histencil_tests::{assert_close, diff, lit_fraction, with_validated_context};
use histencil_vk::{
    Backend, BrdfModules, FlushPolicy, MixedTiles, Readback, Renderer, RendererDesc, Shading,
    Technique, TileSide,
};
use image::RgbaImage;
use std::path::{Path, PathBuf};

const SIZE: u32 = 96;

/// The LUT technique, without hi-stencil.
const LUT: Technique = Technique::Lut {
    backend: Backend::Native,
    flush: FlushPolicy::Auto,
};

fn techniques() -> Vec<(&'static str, Shading)> {
    let flush = FlushPolicy::Auto;
    vec![
        ("forward", Shading::Forward),
        ("branching", Technique::DEFERRED.into()),
        (
            "stencil-ps3",
            Technique::Stencil {
                backend: Backend::Ps3,
                flush,
            }
            .into(),
        ),
        (
            "stencil-native",
            Technique::Stencil {
                backend: Backend::Native,
                flush,
            }
            .into(),
        ),
        (
            "tiled",
            Technique::Tiled {
                mixed: MixedTiles::PerBrdf,
                side: TileSide::Eight,
            }
            .into(),
        ),
        (
            "depth-id",
            Technique::DepthId {
                side: TileSide::Eight,
            }
            .into(),
        ),
    ]
}

fn render(
    ctx: &histencil_vk::Context,
    scene: &histencil_scene::Scene,
    brdfs: &'static BrdfModules,
    shading: Shading,
) -> RgbaImage {
    render_ids(ctx, scene, brdfs, shading).0
}

/// The frame and, deferred, the BRDF each pixel's G-buffer names.
fn render_ids(
    ctx: &histencil_vk::Context,
    scene: &histencil_scene::Scene,
    brdfs: &'static BrdfModules,
    shading: Shading,
) -> (RgbaImage, Option<Vec<Option<BrdfId>>>) {
    let desc = RendererDesc {
        brdfs,
        ..RendererDesc::new(SIZE, SIZE)
    };
    let mut renderer = Renderer::with_desc(ctx, scene.clone(), &desc).expect("renderer");
    let images = renderer
        .render(shading, Readback::ALL)
        .expect("frame")
        .images;
    (images.ldr.expect("asked for"), images.brdf_ids)
}

/// A folder of its own under the test output folder, holding `files`.
fn folder(name: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = histencil_tests::output_dir().join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (file, text) in files {
        std::fs::write(dir.join(file), text).unwrap();
    }
    dir
}

/// A set of one engine BRDF without parameters, `name` in `name.glsl` (`body` its GLSL), with
/// no built-in beside it, compiled.
fn one_brdf(name: &str, body: &str, tint: bool) -> (BrdfSet, &'static BrdfModules) {
    let file = format!("{name}.glsl");
    let dir = folder(&format!("engine-brdfs-{name}"), &[(&file, body)]);
    let spec = EngineBrdfSpec {
        name: name.into(),
        glsl: file,
        function: name.into(),
        white: None,
        params: vec![],
        tangent: false,
        tint,
    };
    let set = BrdfSet::new(&[], vec![spec])
        .unwrap()
        .with_folder(dir.canonicalize().unwrap());
    let modules = histencil_vk::compile_brdf_set(&set).expect("compiles");
    (set, modules)
}

/// What the probe an engine runs itself (`probe_brdfs`) says of `modules`, which it must refuse.
fn probe_refusal(modules: &'static BrdfModules) -> String {
    let mut text = String::new();
    with_validated_context(|ctx| {
        text = histencil_vk::probe_brdfs(ctx, modules)
            .expect_err("the probe refuses it")
            .to_string();
    });
    text
}

#[test]
fn an_engine_brdf_spelling_lambert_gives_the_builtin_frames_bit_for_bit() {
    let dir = folder(
        "engine-brdfs-lambert",
        &[(
            "mine.glsl",
            "vec3 my_lambert(vec4 p, vec3 N, vec3 T, vec3 V, vec3 L) {\n    return vec3(brdf_lambert(p.x, N, L));\n}\n",
        )],
    );
    let spec = EngineBrdfSpec {
        name: "my_lambert".into(),
        glsl: "mine.glsl".into(),
        function: "my_lambert".into(),
        white: None,
        params: vec![EngineParam {
            name: "rho".into(),
            range: Range::new(0.0, 1.0),
            default: 1.0,
        }],
        tangent: false,
        tint: false,
    };
    // Only Blinn-Phong kept beside it: the others are left out of every switch.
    let set = BrdfSet::new(&[BrdfId::BlinnPhong], vec![spec])
        .unwrap()
        .with_folder(dir.canonicalize().unwrap());
    let modules = histencil_vk::compile_brdf_set(&set).expect("compiles");
    let builtin = histencil_scene::embedded("default").unwrap();
    let mut engine = builtin.clone();
    let mut swapped = 0;
    for o in &mut engine.objects {
        if let Brdf::Lambert { rho } = o.material.brdf {
            o.material.brdf = set.engine_brdf("my_lambert", &[("rho", rho)]).unwrap();
            swapped += 1;
        }
    }
    assert!(swapped > 0);
    with_validated_context(|ctx| {
        for (name, shading) in techniques() {
            let expected = render(ctx, &builtin, BrdfModules::builtin(), shading);
            let actual = render(ctx, &engine, modules, shading);
            let d = diff(&expected, &actual);
            assert_eq!(
                d.max, 0,
                "{name}: the engine's Lambert differs from the built-in: {d:?}"
            );
            assert!(lit_fraction(&actual) > 0.2, "{name}: too dark");
        }
    });
}

#[test]
fn the_example_brdfs_are_held_to_forward_by_every_technique() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/brdfs");
    let set = BrdfSet::load(&dir).expect("examples/brdfs loads");
    let modules = histencil_vk::compile_brdf_set(&set).expect("compiles");
    let mut scene = histencil_scene::embedded("brdfs-3").unwrap();
    let pairs = histencil_scene::retarget_brdfs(&mut scene, &set);
    let to: Vec<&str> = pairs.iter().map(|(_, to)| to.name()).collect();
    assert_eq!(to, ["toon", "charlie_sheen", "toon"]);
    with_validated_context(|ctx| {
        let forward = render(ctx, &scene, modules, Shading::Forward);
        assert!(lit_fraction(&forward) > 0.2);
        // Not the built-ins' frame: the engine's functions shade it.
        let builtin = histencil_scene::embedded("brdfs-3").unwrap();
        let theirs = render(ctx, &builtin, BrdfModules::builtin(), Shading::Forward);
        assert!(
            diff(&forward, &theirs).max > 8,
            "the engine BRDFs changed nothing"
        );
        let mut images = Vec::new();
        for (name, shading) in techniques().into_iter().skip(1) {
            let (image, ids) = render_ids(ctx, &scene, modules, shading);
            // The G-buffer's ids read back as the engine's BRDFs, by name.
            let named: Vec<&str> = ids.unwrap().iter().flatten().map(|b| b.name()).collect();
            assert!(
                named.contains(&"toon") && named.contains(&"charlie_sheen"),
                "{name}"
            );
            assert_close(&format!("engine-brdfs-{name}"), &forward, &image, 1);
            images.push((name, image));
        }
        // Stencil and branching light each pixel with one draw per light, in the same order,
        // by the same function: bit-identical, as with the built-ins.
        let d = diff(&images[0].1, &images[1].1);
        assert_eq!(d.max, 0, "branching against stencil: {d:?}");
    });
}

/// An engine BRDF whose function takes the tint is called with the pixel's colour by every
/// technique: spelling glTF's metallic-roughness so (`tint * tinted + white` from histencil's
/// own GLSL) gives the built-in's frames bit for bit, in every technique and every alpha mode. A
/// tint reaching it wrong anywhere (a white surface's, another pixel's) would change them.
#[test]
fn an_engine_brdf_taking_the_tint_gives_the_builtin_gltf_frames_bit_for_bit() {
    let dir = folder(
        "engine-brdfs-gltf-tinted",
        &[(
            "mine.glsl",
            "vec3 my_gltf(vec4 p, vec3 tint, vec3 N, vec3 T, vec3 V, vec3 L) {\n    vec2 g = brdf_gltf_metal_rough(p.x, p.y, N, V, L);\n    return tint * g.x + g.y;\n}\n",
        )],
    );
    let params = ["alpha", "metallic"].map(|name| EngineParam {
        name: name.into(),
        range: Range::new(0.0, 1.0),
        default: 0.5,
    });
    let spec = EngineBrdfSpec {
        name: "my_gltf".into(),
        glsl: "mine.glsl".into(),
        function: "my_gltf".into(),
        white: None,
        params: params.to_vec(),
        tangent: false,
        tint: true,
    };
    let set = BrdfSet::new(&BrdfId::ALL, vec![spec])
        .unwrap()
        .with_folder(dir.canonicalize().unwrap());
    let modules = histencil_vk::compile_brdf_set(&set).expect("compiles");
    let builtin = histencil_scene::embedded("pbr-mixed").unwrap();
    let mut engine = builtin.clone();
    let mut swapped = 0;
    for o in &mut engine.objects {
        if let Brdf::GltfMetalRough { alpha, metallic } = o.material.brdf {
            let given = [("alpha", alpha), ("metallic", metallic)];
            o.material.brdf = set.engine_brdf("my_gltf", &given).unwrap();
            swapped += 1;
        }
    }
    assert!(swapped > 0);
    // And a translucent sphere of it, in every alpha mode.
    let mut glass = histencil_scene::embedded("alpha").unwrap();
    glass.alpha_objects[0].material.brdf = Brdf::GltfMetalRough {
        alpha: 0.3,
        metallic: 0.4,
    };
    glass.alpha_objects[0].material.tint = glam::Vec3::new(0.9, 0.4, 0.1);
    let mut engine_glass = glass.clone();
    let given = [("alpha", 0.3), ("metallic", 0.4)];
    engine_glass.alpha_objects[0].material.brdf = set.engine_brdf("my_gltf", &given).unwrap();
    with_validated_context(|ctx| {
        for (name, shading) in techniques() {
            let expected = render(ctx, &builtin, BrdfModules::builtin(), shading);
            let actual = render(ctx, &engine, modules, shading);
            let d = diff(&expected, &actual);
            assert_eq!(d.max, 0, "{name}: the engine's glTF differs: {d:?}");
        }
        use histencil_vk::{AlphaMode, FrameDesc};
        let light = |scene: &histencil_scene::Scene, brdfs, alpha| {
            let desc = RendererDesc {
                brdfs,
                ..RendererDesc::new(SIZE, SIZE)
            };
            let mut renderer = Renderer::with_desc(ctx, scene.clone(), &desc).unwrap();
            let frame = FrameDesc {
                alpha,
                ..FrameDesc::new(Shading::Forward, Readback::ALL)
            };
            renderer.render_frame(&frame).unwrap().images.ldr.unwrap()
        };
        for mode in [
            AlphaMode::Forward,
            AlphaMode::Lightmap,
            AlphaMode::Probe,
            AlphaMode::Directional,
        ] {
            let expected = light(&glass, BrdfModules::builtin(), mode);
            let d = diff(&expected, &light(&engine_glass, modules, mode));
            assert_eq!(d.max, 0, "{mode:?}: the engine's glTF glass differs: {d:?}");
        }
    });
}

/// A metallic-roughness that goes with the base colour squared (`tests/brdfs/metal-rough`), as
/// engines write it and no `tint * f + white` can: every exact technique holds it to forward;
/// the LUT refuses it, naming why; the probe evaluates it at several colours.
#[test]
fn a_brdf_of_the_colour_squared_is_held_to_forward_and_refused_by_the_lut() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("brdfs/metal-rough");
    let set = BrdfSet::load(&dir).expect("tests/brdfs/metal-rough loads");
    let modules = histencil_vk::compile_brdf_set(&set).expect("compiles");
    let mut scene = histencil_scene::embedded("brdfs-3").unwrap();
    let mut swapped = 0;
    for (i, o) in scene.objects.iter_mut().enumerate() {
        if !matches!(o.material.brdf, Brdf::Lambert { .. } | Brdf::Ggx { .. }) {
            let given = [
                ("roughness", 0.3 + 0.1 * (i % 4) as f64),
                ("metallic", (i % 3) as f64 / 2.0),
            ];
            o.material.brdf = set.engine_brdf("metal_rough_rgb", &given).unwrap();
            swapped += 1;
        }
    }
    assert!(swapped > 0);
    with_validated_context(|ctx| {
        histencil_vk::probe_brdfs(ctx, modules).expect("finite and not negative");
        let forward = render(ctx, &scene, modules, Shading::Forward);
        assert!(lit_fraction(&forward) > 0.2);
        for (name, shading) in techniques().into_iter().skip(1) {
            let image = render(ctx, &scene, modules, shading);
            assert_close(&format!("engine-brdfs-rgb-{name}"), &forward, &image, 1);
        }
        let desc = RendererDesc {
            brdfs: modules,
            ..RendererDesc::new(SIZE, SIZE)
        };
        let mut renderer = Renderer::with_desc(ctx, scene.clone(), &desc).unwrap();
        let err = renderer.render(LUT, Readback::ALL).err().unwrap();
        let text = err.to_string();
        assert!(
            text.contains("`metal_rough_rgb`: its function takes the tint"),
            "{text}"
        );
        assert_eq!(err.cause(), histencil_vk::Cause::Data);
    });
    // Negative for some colours only: the probe's colours find it.
    let (_, modules) = one_brdf(
        "dim",
        "vec3 dim(vec4 p, vec3 tint, vec3 N, vec3 T, vec3 V, vec3 L) {\n    return vec3(max(dot(N, L), 0.0)) * (1.0 - 1.5 * tint);\n}\n",
        true,
    );
    let text = probe_refusal(modules);
    assert!(
        text.contains("engine BRDF `dim` returns -") && text.contains("for a surface of colour"),
        "{text}"
    );
    // Negative only near one colour, which the set's probe does not try (an outside trial's):
    // a renderer whose scene has a surface of that colour probes it at its own, and refuses.
    let (set, modules) = one_brdf(
        "near",
        "vec3 near(vec4 p, vec3 tint, vec3 N, vec3 T, vec3 V, vec3 L) {\n    float s = length(tint - vec3(0.37, 0.6, 0.2)) < 0.05 ? -1.0 : 1.0;\n    return vec3(max(dot(N, L), 0.0)) * s;\n}\n",
        true,
    );
    let mut scene = histencil_scene::embedded("default").unwrap();
    histencil_scene::retarget_brdfs(&mut scene, &set);
    with_validated_context(|ctx| {
        histencil_vk::probe_brdfs(ctx, modules).expect("the set's colours miss it");
        let desc = RendererDesc {
            brdfs: modules,
            ..RendererDesc::new(SIZE, SIZE)
        };
        Renderer::with_desc(ctx, scene.clone(), &desc).expect("no surface of that colour");
        scene.objects[0].material.tint = glam::Vec3::new(0.37, 0.6, 0.2);
        let err = Renderer::with_desc(ctx, scene, &desc).err().unwrap();
        let text = err.to_string();
        assert!(
            text.contains("engine BRDF `near` returns -") && text.contains("0.37"),
            "{text}"
        );
    });
}

/// A wrapped diffuse lights where `N.L <= 0`, where a table's axes end: the LUT would drop that
/// light in silence (an outside trial's wrap lobe came out 44/255 dark). The probe finds it and
/// the LUT refuses the BRDF by name, in `LutTables` and in a renderer's LUT frame alike.
#[test]
fn a_brdf_that_lights_below_the_horizon_has_no_table() {
    let (set, modules) = one_brdf(
        "wrapped",
        "vec3 wrapped(vec4 p, vec3 N, vec3 T, vec3 V, vec3 L) {\n    return vec3(0.8 * INV_PI * max((dot(N, L) + 0.5) / 1.5, 0.0));\n}\n",
        false,
    );
    let wrapped = set.engine_brdf("wrapped", &[]).unwrap();
    assert_eq!(
        set.tabulable(&wrapped),
        Ok(()),
        "the set alone cannot see it"
    );
    let mut scene = histencil_scene::embedded("default").unwrap();
    histencil_scene::retarget_brdfs(&mut scene, &set);
    with_validated_context(|ctx| {
        let err = histencil_vk::LutTables::with_modules(ctx, modules, &[wrapped], 9)
            .err()
            .unwrap()
            .to_string();
        assert!(
            err.contains("`wrapped`: it returns light where N.L <= 0"),
            "{err}"
        );
        let desc = RendererDesc {
            brdfs: modules,
            ..RendererDesc::new(SIZE, SIZE)
        };
        let mut renderer = Renderer::with_desc(ctx, scene, &desc).unwrap();
        let err = renderer.render(LUT, Readback::ALL).err().unwrap();
        assert!(
            matches!(err, histencil_vk::Error::LutUntabulable { .. }),
            "{err}"
        );
        // Every other technique lights it.
        let frame = renderer.render(Technique::DEFERRED, Readback::ALL).unwrap();
        assert!(lit_fraction(frame.images.ldr.as_ref().unwrap()) > 0.2);
    });
    // A division guarded with max(dot(N, L), 1e-4) leaves a trace at the horizon, a ten
    // thousandth of its light above it, which no table misses: it has a table.
    let (set, modules) = one_brdf(
        "guarded",
        "vec3 guarded(vec4 p, vec3 N, vec3 T, vec3 V, vec3 L) {\n    return vec3(0.8 * INV_PI * max(dot(N, L), 1e-4));\n}\n",
        false,
    );
    let guarded = set.engine_brdf("guarded", &[]).unwrap();
    with_validated_context(|ctx| {
        let tables = histencil_vk::LutTables::with_modules(ctx, modules, &[guarded], 9);
        assert!(tables.is_ok(), "{:?}", tables.err());
    });
}

#[test]
fn a_material_the_set_does_not_hold_and_a_non_finite_brdf_are_refused_before_recording() {
    let scene = histencil_scene::embedded("default").unwrap();
    let (set, modules) = one_brdf(
        "spiky",
        "vec3 spiky(vec4 p, vec3 N, vec3 T, vec3 V, vec3 L) {\n    return vec3(p.x / dot(N, L));\n}\n",
        false,
    );
    with_validated_context(|ctx| {
        let desc = RendererDesc {
            brdfs: modules,
            ..RendererDesc::new(SIZE, SIZE)
        };
        // The scene's Lambert is not in a set of the engine's BRDF alone.
        let err = Renderer::with_desc(ctx, scene.clone(), &desc)
            .err()
            .unwrap();
        assert!(
            err.to_string()
                .contains("is not in this lighting's BRDF set"),
            "{err}"
        );
        let mut spiky = scene.clone();
        histencil_scene::retarget_brdfs(&mut spiky, &set);
        let err = Renderer::with_desc(ctx, spiky, &desc).err().unwrap();
        let text = err.to_string();
        assert!(text.contains("engine BRDF `spiky` returns"), "{text}");
        assert_eq!(err.cause(), histencil_vk::Cause::Data);
    });
    // Negative light (an outside engine's BRDF read another's parameter row and gave it) is
    // refused as a NaN is, by the probe an engine runs itself (`probe_brdfs`).
    let (_, modules) = one_brdf(
        "negative",
        "vec3 negative(vec4 p, vec3 N, vec3 T, vec3 V, vec3 L) {\n    return vec3(max(dot(N, L), 0.0) - 0.25);\n}\n",
        false,
    );
    let text = probe_refusal(modules);
    assert!(
        text.contains("engine BRDF `negative` returns -") && text.contains("not negative"),
        "{text}"
    );
}

#[test]
fn glsl_that_does_not_compile_names_the_engine_file_and_line() {
    let dir = folder(
        "engine-brdfs-broken",
        &[(
            "broken.glsl",
            "// line 1\nvec3 broken(vec4 p, vec3 N, vec3 T, vec3 V, vec3 L) {\n    return vec3(p.x;\n}\n",
        )],
    );
    let spec = EngineBrdfSpec {
        name: "broken".into(),
        glsl: "broken.glsl".into(),
        function: "broken".into(),
        white: None,
        params: vec![],
        tangent: false,
        tint: false,
    };
    let real = dir.canonicalize().unwrap();
    let set = BrdfSet::new(&[], vec![spec])
        .unwrap()
        .with_folder(real.clone());
    let err = histencil_vk::compile_brdf_set(&set).unwrap_err();
    let at = format!("{}:3:", real.join("broken.glsl").display());
    assert!(err.contains(&at), "{err}");
    // A function the file does not define: glslc names it.
    let set = BrdfSet::new(
        &[],
        vec![EngineBrdfSpec {
            name: "absent".into(),
            glsl: "broken.glsl".into(),
            function: "no_such_function".into(),
            white: None,
            params: vec![],
            tangent: false,
            tint: false,
        }],
    )
    .unwrap()
    .with_folder(real);
    assert!(histencil_vk::compile_brdf_set(&set).is_err());
}

/// The lab takes the same folder: `calibrate --brdfs` fits costs on a wall striped in the
/// engine's BRDFs, and `compare --brdfs` folds its columns onto them and names them.
#[test]
fn the_lab_measures_the_engine_brdfs() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/brdfs");
    let modules = histencil_vk::compile_brdf_set(&BrdfSet::load(&dir).unwrap()).unwrap();
    let sampling = histencil_lab::stats::Sampling::rounds(2);
    with_validated_context(|ctx| {
        let calibration =
            histencil_lab::calibrate_with(ctx, (64, 36), modules, &sampling, None, &mut |_| {})
                .unwrap();
        let c = calibration.costs;
        assert!(c.shade_ms > 0.0 && c.pass_overhead_ms.is_finite(), "{c:?}");
        // Each engine BRDF weighed on its own (and the wall's padding), relative to their mean;
        // the costs file carries the weights by name, and they read back for this set only.
        let weights = &calibration.brdf_weights;
        let names: Vec<&str> = weights.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["toon", "charlie_sheen", "lambert"]);
        for (name, w) in weights {
            assert!(
                w.lo > 0.0 && w.lo <= w.median && w.median <= w.hi,
                "{name}: {w:?}"
            );
        }
        let path =
            std::env::temp_dir().join(format!("histencil-weights-{}.json", std::process::id()));
        calibration.write(&path).unwrap();
        let read = histencil_lab::read_brdf_weights(&path, &modules.set)
            .unwrap()
            .unwrap();
        let toon = modules.set.by_name("toon").unwrap();
        assert_eq!(read.get(toon), weights[0].1.median as f32);
        let builtin = &histencil_vk::BrdfModules::builtin().set;
        let err = histencil_lab::read_brdf_weights(&path, builtin)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("`charlie_sheen`") && err.contains("another set"),
            "{err}"
        );
        std::fs::remove_file(&path).unwrap();
        let mut settings = histencil_lab::compare::CompareSettings::talk(64, 36, 2);
        settings.brdfs = modules;
        settings.light_sizes = vec![1.0];
        settings.scene = histencil_scene::embedded("huge-lights").unwrap();
        histencil_scene::retarget_brdfs(&mut settings.scene, &modules.set);
        let report = histencil_lab::run_compare(ctx, &settings, &mut |_| {}).unwrap();
        assert_eq!(report.models, ["toon", "charlie_sheen", "lambert"]);
        // The steady clock's canary renders the engine's set too: the table and the size.
        let stability = report
            .stability
            .as_ref()
            .expect("a steady clock by default");
        assert_eq!(stability.sets.len(), 2, "{stability:?}");
        // The sheen's white part is held beside its tinted part: the LUT row is measured.
        assert!(report.rows.iter().any(|r| r.name == "lut"));
        assert_eq!(report.lut_left_out, None);
        // Its error is stated against the tables' resolution.
        assert!(report.markdown().contains("tables hold 32 points per axis"));
        assert!(report
            .markdown()
            .contains("the 2-BRDF column adds `charlie_sheen`"));
    });
}

/// A translucent entity with an engine BRDF is lit by it in every alpha mode: per pixel
/// forward, by lightmap, by probe and by direction map, the glass sphere of `alpha` in Charlie
/// sheen adds light above the same sphere in black (a Lambert of tint 0, which only darkens what
/// is behind it), as its white Lambert twin does. A mode whose shader lacked the set's BRDF would
/// shade it black. (The pane of `own-brdfs.gltf`, from the test scene `two-brdfs.gltf`, faces
/// away from its lights: it is black whatever its BRDF.)
#[test]
fn an_alpha_entity_with_an_engine_brdf_is_lit_in_every_alpha_mode() {
    use histencil_vk::{AlphaMode, FrameDesc};
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/brdfs");
    let set = BrdfSet::load(&dir).unwrap();
    let modules = histencil_vk::compile_brdf_set(&set).unwrap();
    let mut scene = histencil_scene::embedded("alpha").unwrap();
    scene.alpha_objects[0].material.brdf = set.engine_brdf("charlie_sheen", &[]).unwrap();
    let mut white = scene.clone();
    white.alpha_objects[0].material.brdf = Brdf::Lambert { rho: 1.0 };
    let mut black = white.clone();
    black.alpha_objects[0].material.tint = glam::Vec3::ZERO;
    let desc = RendererDesc {
        brdfs: modules,
        ..RendererDesc::new(SIZE, SIZE)
    };
    with_validated_context(|ctx| {
        let light = |scene: &histencil_scene::Scene, alpha| {
            let mut renderer = Renderer::with_desc(ctx, scene.clone(), &desc).unwrap();
            let frame = FrameDesc {
                alpha,
                ..FrameDesc::new(Shading::Forward, Readback::ALL)
            };
            let ldr = renderer.render_frame(&frame).unwrap().images.ldr.unwrap();
            ldr.pixels()
                .map(|p| f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2]))
                .sum::<f64>()
        };
        for mode in [
            AlphaMode::Forward,
            AlphaMode::Lightmap,
            AlphaMode::Probe,
            AlphaMode::Directional,
        ] {
            let dark = light(&black, mode);
            let lambert = light(&white, mode) - dark;
            let sheen = light(&scene, mode) - dark;
            assert!(lambert > 0.0, "{mode:?}: the white twin adds {lambert}");
            assert!(
                sheen > 0.05 * lambert,
                "{mode:?}: the sheen glass adds {sheen} over a black one, its white Lambert twin {lambert}"
            );
        }
    });
}

/// An engine BRDF's LUT table is filled by its own GLSL on the GPU, at histencil-brdf's grid
/// points: one spelling GGX with histencil's GLSL fills the table that the built-in GGX's f64
/// reference bakes, within the GLSL's own error against that reference (`brdf_gpu.rs`: 1e-2 of
/// max(1, |value|) on hard cases, which grazing grid points are), and lights the LUT frame as the
/// built-in's table does. A BRDF no table can hold is refused, saying why (one reading the
/// tangent); Charlie sheen's table holds its white lobe beside its tinted base.
#[test]
fn an_engine_brdfs_lut_table_is_filled_by_its_glsl() {
    let dir = folder(
        "engine-brdfs-ggx",
        &[(
            "mine.glsl",
            "vec3 my_ggx(vec4 p, vec3 N, vec3 T, vec3 V, vec3 L) {\n    return vec3(brdf_ggx(p.x, p.y, p.z, N, V, L));\n}\n",
        )],
    );
    let params = ["alpha", "f0", "f90"].map(|name| EngineParam {
        name: name.into(),
        range: Range::new(0.0, 1.0),
        default: 0.5,
    });
    let spec = |name: &str, tangent| EngineBrdfSpec {
        name: name.into(),
        glsl: "mine.glsl".into(),
        function: "my_ggx".into(),
        white: None,
        params: params.to_vec(),
        tangent,
        tint: false,
    };
    let set = BrdfSet::new(
        &BrdfId::ALL,
        vec![spec("my_ggx", false), spec("combed", true)],
    )
    .unwrap()
    .with_folder(dir.canonicalize().unwrap());
    let modules = histencil_vk::compile_brdf_set(&set).expect("compiles");
    let builtin = histencil_scene::embedded("brdfs-3").unwrap();
    let mut engine = builtin.clone();
    let mut ggx = None;
    for o in &mut engine.objects {
        if let Brdf::Ggx { alpha, f0, f90 } = o.material.brdf {
            ggx = Some(o.material.brdf);
            let given = [("alpha", alpha), ("f0", f0), ("f90", f90)];
            o.material.brdf = set.engine_brdf("my_ggx", &given).unwrap();
        }
    }
    let ggx = ggx.expect("brdfs-3 has GGX");
    let Brdf::Ggx { alpha, f0, f90 } = ggx else {
        unreachable!()
    };
    let given = [("alpha", alpha), ("f0", f0), ("f90", f90)];
    let mine = set.engine_brdf("my_ggx", &given).unwrap();
    let lut: Shading = LUT.into();
    with_validated_context(|ctx| {
        let cpu = histencil_vk::LutTables::new(ctx, &[ggx], 9).unwrap();
        let gpu = histencil_vk::LutTables::with_modules(ctx, modules, &[mine], 9).unwrap();
        let (c, g) = (&cpu.luts()[0], &gpu.luts()[0]);
        assert_eq!((c.axes, c.values.len()), (g.axes, g.values.len()));
        let mut worst = 0f64;
        for (a, b) in c.values.iter().zip(&g.values) {
            for k in 0..3 {
                let scale = f64::from(a[k].abs()).max(1.0);
                worst = worst.max(f64::from((a[k] - b[k]).abs()) / scale);
            }
        }
        println!("engine GGX table against the built-in's, 9^3 points: {worst:.2e}");
        assert!(worst <= 1e-2, "{worst:e}");

        let theirs = render(ctx, &builtin, BrdfModules::builtin(), lut);
        let ours = render(ctx, &engine, modules, lut);
        assert!(lit_fraction(&ours) > 0.2);
        assert_close("engine-brdfs-lut", &theirs, &ours, 1);
        let forward = render(ctx, &engine, modules, Shading::Forward);
        let e = diff(&forward, &ours);
        let bound = histencil_check::judge::LUT;
        assert!(e.max <= bound.max && e.mean <= bound.mean, "{e:?}");

        let combed = set.engine_brdf("combed", &given).unwrap();
        let err = histencil_vk::LutTables::with_modules(ctx, modules, &[combed], 9)
            .err()
            .unwrap()
            .to_string();
        assert!(err.contains("`combed`: it reads the tangent"), "{err}");
        // The example folder's own scene: the toon ramp and the Charlie sheen, whose table
        // holds its white lobe beside its tinted base. Every object is lit, and the frame is
        // within 1/255 of forward on the mean (the toon's hard band edges are the most a
        // table misses).
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/brdfs");
        let example = BrdfSet::load(&dir).unwrap();
        let example_modules = histencil_vk::compile_brdf_set(&example).unwrap();
        let own = histencil_scene::load_gltf_in(&dir.join("own-brdfs.gltf"), &example)
            .unwrap()
            .scene;
        let sheen = example.engine_brdf("charlie_sheen", &[]).unwrap();
        let tables =
            histencil_vk::LutTables::with_modules(ctx, example_modules, &[sheen], 9).unwrap();
        assert!(tables.luts()[0].has_white());
        let forward = render(ctx, &own, example_modules, Shading::Forward);
        let (table, ids) = render_ids(ctx, &own, example_modules, lut);
        let ids = ids.unwrap();
        for brdf in ["toon", "charlie_sheen"] {
            let pixels: Vec<_> = (ids.iter().zip(table.pixels()))
                .filter(|(id, _)| id.is_some_and(|b| b.name() == brdf))
                .collect();
            let lit = pixels.iter().filter(|(_, p)| p.0[..3] != [0; 3]).count();
            println!("{brdf}: {lit} of {} pixels lit", pixels.len());
            assert!(!pixels.is_empty() && lit * 2 > pixels.len(), "{brdf} unlit");
        }
        let e = diff(&forward, &table);
        println!("own-brdfs.gltf, LUT against forward: {e:?}");
        assert!(e.mean <= 1.0, "{e:?}");
    });
}
