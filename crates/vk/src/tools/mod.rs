//! What histencil's own command line, lab and tests use beyond an engine's needs: the BRDF
//! evaluator that holds the GLSL to the Rust reference, and (feature `tools`) image error
//! measures and file output.

pub(crate) mod brdf_eval;
#[cfg(feature = "tools")]
pub(crate) mod image_error;
#[cfg(feature = "tools")]
pub(crate) mod output;
