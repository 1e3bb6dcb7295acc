// BRDF look-up tables on the GPU: the GLSL spelling of histencil_brdf::lut (axes, coordinates and
// the multilinear lookup of `Lut::lookup`, operation for operation in f32). Rust side of the
// buffers: crates/vk/src/lighting/lut.rs (GpuLutTable).
//
// Tables live in storage buffers and are interpolated here rather than by texture filtering:
// the lookup is then the one the accuracy report measured, on every device (hardware filtering
// quantises its weights, to 8 bits on many GPUs), and 3D tables of any resolution need no
// format or size checks beyond the buffer's.
//
// The includer defines LUT_SET and LUT_BINDING: the headers are at LUT_BINDING, the values at
// LUT_BINDING + 1.
#ifndef LUT_GLSL
#define LUT_GLSL

#include "brdf/common.glsl"

struct LutTable {
    uint axes;       // LUT_AXES_*
    uint resolution; // grid points per axis
    uint offset;     // first float of the table in lut_values
    float curvature; // the skin table's lookup curvature (1/mm); 0 otherwise
    uint channels;   // floats per grid point: 3 (tinted RGB), or 4 with the white part after it
};

layout(set = LUT_SET, binding = LUT_BINDING, std430) readonly buffer LutTables {
    LutTable lut_tables[];
};

// Per grid point, first axis fastest: the tinted factor (RGB f32), then the white one (f32)
// where the table has a white part (channels 4): f * N.L = tint * tinted + white.
layout(set = LUT_SET, binding = LUT_BINDING + 1, std430) readonly buffer LutValues {
    float lut_values[];
};

// atan2(|a x b|, a . b): accurate near 0 and pi (histencil_brdf::vector::angle_between).
float lut_angle_between(vec3 a, vec3 b) {
    vec3 x = cross(a, b);
    return atan(sqrt(dot(x, x)), dot(a, b));
}

uint lut_dimensions(uint axes) {
    switch (axes) {
    case LUT_AXES_COS_LIGHT:
        return 1u;
    case LUT_AXES_ISOTROPIC:
        return 3u;
    }
    return 2u;
}

// The table coordinates of a shading point (LutAxes::coordinates); false where the model gives 0
// without a lookup.
bool lut_coordinates(LutTable table, vec3 N, vec3 T, vec3 V, vec3 L, out vec3 u) {
    u = vec3(0.0);
    vec3 n, t, v, l;
    switch (table.axes) {
    case LUT_AXES_COS_LIGHT: {
        if (!brdf_normalize(N, n) || !brdf_normalize(L, l)) {
            return false;
        }
        float c = min(dot(n, l), 1.0);
        u.x = c;
        return c > 0.0;
    }
    case LUT_AXES_ISOTROPIC: {
        if (!brdf_normalize(N, n) || !brdf_normalize(V, v) || !brdf_normalize(L, l)) {
            return false;
        }
        float n_dot_v;
        if (dot(n, l) <= 0.0 || !brdf_above_horizon(n, v, n_dot_v)) {
            return false;
        }
        vec3 lp, vp;
        // Along the normal the azimuth is undefined and the BRDF does not depend on it.
        float phi = 0.0;
        if (brdf_normalize(l - n * dot(n, l), lp) && brdf_normalize(v - n * dot(n, v), vp)) {
            phi = lut_angle_between(lp, vp);
        }
        u = vec3(lut_angle_between(n, l) / (0.5 * PI), lut_angle_between(n, v) / (0.5 * PI), phi / PI);
        return true;
    }
    case LUT_AXES_FIBRE: {
        if (!brdf_normalize(T, t) || !brdf_normalize(V, v) || !brdf_normalize(L, l)) {
            return false;
        }
        u.xy = vec2(lut_angle_between(t, l), lut_angle_between(t, v)) / PI;
        return true;
    }
    case LUT_AXES_SKIN_CURVATURE: {
        if (!brdf_normalize(N, n) || !brdf_normalize(L, l)) {
            return false;
        }
        float k = max(table.curvature, 0.0);
        u.xy = vec2(lut_angle_between(n, l) / PI, k / (k + 1.0));
        return true;
    }
    }
    return false;
}

// Grid point `point` of `table`: the tinted factor in rgb, the white one in a (0 without one).
vec4 lut_value(LutTable table, uint point) {
    uint at = table.offset + table.channels * point;
    float white = table.channels == 4u ? lut_values[at + 3u] : 0.0;
    return vec4(lut_values[at], lut_values[at + 1u], lut_values[at + 2u], white);
}

// The two factors of `f_r * cos(theta_L)` of table `index` at a shading point, interpolated
// between grid points: the tinted one in rgb, the white one in a (histencil_brdf::Lut::lookup).
// A surface of colour `tint` takes tint * f.rgb + f.a.
vec4 lut_lookup(uint index, vec3 N, vec3 T, vec3 V, vec3 L) {
    // A decode hook's table index past the tables (a material index with fewer tables than
    // materials) reads no header past the buffer's end.
    if (index >= uint(lut_tables.length())) {
        return vec4(0.0);
    }
    LutTable table = lut_tables[index];
    vec3 u;
    if (!lut_coordinates(table, N, T, V, L, u)) {
        return vec4(0.0);
    }
    uint dims = lut_dimensions(table.axes);
    uint r = table.resolution;
    float last = float(r - 1u);
    // Per axis: the lower grid index and the weight of the upper one.
    uvec3 base = uvec3(0u);
    vec3 frac = vec3(0.0);
    for (uint a = 0u; a < dims; a++) {
        float x = clamp(u[a], 0.0, 1.0) * last;
        uint i = min(uint(floor(x)), r - 2u);
        base[a] = i;
        frac[a] = x - float(i);
    }
    vec4 result = vec4(0.0);
    for (uint corner = 0u; corner < (1u << dims); corner++) {
        float weight = 1.0;
        uint offset = 0u;
        uint stride = 1u;
        for (uint a = 0u; a < dims; a++) {
            uint upper = (corner >> a) & 1u;
            weight *= upper == 1u ? frac[a] : 1.0 - frac[a];
            offset += (base[a] + upper) * stride;
            stride *= r;
        }
        result += weight * lut_value(table, offset);
    }
    return result;
}

#endif
