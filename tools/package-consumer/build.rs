//! histencil's light shaders with this consumer's visibility hook, from the packages.

fn main() {
    let out = std::path::PathBuf::from(std::env::var("OUT_DIR").unwrap());
    histencil_build::compile_light_shaders("hooks".as_ref(), &out)
        .unwrap_or_else(|e| panic!("{e}"));
}
