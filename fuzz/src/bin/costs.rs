//! The `costs` fuzz target ([`histencil_fuzz::costs`]).

fn main() {
    histencil_fuzz::run(histencil_fuzz::costs);
}
