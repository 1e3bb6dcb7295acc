// A mesh draw's surface with its material's texture maps applied: the one function the G-buffer
// pass and the forward reference both call, so textures change what is lit, never how exactly a
// technique lights it. Rust side: crates/vk/src/renderer/materials.rs (MaterialRecord), the rules in
// histencil_scene::MaterialMaps and histencil_scene::textured_brdf.
#ifndef MATERIAL_GLSL
#define MATERIAL_GLSL

#include "generated.glsl"
#include "draw.glsl"

// Map slots, in MaterialMaps::refs order.
#define MAP_BASE_COLOR 0
#define MAP_NORMAL 1
#define MAP_METALLIC_ROUGHNESS 2
#define MAP_EMISSIVE 3

layout(set = 1, binding = 0, std140) uniform MaterialMaps {
    // Per map, two rows (a, b, c) of its KHR_texture_transform: u' = a u + b v + c; the first
    // row's w is the texture coordinate set (0 or 1).
    vec4 transform[8];
    // x: 1 where the normal map is read; y: the normal map's scale.
    vec4 normal_map;
    // rgb: the radiance the surface emits, times the emissive map.
    vec4 emissive;
    // x: 1 where fragments are masked (glTF MASK); y: the threshold on texel alpha times vertex
    // alpha (alphaCutoff / baseColorFactor.a).
    vec4 alpha_mask;
} material_maps;
layout(set = 1, binding = 1) uniform texture2D map_base_color;
layout(set = 1, binding = 2) uniform texture2D map_normal;
layout(set = 1, binding = 3) uniform texture2D map_metallic_roughness;
layout(set = 1, binding = 4) uniform texture2D map_emissive;
layout(set = 1, binding = 5) uniform sampler sampler_base_color;
layout(set = 1, binding = 6) uniform sampler sampler_normal;
layout(set = 1, binding = 7) uniform sampler sampler_metallic_roughness;
layout(set = 1, binding = 8) uniform sampler sampler_emissive;

// The map's texture coordinates: its set of `uv` (xy TEXCOORD_0, zw TEXCOORD_1), transformed.
vec2 material_map_uv(int map, vec4 uv) {
    vec4 row0 = material_maps.transform[2 * map];
    vec3 row1 = material_maps.transform[2 * map + 1].xyz;
    vec3 st = vec3(row0.w > 0.5 ? uv.zw : uv.xy, 1.0);
    return vec2(dot(row0.xyz, st), dot(row1, st));
}

// histencil_scene::textured_brdf on packed parameters, in f32: roughness and metal share
// scaled by a metallic-roughness texel. A white texel changes nothing, bit for bit.
vec4 material_textured_params(uint model, vec4 p, float roughness, float metallic) {
    float r = clamp(roughness, 0.0, 1.0);
    float m = clamp(metallic, 0.0, 1.0);
    switch (model) {
    case BRDF_GGX:
        p.x = p.x * r * r;
        p.y = p.y - max(p.y - 0.04, 0.0) * (1.0 - m);
        break;
    case BRDF_BLINN_PHONG:
        if (r < 1.0) {
            float r4 = (r * r) * (r * r);
            float sharpened = r4 > 0.0 ? (p.x + 2.0) / r4 - 2.0 : 1e4;
            p.x = min(max(sharpened, p.x), 1e4);
        }
        break;
    case BRDF_OREN_NAYAR_FULL:
    case BRDF_OREN_NAYAR_QUALITATIVE:
        p.y = p.y * r;
        break;
    case BRDF_GLTF_METAL_ROUGH:
        p.x = p.x * r * r;
        p.y = p.y * m;
        break;
    }
    return p;
}

// The surface at a fragment of the draw: the draw's material, its maps read at `uv`, the vertex
// colour, and the normal map in the frame of `world_tangent` (xyz along +u, w the bitangent's
// sign). A back face (only a double-sided material's is drawn) turns its shading normal toward
// the viewer, as glTF's doubleSided asks: the whole tangent frame flipped, as Khronos's sample
// viewer does.
Surface surface_from_material(vec3 world_position, vec3 world_normal, vec4 uv,
                              vec4 world_tangent, vec4 color, bool front_facing) {
    Surface s = surface_from_draw(world_position, world_normal);
    vec4 base = texture(sampler2D(map_base_color, sampler_base_color),
                        material_map_uv(MAP_BASE_COLOR, uv));
    s.tint *= base.rgb * color.rgb;
    vec4 mr = texture(sampler2D(map_metallic_roughness, sampler_metallic_roughness),
                      material_map_uv(MAP_METALLIC_ROUGHNESS, uv));
    s.params = material_textured_params(s.brdf, s.params, mr.g, mr.b);
    if (material_maps.normal_map.x > 0.5) {
        vec3 n = s.normal;
        // Gram-Schmidt: the interpolated tangent is only nearly perpendicular to N.
        vec3 t = world_tangent.xyz - n * dot(n, world_tangent.xyz);
        float t_len = length(t);
        if (t_len > 1e-20) {
            t /= t_len;
            vec3 b = cross(n, t) * (world_tangent.w < 0.0 ? -1.0 : 1.0);
            vec3 m = texture(sampler2D(map_normal, sampler_normal),
                             material_map_uv(MAP_NORMAL, uv)).xyz * 2.0 - 1.0;
            float scale = material_maps.normal_map.y;
            m *= vec3(scale, scale, 1.0);
            vec3 bent = t * m.x + b * m.y + n * m.z;
            float len = length(bent);
            if (len > 1e-20) {
                s.normal = bent / len;
            }
        }
    }
    if (!front_facing) {
        s.normal = -s.normal;
    }
    return s;
}

// Whether glTF's MASK cuts the fragment at `uv` with vertex colour `color` away: every pass that
// draws the surface (G-buffer, forward, emissive) discards it alike.
bool material_masked(vec4 uv, vec4 color) {
    if (material_maps.alpha_mask.x < 0.5) {
        return false;
    }
    float alpha = texture(sampler2D(map_base_color, sampler_base_color),
                          material_map_uv(MAP_BASE_COLOR, uv)).a * color.a;
    return alpha < material_maps.alpha_mask.y;
}

// The radiance the draw's surface emits at `uv`: added once per pixel, not per light.
vec3 material_emissive(vec4 uv) {
    vec3 map = texture(sampler2D(map_emissive, sampler_emissive),
                       material_map_uv(MAP_EMISSIVE, uv)).rgb;
    return material_maps.emissive.rgb * map;
}

#endif
