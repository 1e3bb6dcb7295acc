// An alpha entity's lightmap record, as histencil writes it (one per entity, in the order the
// entities were given to histencil_vk::AlphaLightmaps): which texels of the lightmap atlas hold
// its light and how its probes sit in them. An engine binds AlphaLightmaps::entity_buffer as a
// std430 array of these and samples the atlas through lightmap_sample.glsl.
// Rust mirror: histencil_vk::AlphaEntityRecord.
//
// Self-contained on purpose: an engine's alpha shader needs nothing else from histencil.
#ifndef ALPHA_ENTITY_GLSL
#define ALPHA_ENTITY_GLSL

// AlphaEntity.shape.x: how the entity's texels map to probe positions
// (histencil_vk's ALPHA_KINDS; a unit test holds the two together).
#define ALPHA_OBJECT 0u
#define ALPHA_SLICES 1u
#define ALPHA_DUST 2u
#define ALPHA_RIBBON 3u

struct AlphaEntity {
    mat4 model;           // object -> world (identity for particle systems)
    vec4 tint_opacity;    // rgb tint, w opacity
    vec4 params;          // xyz the BRDF's packed parameters, w BRDF id
    uvec4 region;         // xy: the region's first texel in the atlas; zw: one tile's size
    uvec4 shape;          // x: ALPHA_* kind, y: tiles (slices), z: first point or probe
                          // (ALPHA_SLICES: tiles to a row), w: point count
    vec4 centre_radius;   // xyz: probe frame centre (the single probe's point), w: its radius
    vec4 right_depth;     // xyz: unit right, w: half depth of the slice stack
    vec4 up;              // xyz: unit up
    vec4 forward;         // xyz: unit view direction
    uvec4 light_range;    // x: first index into the entity light list, y: count
};

// Tiles to a row of the entity's region: tile k sits at (k % columns, k / columns).
uint tile_columns(AlphaEntity e) {
    return e.shape.x == ALPHA_SLICES ? max(e.shape.z, 1u) : 1u;
}

#endif
