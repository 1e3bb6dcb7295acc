// The G-buffer contract, for the G-buffer pass that feeds histencil's lighting: histencil's own
// (gbuffer.frag) and an engine's, which includes this file and writes its three colour outputs
// through gbuffer_encode. The light shaders read the same layout back (gbuffer.glsl).
//
//   location 0, albedo       R16G16B16A16_SFLOAT  rgb: tint the BRDF's value is multiplied by
//                                                 a:   material index (the LUT technique's
//                                                      table; exact in f16 up to 2048)
//   location 1, normal_depth R32G32B32A32_SFLOAT  xyz: world-space unit normal
//                                                 w:   linear view depth, -z in view space
//                                                      (> 0; 0 where nothing is drawn)
//   location 2, material     R32G32B32A32_SFLOAT  xyz: the BRDF's packed parameters
//                                                      (histencil_brdf::Brdf::packed_params)
//                                                 w:   the BRDF's model id
//                                                      (histencil_brdf::Brdf::model_index)
//
// Clear values: 0 for albedo and normal_depth, (0, 0, 0, -1) for material. The stencil gets the
// draw's BRDF slot in the layout's BRDF field with the culling bit 0, the BRDF bits cleared to 0
// first (LightingDesc::stencil_reference in Rust, histencil_lighting_stencil_reference in C give
// reference and write mask); the depth buffer is the engine's, in the depth convention its view
// names.
//
// Self-contained on purpose: an engine's shader needs nothing else from histencil to write it.
#ifndef GBUFFER_WRITE_GLSL
#define GBUFFER_WRITE_GLSL

struct GBufferTexel {
    vec4 albedo;
    vec4 normal_depth;
    vec4 material;
};

// The three outputs for a surface point; `world_normal` must be unit length (the light shaders
// use it as stored).
GBufferTexel gbuffer_encode(vec3 tint, vec3 world_normal, float linear_depth, vec3 brdf_params,
                            uint brdf_model, uint material_index) {
    GBufferTexel t;
    t.albedo = vec4(tint, float(material_index));
    t.normal_depth = vec4(world_normal, linear_depth);
    t.material = vec4(brdf_params, float(brdf_model));
    return t;
}

#endif
