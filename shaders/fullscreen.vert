#version 460
// One triangle covering the screen at depth 1 (the far plane). With depth compare GREATER it
// touches exactly the pixels where geometry was drawn.
void main() {
    vec2 uv = vec2((gl_VertexIndex << 1) & 2, gl_VertexIndex & 2);
    gl_Position = vec4(uv * 2.0 - 1.0, 1.0, 1.0);
}
