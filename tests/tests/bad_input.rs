//! Bad input gives a clear error, never a panic, and leaves the context validation-clean.

use histencil_tests::with_validated_context;
use histencil_vk::{Error, Renderer};

#[test]
fn zero_and_oversized_resolutions_are_errors() {
    let scene = histencil_scene::embedded("default").unwrap();
    with_validated_context(|ctx| {
        for (w, h) in [(0, 64), (64, 0), (1 << 20, 64)] {
            match Renderer::new(ctx, scene.clone(), w, h) {
                Err(e @ Error::BadResolution { .. }) => {
                    assert!(e.to_string().contains(&format!("{w}x{h}")))
                }
                Err(e) => panic!("{w}x{h}: wrong error {e}"),
                Ok(_) => panic!("{w}x{h} accepted"),
            }
        }
    });
}

#[test]
fn nan_and_zero_size_lights_are_errors() {
    let mut scene = histencil_scene::embedded("default").unwrap();
    scene.lights[3].color.y = f32::NAN;
    with_validated_context(|ctx| {
        let err = Renderer::new(ctx, scene.clone(), 32, 32)
            .err()
            .expect("NaN light rejected");
        assert!(err.to_string().contains("light 3"), "{err}");
        scene.lights[3].color.y = 1.0;
        scene.lights[5].radius = 0.0;
        let err = Renderer::new(ctx, scene.clone(), 32, 32)
            .err()
            .expect("zero-size light rejected");
        assert!(err.to_string().contains("light 5"), "{err}");
    });
}

