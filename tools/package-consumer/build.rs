//! histencil's light shaders with this consumer's visibility hook, from the packages.
//!
//! tools/test builds this consumer with `HISTENCIL_GLSLC` pointing at a program that always
//! fails, so that a package reaching for glslc fails the build: each ships its SPIR-V. Hooks are
//! compiled by the engine's own build script, here this one, with the compiler
//! `HISTENCIL_CONSUMER_GLSLC` names.

fn main() {
    println!("cargo:rerun-if-env-changed=HISTENCIL_CONSUMER_GLSLC");
    if let Some(glslc) = std::env::var_os("HISTENCIL_CONSUMER_GLSLC") {
        std::env::set_var("HISTENCIL_GLSLC", glslc);
    }
    let out = std::path::PathBuf::from(std::env::var("OUT_DIR").unwrap());
    histencil_build::compile_light_shaders("hooks".as_ref(), &out)
        .unwrap_or_else(|e| panic!("{e}"));
}
