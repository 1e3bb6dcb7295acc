//! Re-publishes histencil-vk's shader folders to the build scripts of this crate's dependents:
//! an engine that depends on `histencil` alone gets `DEP_HISTENCIL_INCLUDE` (the GLSL includes,
//! `gbuffer_write.glsl` and `lightmap_sample.glsl` among them), `DEP_HISTENCIL_SHADERS` and
//! `DEP_HISTENCIL_GENERATED` (for `histencil_build::compile_light_shaders`).

fn main() {
    for (from, to) in [
        ("DEP_HISTENCIL_GLSL_INCLUDE", "include"),
        ("DEP_HISTENCIL_GLSL_SHADERS", "shaders"),
        ("DEP_HISTENCIL_GLSL_GENERATED", "generated"),
    ] {
        let value = std::env::var(from).unwrap_or_else(|_| panic!("histencil-vk sets {from}"));
        println!("cargo:{to}={value}");
    }
}
