#version 460
// HDR -> display: exposure, per-channel Reinhard, sRGB encoding (done here so the result does not
// depend on a driver's sRGB conversion).
#include "frame.glsl"

#extension GL_EXT_samplerless_texture_functions : require

layout(set = 1, binding = 0) uniform texture2D hdr;

layout(location = 0) out vec4 out_color;

vec3 srgb_encode(vec3 linear) {
    vec3 lo = linear * 12.92;
    vec3 hi = 1.055 * pow(linear, vec3(1.0 / 2.4)) - 0.055;
    return mix(hi, lo, lessThanEqual(linear, vec3(0.0031308)));
}

void main() {
    vec3 c = texelFetch(hdr, ivec2(gl_FragCoord.xy), 0).rgb;
    // Light beyond the f16 target saturates it to +inf (and +inf blended "over" by an opaque
    // alpha entity is NaN): both are the brightest value there is, so they tonemap to white
    // rather than to the 0 that an unorm conversion makes of NaN.
    c = mix(min(c, vec3(65504.0)), vec3(65504.0), isnan(c));
    c = max(c * frame.settings.x, vec3(0.0));
    out_color = vec4(srgb_encode(c / (1.0 + c)), 1.0);
}
