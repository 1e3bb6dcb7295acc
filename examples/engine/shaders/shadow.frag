#version 460
// Depth only: the shadow map pass writes no colour.
void main() {
}
