//! Each timed pass's one name, spelled once: the pass's debug label, its timestamp in
//! [`crate::FrameTimings`], the technique's list of passes ([`crate::Shading::lighting_passes`])
//! and every reader in the lab and the command line take it from here. Two spellings of one
//! pass had drifted apart (the tiled classification was timed `tile-classify` and labelled
//! `tiled-classify`).

/// The G-buffer pass.
pub const GBUFFER: &str = "gbuffer";
/// The deferred lighting, whatever its technique (after the tiled classification and light
/// lists, for the techniques that have them).
pub const LIGHTING: &str = "lighting";
/// The forward reference: every light at every pixel.
pub const FORWARD: &str = "forward";
/// The tiled techniques' classification of each tile's depth range and BRDFs.
pub const TILE_CLASSIFY: &str = "tile-classify";
/// The tiled techniques' light lists: each light's bit in the tiles it reaches.
pub const TILE_LIGHTS: &str = "tile-lights";
/// The alpha entities' lightmaps (with their direction maps, where asked for).
pub const ALPHA_LIGHTMAPS: &str = "alpha-lightmaps";
/// The alpha entities, drawn over the lit frame.
pub const ALPHA: &str = "alpha";
/// The tonemap to the 8-bit image.
pub const TONEMAP: &str = "tonemap";
