//! The engine's own shaders, compiled with glslc. `gbuffer.frag` includes histencil's
//! `gbuffer_write.glsl` and the alpha shaders its `lightmap_sample.glsl`; histencil-vk says where
//! they are (DEP_HISTENCIL_GLSL_INCLUDE).

use std::path::PathBuf;

fn main() {
    let include = std::env::var("DEP_HISTENCIL_GLSL_INCLUDE")
        .expect("histencil-vk publishes its GLSL include folder");
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap());
    let glslc = std::env::var("HISTENCIL_GLSLC").unwrap_or_else(|_| "glslc".into());
    println!("cargo:rerun-if-changed=shaders/alpha.glsl");
    let stages = [
        "gbuffer.vert",
        "gbuffer.frag",
        "alpha_object.vert",
        "alpha_object.frag",
        "particle.vert",
        "particle.frag",
    ];
    for name in stages {
        let source = format!("shaders/{name}");
        println!("cargo:rerun-if-changed={source}");
        let status = std::process::Command::new(&glslc)
            .args(["--target-env=vulkan1.3", "-O", "-Werror"])
            .arg(format!("-I{include}"))
            .arg(&source)
            .arg("-o")
            .arg(out.join(format!("{name}.spv")))
            .status()
            .expect("glslc (apt install glslc, or the Vulkan SDK)");
        assert!(status.success(), "glslc failed on {source}");
    }
}
