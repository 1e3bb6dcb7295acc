//! BRDF maths for histencil: one definition, spelled twice (here in Rust, and in GLSL under
//! `shaders/include/brdf.glsl`), held together by tests.
//!
//! # Convention
//! Every function returns `f_r * cos(theta_L)`: the reflected radiance for a directional light of
//! unit irradiance perpendicular to the light. So Lambert is `rho / pi * max(N.L, 0)`. All vectors
//! point away from the surface and need not be normalized. For surface BRDFs, `N.L <= 0` or
//! `N.V < 0` gives 0.
//!
//! The spine implements Lambert and normalized Blinn-Phong; the `[brdf]` issue extends [`BrdfId`]
//! with Oren-Nayar, GGX, Kajiya-Kay and pre-integrated skin.

mod id;
pub mod reference;

pub use id::{BrdfId, UnknownBrdf};
