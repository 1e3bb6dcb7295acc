// The engine's world: a floor, a back wall and four boxes of three histencil BRDFs (Lambert,
// GGX, Oren-Nayar), a perspective camera with standard depth, eight point lights of varying
// radius and a spot light, moving a little from frame to frame.
#pragma once

#include <histencil.h>

#include <array>
#include <cstdint>
#include <vector>

using Mat4 = std::array<float, 16>;  // column-major, as GLSL and HistencilView hold matrices

// A unit box centred on the origin, a face at a time (each face its own normal): 24 vertices
// of position and normal, 36 indices.
struct Mesh {
    std::vector<float> vertices;  // x, y, z, nx, ny, nz
    std::vector<uint16_t> indices;
};
Mesh unit_box();

// What the engine pushes per draw; scene.vert, gbuffer.frag and forward.frag declare it alike.
struct DrawPush {
    float model[16];
    float tint_material[4];  // rgb tint, w material index
    float brdf[4];           // xyz packed BRDF parameters, w BRDF model id
};

// A surface kind: its BRDF (by histencil's name, and its slot in the lighting) with the values
// histencil_brdf_encode gave for its parameters, and a tint.
struct Material {
    uint32_t brdf_slot;
    float packed[4];
    uint32_t model;
    float tint[3];  // exact in f16, as the G-buffer's albedo stores it
};

struct Object {
    Mat4 model;
    uint32_t material;
    std::array<float, 6> bounds;  // the world box around it: min xyz, max xyz
};

struct World {
    // Seen on a `width` x `height` target, its materials encoded for histencil's shaders of
    // the engine's BRDF set (`shaders`, which hold its own `wrap_diffuse`). Throws with
    // histencil_last_error() when histencil refuses a BRDF's parameters.
    World(uint32_t width, uint32_t height, const HistencilShaders *shaders);

    // The lighting's BRDFs, one stencil slot each, in this order.
    std::vector<const char *> brdf_names;
    std::vector<Material> materials;
    std::vector<Object> objects;
    HistencilView view{};

    // The lights of frame `frame`: they drift along small circles, so each frame differs.
    std::vector<HistencilLight> lights(uint32_t frame) const;
    // Per BRDF slot, the boxes of the objects drawn with it.
    std::vector<std::vector<HistencilBox>> brdf_boxes() const;
    DrawPush push(const Object &object) const;
};

constexpr uint32_t kLights = 9;
