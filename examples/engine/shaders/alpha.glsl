// The engine's alpha pass: its camera, and histencil's lightmap records and atlas, bound where
// the engine chooses (set 1). Everything about sampling comes from lightmap_sample.glsl.
#extension GL_GOOGLE_include_directive : require
#include "lightmap_sample.glsl"

layout(set = 0, binding = 0, std140) uniform Camera {
    mat4 view;
    mat4 proj; // reversed Z, infinite far plane
} camera;

// histencil_vk::AlphaLightmaps::entity_buffer: one AlphaEntity per entity, in the engine's order.
layout(set = 1, binding = 0, std430) readonly buffer Entities {
    AlphaEntity entities[];
};
layout(set = 1, binding = 1) uniform texture2D lightmap_atlas;
layout(set = 1, binding = 2) uniform sampler lightmap_linear; // bilinear, clamp to edge

layout(push_constant) uniform Draw {
    mat4 model;
    uint entity;
} draw;
