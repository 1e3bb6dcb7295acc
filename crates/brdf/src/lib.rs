//! BRDF maths for histencil: one definition, spelled twice (here in Rust, generic over f32 and
//! f64, and in GLSL under `crates/vk/shaders/include/brdf/`), held together by tests.
//!
//! # Convention
//! Every function returns `f_r * cos(theta_L)`: the reflected radiance for a directional light of
//! unit irradiance perpendicular to the light. So Lambert is `rho / pi * max(N.L, 0)`.
//! - All vectors point away from the surface and need not be normalized; denormal-scale and huge
//!   inputs are rescaled before normalising. A zero (or non-finite) vector gives 0.
//! - Surface BRDFs (Lambert, Blinn-Phong, Oren-Nayar, GGX): `N.L <= 0` gives 0; a view below
//!   the horizon (`N.V < 0`, which shading normals give along silhouettes) is evaluated as the
//!   grazing view of the same azimuth, so the value is continuous there; `N.V == 0` with
//!   `N.L > 0` gives the finite limit.
//! - Kajiya-Kay ignores N and is not gated; a zero tangent gives 0.
//! - Penner skin is not gated (light wraps past the terminator) and ignores V.
//! - GGX clamps alpha to [`GGX_MIN_ALPHA`]; `pow(0, 0)` is 1 everywhere (GLSL leaves it undefined,
//!   so the GLSL guards it).
//!
//! # Models
//! [`lambert`], normalized [`blinn_phong`], [`oren_nayar_full`] (1994, with inter-reflection),
//! [`oren_nayar_qualitative`], [`ggx`] (Cook-Torrance: GGX D, Smith height-correlated visibility,
//! Schlick Fresnel), [`kajiya_kay`] and Penner's pre-integrated skin [`penner_skin`]. [`Brdf`]
//! holds a model with its parameters and evaluates it as the f64 reference or the f32 spelling.
//!
//! [`lut`] bakes the talk's look-up tables and measures their error against resolution;
//! [`encoding`] measures what G-buffer quantisation adds; `eval_csv` (with the `files` feature,
//! as `Brdf::parse`) reads and writes the `brdf-eval` case files.
//!
//! [`BrdfId`] is the renderer's list of shading models stored in the G-buffer and stencil;
//! [`MaterialRows`] lays an engine's materials out as rows its decode hook reads by material
//! index, so materials of one BRDF keep their own parameters.
//! [`BrdfSet`] adds an engine's own (GLSL functions, read from a `brdfs.toml` folder with the
//! `files` feature) to the built-ins it keeps.

#![warn(missing_docs)]

pub mod cases;
pub mod encoding;
#[cfg(feature = "files")]
pub mod eval_csv;
pub mod half_float;
mod id;
#[cfg(feature = "manifest")]
mod includes;
pub mod lut;
#[cfg(feature = "manifest")]
mod manifest;
mod materials;
mod model;
mod models;
mod set;
mod vector;
mod weights;

pub use id::{BrdfId, EngineBrdf, UnknownBrdf, ENGINE_FIRST, MAX_ENGINE_BRDFS};
#[cfg(feature = "manifest")]
pub use manifest::{ManifestError, MANIFEST};
pub use materials::{MaterialError, MaterialRows, MATERIAL_ROW_BYTES};
pub use model::{ranges, Brdf, BrdfError, Parts, Range, MODEL_NAMES};
pub use models::*;
pub use set::{BrdfSet, EngineBrdfSpec, EngineParam, SetError, MAX_ENGINE_PARAMS, MODEL_IDS};
pub use vector::{normalize, Real, V3};
pub use weights::{BrdfWeights, WeightsError};
