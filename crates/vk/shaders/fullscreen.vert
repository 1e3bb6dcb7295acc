#version 460
// One triangle covering the screen at the far plane's depth (1, or 0 with reversed Z). With the
// depth compare "nearer than far" (GREATER, or LESS reversed) it touches exactly the pixels where
// geometry was drawn.
#include "frame.glsl"

void main() {
    vec2 uv = vec2((gl_VertexIndex << 1) & 2, gl_VertexIndex & 2);
    gl_Position = vec4(uv * 2.0 - 1.0, frame.settings.y, 1.0);
}
