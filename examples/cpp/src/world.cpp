#include "world.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

namespace {

struct Vec3 {
    float x, y, z;
};
Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3 cross(Vec3 a, Vec3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
Vec3 normalize(Vec3 v) {
    const float l = std::sqrt(dot(v, v));
    return {v.x / l, v.y / l, v.z / l};
}

// World to view, right-handed, looking down -Z (glam's look_at_rh, which histencil's own
// cameras use).
Mat4 look_at(Vec3 eye, Vec3 target, Vec3 up) {
    const Vec3 f = normalize(target - eye);
    const Vec3 s = normalize(cross(f, up));
    const Vec3 u = cross(s, f);
    return {s.x, u.x, -f.x, 0,  s.y, u.y, -f.y, 0,  s.z, u.z, -f.z, 0,
            -dot(s, eye), -dot(u, eye), dot(f, eye), 1};
}

// View to Vulkan clip space: Y flipped (Vulkan's Y points down), standard depth with the near
// plane at 0 and a finite far plane at 1, clip w = -z (histencil needs that last row).
Mat4 perspective(float fov_y, float aspect, float near, float far) {
    const float f = 1.0f / std::tan(0.5f * fov_y);
    return {f / aspect, 0, 0, 0,  0, -f, 0, 0,  0, 0, far / (near - far), -1,
            0, 0, near * far / (near - far), 0};
}

// Translation, then a turn about Y, then a scale, applied to the unit box.
Mat4 placed(Vec3 centre, float turn, Vec3 size) {
    const float c = std::cos(turn), s = std::sin(turn);
    return {c * size.x, 0, -s * size.x, 0,  0, size.y, 0, 0,  s * size.z, 0, c * size.z, 0,
            centre.x, centre.y, centre.z, 1};
}

std::array<float, 6> world_box(const Mat4 &m) {
    std::array<float, 6> box{1e30f, 1e30f, 1e30f, -1e30f, -1e30f, -1e30f};
    for (int corner = 0; corner < 8; ++corner) {
        const float p[3] = {corner & 1 ? 0.5f : -0.5f, corner & 2 ? 0.5f : -0.5f,
                            corner & 4 ? 0.5f : -0.5f};
        for (int axis = 0; axis < 3; ++axis) {
            const float v = m[axis] * p[0] + m[4 + axis] * p[1] + m[8 + axis] * p[2] + m[12 + axis];
            box[axis] = std::min(box[axis], v);
            box[3 + axis] = std::max(box[3 + axis], v);
        }
    }
    // A hair wider: the bounds decide which lights histencil draws for a BRDF, and a light
    // left out for a surface it reaches would be missing from the frame.
    for (int axis = 0; axis < 3; ++axis) {
        box[axis] -= 1e-3f;
        box[3 + axis] += 1e-3f;
    }
    return box;
}

}  // namespace

Mesh unit_box() {
    Mesh mesh;
    // Each face: its normal axis and sign; the four corners span the other two axes.
    for (int axis = 0; axis < 3; ++axis) {
        for (float sign : {-1.0f, 1.0f}) {
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            const auto first = static_cast<uint16_t>(mesh.vertices.size() / 6);
            const float corners[4][2] = {{-0.5f, -0.5f}, {0.5f, -0.5f}, {0.5f, 0.5f}, {-0.5f, 0.5f}};
            for (const auto &c : corners) {
                float vertex[6] = {};
                vertex[axis] = 0.5f * sign;
                vertex[u] = c[0];
                vertex[v] = c[1];
                vertex[3 + axis] = sign;
                mesh.vertices.insert(mesh.vertices.end(), vertex, vertex + 6);
            }
            for (uint16_t i : {0, 1, 2, 0, 2, 3}) mesh.indices.push_back(first + i);
        }
    }
    return mesh;
}

World::World(uint32_t width, uint32_t height, const HistencilShaders *shaders) {
    // histencil's three and the engine's own (brdfs/brdfs.toml).
    brdf_names = {"lambert", "ggx", "oren_nayar_full", "wrap_diffuse"};
    // Each material's BRDF values, as histencil encodes them for the G-buffer.
    struct Spec {
        uint32_t slot;
        std::vector<HistencilBrdfParam> params;
        std::array<float, 3> tint;
    };
    const Spec specs[] = {
        {0, {{"rho", 0.8}}, {0.75f, 0.75f, 0.75f}},                            // floor
        {2, {{"rho", 0.9}, {"sigma", 0.5}}, {0.625f, 0.75f, 0.875f}},          // wall
        {1, {{"perceptual_roughness", 0.5}, {"f0", 0.5}}, {0.875f, 0.5f, 0.25f}},  // rough metal
        {1, {{"alpha", 0.09}, {"f0", 0.04}}, {0.5f, 0.625f, 0.875f}},          // glossy plastic
        {0, {{"rho", 1.0}}, {0.25f, 0.875f, 0.5f}},                            // white paint
        {2, {{"rho", 0.7}, {"sigma", 1.2}}, {0.875f, 0.875f, 0.5f}},           // clay
        {3, {{"wrap", 0.6}, {"rho", 0.85}}, {0.875f, 0.625f, 0.5f}},           // skin-like wrap
    };
    for (const Spec &spec : specs) {
        Material m{};
        m.brdf_slot = spec.slot;
        const char *name = brdf_names[spec.slot];
        // The engine's set holds histencil's built-ins it keeps and its own.
        if (histencil_brdf_encode(shaders, name, spec.params.data(),
                                  static_cast<uint32_t>(spec.params.size()), m.packed,
                                  &m.model) != HISTENCIL_RESULT_SUCCESS) {
            throw std::runtime_error(std::string("histencil_brdf_encode(") + name +
                                     "): " + histencil_last_error());
        }
        std::copy(spec.tint.begin(), spec.tint.end(), m.tint);
        materials.push_back(m);
    }
    auto add = [this](Vec3 centre, float turn, Vec3 size, uint32_t material) {
        const Mat4 model = placed(centre, turn, size);
        objects.push_back({model, material, world_box(model)});
    };
    add({0, -0.1f, 0}, 0, {10, 0.2f, 10}, 0);        // floor, its top at y = 0
    add({0, 1.5f, -3}, 0, {10, 3, 0.2f}, 1);         // back wall
    add({-1.5f, 0.5f, 0}, 0.5f, {1, 1, 1}, 2);
    add({1.2f, 0.75f, 0.5f}, -0.3f, {0.8f, 1.5f, 0.8f}, 3);
    add({0.2f, 0.3f, 1.8f}, 0.8f, {0.6f, 0.6f, 0.6f}, 4);
    add({-0.3f, 0.4f, -1.6f}, 0.2f, {1.4f, 0.8f, 0.6f}, 5);
    add({-1.6f, 0.45f, 1.9f}, 0.4f, {0.7f, 0.9f, 0.7f}, 6);  // the engine's own BRDF

    const Mat4 world_to_view = look_at({0, 3, 6.5f}, {0, 0.6f, 0}, {0, 1, 0});
    const Mat4 view_to_clip = perspective(1.0f, float(width) / float(height), 0.1f, 50.0f);
    std::copy(world_to_view.begin(), world_to_view.end(), view.world_to_view);
    std::copy(view_to_clip.begin(), view_to_clip.end(), view.view_to_clip);
    view.reversed_depth = 0;
}

std::vector<HistencilLight> World::lights(uint32_t frame) const {
    struct Point {
        Vec3 at;
        float radius;
        Vec3 color;
        uint32_t falloff;
    };
    // Radii from 1.5 to 5: some lights reach one box, some the whole floor.
    const Point points[8] = {
        {{-2.0f, 1.2f, 1.0f}, 3.0f, {6.0f, 4.8f, 3.6f}, HISTENCIL_FALLOFF_SQUARED_WINDOW},
        {{1.8f, 1.0f, 1.5f}, 2.5f, {2.4f, 3.6f, 6.4f}, HISTENCIL_FALLOFF_SQUARED_WINDOW},
        {{0.0f, 2.2f, 0.0f}, 5.0f, {6.0f, 6.0f, 6.0f}, HISTENCIL_FALLOFF_SQUARED_WINDOW},
        {{-0.8f, 0.6f, 2.6f}, 1.5f, {3.6f, 1.6f, 1.6f}, HISTENCIL_FALLOFF_GLTF},
        {{2.5f, 0.5f, -1.5f}, 2.0f, {2.0f, 4.0f, 2.0f}, HISTENCIL_FALLOFF_SQUARED_WINDOW},
        {{-2.8f, 2.0f, -2.0f}, 4.0f, {4.0f, 3.2f, 5.6f}, HISTENCIL_FALLOFF_INVERSE_SQUARE},
        {{0.6f, 0.4f, 0.2f}, 1.8f, {3.2f, 3.2f, 1.2f}, HISTENCIL_FALLOFF_SQUARED_WINDOW},
        {{0.0f, 1.0f, -2.4f}, 2.2f, {1.6f, 2.8f, 4.0f}, HISTENCIL_FALLOFF_SQUARED_WINDOW},
    };
    std::vector<HistencilLight> out;
    for (uint32_t i = 0; i < 8; ++i) {
        const Point &p = points[i];
        const float angle = 0.7f * static_cast<float>(frame) + 1.3f * static_cast<float>(i);
        HistencilLight l{};
        l.kind = HISTENCIL_LIGHT_POINT;
        l.falloff = p.falloff;
        l.position[0] = p.at.x + 0.3f * std::cos(angle);
        l.position[1] = p.at.y;
        l.position[2] = p.at.z + 0.3f * std::sin(angle);
        l.radius = p.radius;
        l.color[0] = p.color.x;
        l.color[1] = p.color.y;
        l.color[2] = p.color.z;
        out.push_back(l);
    }
    // A spot light from above and in front, sweeping a little.
    HistencilLight spot{};
    spot.kind = HISTENCIL_LIGHT_SPOT;
    spot.falloff = HISTENCIL_FALLOFF_SQUARED_WINDOW;
    spot.position[0] = 0.5f * std::sin(0.5f * static_cast<float>(frame));
    spot.position[1] = 4.0f;
    spot.position[2] = 2.0f;
    spot.radius = 7.0f;
    spot.color[0] = 40.0f;
    spot.color[1] = 36.0f;
    spot.color[2] = 30.0f;
    spot.direction[0] = 0.0f;
    spot.direction[1] = -1.0f;
    spot.direction[2] = -0.5f;
    spot.inner_angle = 0.2f;
    spot.outer_angle = 0.45f;
    out.push_back(spot);
    return out;
}

std::vector<std::vector<HistencilBox>> World::brdf_boxes() const {
    std::vector<std::vector<HistencilBox>> out(brdf_names.size());
    for (const Object &o : objects) {
        const auto &b = o.bounds;
        out[materials[o.material].brdf_slot].push_back({{b[0], b[1], b[2]}, {b[3], b[4], b[5]}});
    }
    return out;
}

DrawPush World::push(const Object &object) const {
    const Material &m = materials[object.material];
    DrawPush p{};
    std::memcpy(p.model, object.model.data(), sizeof p.model);
    p.tint_material[0] = m.tint[0];
    p.tint_material[1] = m.tint[1];
    p.tint_material[2] = m.tint[2];
    p.tint_material[3] = static_cast<float>(object.material);
    std::memcpy(p.brdf, m.packed, 3 * sizeof(float));
    p.brdf[3] = static_cast<float>(m.model);
    return p;
}
