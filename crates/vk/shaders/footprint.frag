#version 460
// Writes the depth of the light-volume face being rasterised: the GPU's own footprint of a light
// for the CPU simulator (crates/vk/src/renderer/capture.rs). Clamped to [0, 1] as the depth test sees it
// with depth clamp on.
layout(location = 0) out float out_depth;

void main() {
    out_depth = clamp(gl_FragCoord.z, 0.0, 1.0);
}
