//! The `material` fuzz target ([`histencil_fuzz::material`]).

fn main() {
    histencil_fuzz::run(histencil_fuzz::material);
}
