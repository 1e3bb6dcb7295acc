//! The book's two-target hooks (`examples/hooks/two_target`) compiled with histencil's light
//! shaders as an engine's build script compiles its own (`histencil_build`), for
//! `tests/engine_hook_two_target.rs`: what the engine chapter shows is what the tests compile.

fn main() {
    let out = std::path::PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    let hooks = std::path::Path::new("../examples/hooks/two_target");
    histencil_build::compile_light_shaders(hooks, &out).unwrap_or_else(|e| panic!("{e}"));
}
