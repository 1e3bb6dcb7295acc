//! The `engine_plan` fuzz target ([`histencil_fuzz::engine_plan`]).

fn main() {
    histencil_fuzz::run(histencil_fuzz::engine_plan);
}
