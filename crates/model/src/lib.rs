//! histencil-model: everything about stencil bits and hi-stencil that can be decided without a GPU.
//!
//! # The talk's algorithm, in short
//! A deferred renderer normally runs one light shader for every pixel a light touches, so every
//! pixel gets the same BRDF. To allow several BRDFs without paying for a branch in every light
//! shader, each pixel's BRDF id is written into stencil bits by the G-buffer pass. Each light
//! volume is then drawn once per BRDF it actually touches, each time masked by stencil so only the
//! pixels of that BRDF run that BRDF's light shader.
//!
//! The same stencil byte already serves light *depth culling*: back faces of the light volume mark
//! a culling bit where the surface lies behind the volume, front faces shade where the bit is
//! clear, back faces clear it again. The talk packs both into one byte:
//!
//! ```text
//!   bit:   7   6   5   4 | 3   2   1 | 0
//!          preserved     | BRDF id   | culling
//!          (engine data) |           |
//! ```
//!
//! With 8 BRDFs in use: `culling_mask = 0x01`, `brdf_mask = 0x0E`, `brdf_shift = 1`, preserved
//! `0xF0`. The layout here is derived from the number of BRDFs a scene uses, never hard-coded.

mod layout;

pub use layout::{LayoutError, StencilLayout};
