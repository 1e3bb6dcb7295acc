//! The `gltf` fuzz target ([`histencil_fuzz::gltf`]).

fn main() {
    histencil_fuzz::run(histencil_fuzz::gltf);
}
