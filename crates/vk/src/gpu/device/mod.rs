//! The device and what lives as long as it: the context (borrowed or owned), memory and
//! resources, descriptor and pipeline layouts, the driver's facts, limits and quirks, the
//! validation log and its canary, the hazard check the encoder feeds, and teardown.

pub(crate) mod canary;
pub(crate) mod context;
pub(crate) mod debug;
pub mod descriptors;
pub(crate) mod driver;
pub(crate) mod error;
pub(crate) mod hazards;
pub(crate) mod limits;
pub(crate) mod pipelines;
pub(crate) mod quirks;
pub(crate) mod requirements;
pub(crate) mod resources;
pub(crate) mod spirv_bindings;
pub(crate) mod teardown;
