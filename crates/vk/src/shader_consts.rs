// Constants shared by the Rust renderer and the GLSL. This file is `include!`d by build.rs, which
// writes them into `generated.glsl`, and compiled into the library: one definition, two readers.

/// GLSL `LIGHT_*` kinds, stored in `Light.color_kind.w`.
pub const LIGHT_KINDS: [(&str, u32); 3] = [
    ("LIGHT_POINT", 0),
    ("LIGHT_SPOT", 1),
    ("LIGHT_DIRECTIONAL", 2),
];

/// GLSL `LIGHT_FALLOFF_*`, stored in `Light.direction.w`: `histencil_scene::Falloff::code` of
/// each convention (a test holds them together). Read by build.rs.
#[allow(dead_code)]
pub const LIGHT_FALLOFFS: [(&str, u32); 3] = [
    ("LIGHT_FALLOFF_SQUARED_WINDOW", 0),
    ("LIGHT_FALLOFF_GLTF", 1),
    ("LIGHT_FALLOFF_INVERSE_SQUARE", 2),
];

/// Side of a hi-stencil tile in pixels (GLSL `HI_STENCIL_TILE`): one flag of the emulated coarse
/// surface covers this many pixels squared, like the 8x8 granularity of console hi-stencil.
pub const HI_STENCIL_TILE: u32 = 8;

/// Tiles per workgroup of the hi-stencil tile update (GLSL `HI_STENCIL_UPDATE_GROUP`): one
/// invocation per tile of the rectangle holding a write's volume. Read by build.rs.
#[allow(dead_code)]
pub const HI_STENCIL_UPDATE_GROUP: u32 = 64;

/// `mode` of the hi-stencil tile update's push constants (GLSL `HI_STENCIL_MODE_*`): what a
/// tile's flag evaluates: the console's compare, AMD's two pretests, or AMD's AND/OR tiles.
pub const HI_STENCIL_MODE_CONSOLE: u32 = 0;
/// See [`HI_STENCIL_MODE_CONSOLE`].
pub const HI_STENCIL_MODE_PRETESTS: u32 = 1;
/// See [`HI_STENCIL_MODE_CONSOLE`].
pub const HI_STENCIL_MODE_AND_OR: u32 = 2;

/// GLSL `HI_STENCIL_MODE_*` (hi_stencil_update.comp). Read by build.rs; the library uses the
/// constants above.
#[allow(dead_code)]
pub const HI_STENCIL_MODES: [(&str, u32); 3] = [
    ("HI_STENCIL_MODE_CONSOLE", HI_STENCIL_MODE_CONSOLE),
    ("HI_STENCIL_MODE_PRETESTS", HI_STENCIL_MODE_PRETESTS),
    ("HI_STENCIL_MODE_AND_OR", HI_STENCIL_MODE_AND_OR),
];

/// BRDF model ids the tiled classification maps to slots (GLSL `TILED_MODELS`): at least
/// `histencil_brdf::MODEL_IDS`, the built-ins' and an engine set's (build.rs checks). Its push
/// constants are then 116 bytes, within the 128 every device has.
pub const TILED_MODELS: u32 = 24;

/// `LightDraw.flags` bit: reject fragments in tiles the active hi-stencil surface marks failing.
pub const LIGHT_DRAW_HI_STENCIL_TEST: u32 = 1;
/// `LightDraw.flags` bit: count shaded fragments into the tile statistics.
pub const LIGHT_DRAW_COUNT: u32 = 2;

/// GLSL `LIGHT_DRAW_*` bits of `LightDraw.flags` (include/light_draw.glsl). Read by build.rs;
/// the library uses the constants above.
#[allow(dead_code)]
pub const LIGHT_DRAW_FLAGS: [(&str, u32); 2] = [
    ("LIGHT_DRAW_HI_STENCIL_TEST", LIGHT_DRAW_HI_STENCIL_TEST),
    ("LIGHT_DRAW_COUNT", LIGHT_DRAW_COUNT),
];

/// GLSL `ALPHA_*` entity kinds, in `AlphaEntity.shape.x` (include/alpha.glsl): how an entity's
/// lightmap texels map to probe positions.
pub const ALPHA_KINDS: [(&str, u32); 4] = [
    ("ALPHA_OBJECT", 0),
    ("ALPHA_SLICES", 1),
    ("ALPHA_DUST", 2),
    ("ALPHA_RIBBON", 3),
];

/// GLSL `ALPHA_MODE_*`: how the alpha pass lights a fragment (an index of its pipelines).
pub const ALPHA_MODES: [(&str, u32); 4] = [
    ("ALPHA_MODE_LIGHTMAP", 0),
    ("ALPHA_MODE_FORWARD", 1),
    ("ALPHA_MODE_PROBE", 2),
    ("ALPHA_MODE_DIRECTIONAL", 3),
];
