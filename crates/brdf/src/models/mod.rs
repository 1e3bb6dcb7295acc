//! The BRDF models, each written once, generic over `f32` / `f64` ([`crate::Real`]).

mod fibre;
mod gltf;
mod skin;
mod surface;

pub use fibre::kajiya_kay;
pub use gltf::gltf_metal_rough;
pub use skin::{
    penner_skin, skin_diffusion, FLAT_LIMIT as SKIN_FLAT_LIMIT, REFERENCE_PANELS, SHIPPING_PANELS,
    SKIN_PROFILE,
};
pub use surface::{
    blinn_phong, ggx, lambert, oren_nayar_full, oren_nayar_qualitative, GGX_MIN_ALPHA,
};