/// Every error in `err`'s chain says something its parent did not: a message never repeats its
/// own cause (`LUT resolution 0 is out of range: LUT resolution 0 is out of range`).
fn assert_says_each_thing_once(err: &(dyn std::error::Error + 'static)) {
    let mut parent = err.to_string();
    assert!(!parent.is_empty(), "an empty error message");
    let mut source = err.source();
    while let Some(cause) = source {
        let text = cause.to_string();
        assert!(
            !parent.contains(&text),
            "`{parent}` repeats its cause `{text}`"
        );
        parent = text;
        source = cause.source();
    }
}

/// The kinds of finite value that break f32 arithmetic somewhere: beyond f32's range, at its
/// edge, huge but representable, tiny, denormal, zero and negative.
const HOSTILE: [f64; 9] = [1e39, 3.0e38, 1e30, 1e12, 1e-30, 1e-45, 0.0, -1.0, -1e30];

/// Numbers of the glTF test scene that reach the GPU: light ranges, intensities and cone,
/// BRDF parameters and tints in extras, node translations and scales (objects, lights, the
/// camera), the camera's projection.
const SITES: [&str; 14] = [
    "/extensions/KHR_lights_punctual/lights/0/range",
    "/extensions/KHR_lights_punctual/lights/1/intensity",
    "/extensions/KHR_lights_punctual/lights/2/spot/outerConeAngle",
    "/materials/0/extras/rho",
    "/materials/0/extras/sigma",
    "/materials/1/extras/n",
    "/materials/1/extras/tint/0",
    "/nodes/0/scale/0",
    "/nodes/0/translation/1",
    "/nodes/3/translation/0",
    "/nodes/6/translation/2",
    "/cameras/0/perspective/znear",
    "/cameras/0/perspective/zfar",
    "/cameras/0/perspective/yfov",
];

/// Accessor fields the importer must not read past: component types, element types, the
/// normalised flag, on POSITION (0), NORMAL (1), the indices (2) and the pane's TEXCOORD_0 (4).
fn accessor_mutations() -> Vec<(String, serde_json::Value)> {
    use serde_json::json;
    let mut out = vec![];
    for accessor in [0, 1, 2, 4] {
        for component in [5120, 5121, 5122, 5123, 5125, 5126] {
            out.push((
                format!("/accessors/{accessor}/componentType"),
                json!(component),
            ));
        }
        for kind in ["SCALAR", "VEC2", "VEC4", "MAT2"] {
            out.push((format!("/accessors/{accessor}/type"), json!(kind)));
        }
        out.push((format!("/accessors/{accessor}/normalized"), json!(true)));
    }
    out
}

/// The hostile-input generator: every site x every hostile value, and every accessor
/// mutation. Each either fails to import with a message that names its cause once, or imports
/// into a scene that the stencil technique renders within 1/255 of forward under validation
/// (what the GPU accepts, it computes as the CPU-side reference does: no inf, no NaN, no black
/// frame where forward is lit), never a panic.
#[test]
fn hostile_gltf_values_are_refused_or_rendered_exactly() {
    use histencil_tests::gltf_builder::{test_gltf, write};
    use histencil_vk::{Backend, FlushPolicy, Readback, Shading, Technique};
    let (doc, bin) = test_gltf("blinn_phong");
    let mut cases: Vec<(String, serde_json::Value)> = vec![];
    for site in SITES {
        for value in HOSTILE {
            cases.push((site.to_owned(), serde_json::json!(value)));
        }
    }
    cases.extend(accessor_mutations());
    let stencil = Technique::Stencil {
        backend: Backend::X360 {
            zero_preserved: true,
            save_restore: false,
        },
        flush: FlushPolicy::Auto,
    };
    let ldr = Readback {
        ldr: true,
        ..Readback::NONE
    };
    let (mut refused, mut rendered, mut wrong) = (0, 0, vec![]);
    with_validated_context(|ctx| {
        for (i, (site, value)) in cases.iter().enumerate() {
            let mut doc = doc.clone();
            match doc.pointer_mut(site) {
                Some(slot) => *slot = value.clone(),
                None => {
                    let (parent, key) = site.rsplit_once('/').unwrap();
                    doc.pointer_mut(parent).unwrap_or_else(|| panic!("{site}"))[key] =
                        value.clone();
                }
            }
            let path = write(&format!("hostile-{i}"), &doc, &bin);
            let scene = match histencil_scene::load_scene(path.to_str().unwrap()) {
                Ok(scene) => scene,
                Err(e) => {
                    assert_says_each_thing_once(&e);
                    refused += 1;
                    continue;
                }
            };
            let what = format!("{site} = {value}");
            let mut renderer = match Renderer::new(ctx, scene, 24, 24) {
                Ok(r) => r,
                Err(e) => {
                    assert_says_each_thing_once(&e);
                    refused += 1;
                    continue;
                }
            };
            let mut frame = |t: Shading| {
                let frame = renderer
                    .render(t, ldr)
                    .unwrap_or_else(|e| panic!("{what}: {e}"));
                frame.images.ldr.unwrap()
            };
            let deferred = frame(stencil.into());
            let forward = frame(Shading::Forward);
            let d = histencil_tests::diff(&deferred, &forward);
            if d.max > 1 {
                wrong.push(format!("{what}: stencil {d:?} off forward"));
            }
            rendered += 1;
        }
    });
    eprintln!(
        "{} hostile cases: {refused} refused, {rendered} rendered",
        cases.len()
    );
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    assert!(refused > 0 && rendered > 0);
}

/// Light ranges far beyond the scene (up to f32's largest) light it exactly as forward does:
/// the range is capped where its window is already 1 everywhere in the scene.
#[test]
fn huge_light_ranges_render_as_forward_does() {
    use histencil_vk::{Backend, FlushPolicy, Readback, Shading, Technique};
    let mut scene = histencil_scene::embedded("default").unwrap();
    for light in scene.lights.iter_mut().filter(|l| l.is_local()) {
        light.radius = f32::MAX;
    }
    let ldr = Readback {
        ldr: true,
        ..Readback::NONE
    };
    with_validated_context(|ctx| {
        let mut renderer = Renderer::new(ctx, scene, 48, 48).unwrap();
        let mut frame = |t: Shading| renderer.render(t, ldr).unwrap().images.ldr.unwrap();
        let forward = frame(Shading::Forward);
        assert!(histencil_tests::lit_fraction(&forward) > 0.5);
        for backend in [Backend::Native, Backend::Ps3] {
            let flush = FlushPolicy::Auto;
            let deferred = frame(Technique::Stencil { backend, flush }.into());
            histencil_tests::assert_close("huge-ranges", &deferred, &forward, 1);
        }
    });
}
