//! The engine's own shaders, compiled with glslc, and histencil's light shaders compiled with the
//! engine's decode hook (`shaders/histencil_hooks`) and its own BRDFs (`../brdfs`: a toon ramp
//! and glTF's Charlie sheen) by histencil_build. `gbuffer.frag` includes histencil's
//! `gbuffer_write.glsl` and the alpha shaders its `lightmap_sample.glsl`; histencil says where
//! they are (DEP_HISTENCIL_INCLUDE, and DEP_HISTENCIL_GENERATED for the BRDF ids the compact
//! G-buffer names); the engine's forward reference shades with its BRDFs through the set's
//! include folder (histencil_build::write_brdf_set), searched first.

use std::path::PathBuf;

fn main() {
    let include = std::env::var("DEP_HISTENCIL_INCLUDE")
        .expect("histencil publishes its GLSL include folder");
    let generated =
        std::env::var("DEP_HISTENCIL_GENERATED").expect("histencil publishes its generated GLSL");
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap());
    let glslc = std::env::var("HISTENCIL_GLSLC").unwrap_or_else(|_| "glslc".into());
    let brdfs = histencil_build::brdf_folder(std::path::Path::new("../brdfs"))
        .unwrap_or_else(|e| panic!("{e}"));
    let set_include =
        histencil_build::write_brdf_set(&brdfs, &out).unwrap_or_else(|e| panic!("{e}"));
    for shared in [
        "alpha.glsl",
        "histencil_hooks/compact_gbuffer.glsl",
        "histencil_hooks/light_visibility.glsl",
    ] {
        println!("cargo:rerun-if-changed=shaders/{shared}");
    }
    // (output, source, defines): the compact G-buffer's vertex stage is gbuffer.vert without
    // the linear depth output, and so is the forward reference's (it rebuilds position from depth).
    let stages = [
        ("gbuffer.vert", "gbuffer.vert", None),
        ("gbuffer_compact.vert", "gbuffer.vert", Some("-DCOMPACT")),
        ("forward.vert", "gbuffer.vert", Some("-DFORWARD")),
        ("forward.frag", "forward.frag", None),
        ("shadow.vert", "shadow.vert", None),
        ("shadow.frag", "shadow.frag", None),
        ("gbuffer.frag", "gbuffer.frag", None),
        ("gbuffer_compact.frag", "gbuffer_compact.frag", None),
        ("alpha_object.vert", "alpha_object.vert", None),
        ("alpha_object.frag", "alpha_object.frag", None),
        ("particle.vert", "particle.vert", None),
        ("particle.frag", "particle.frag", None),
    ];
    for (name, source, define) in stages {
        let source = format!("shaders/{source}");
        println!("cargo:rerun-if-changed={source}");
        let status = std::process::Command::new(&glslc)
            .args(["--target-env=vulkan1.3", "-O", "-Werror"])
            .args(define)
            .arg(format!("-I{}", set_include.display()))
            .arg(format!("-I{include}"))
            .arg(format!("-I{generated}"))
            .arg(&source)
            .arg("-o")
            .arg(out.join(format!("{name}.spv")))
            .status()
            .expect("glslc (apt install glslc, or the Vulkan SDK)");
        assert!(status.success(), "glslc failed on {source}");
    }
    // histencil's light shaders with the engine's decode and visibility hooks; the decode
    // includes the layout beside it (histencil_hooks/compact_gbuffer.glsl, shared with
    // gbuffer_compact.frag and forward.frag).
    let hooks = std::path::Path::new("shaders/histencil_hooks");
    histencil_build::compile_light_shaders_for(Some(hooks), &brdfs, &out)
        .unwrap_or_else(|e| panic!("{e}"));
    // And every BRDF-evaluating module with histencil's own G-buffer: the lighting the compact
    // layout is timed against, the lightmaps and histencil's Renderer of the same state.
    histencil_build::compile_brdf_modules(&brdfs, &out).unwrap_or_else(|e| panic!("{e}"));
}
