// Constants shared by the Rust renderer and the GLSL. This file is `include!`d by build.rs, which
// writes them into `generated.glsl`, and compiled into the library: one definition, two readers.

/// GLSL `LIGHT_*` kinds, stored in `Light.color_kind.w`.
pub const LIGHT_KINDS: [(&str, u32); 3] = [
    ("LIGHT_POINT", 0),
    ("LIGHT_SPOT", 1),
    ("LIGHT_DIRECTIONAL", 2),
];
