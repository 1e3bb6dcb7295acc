//! The `brdf_csv` fuzz target ([`histencil_fuzz::brdf_csv`]).

fn main() {
    histencil_fuzz::run(histencil_fuzz::brdf_csv);
}
