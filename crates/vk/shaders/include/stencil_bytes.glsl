// Stencil copied out of the depth-stencil image into a buffer (the 360-like save before a
// restore): one byte per pixel, row-major, four pixels to a uint.
#ifndef STENCIL_BYTES_GLSL
#define STENCIL_BYTES_GLSL

// The byte of pixel `index`, given the word that holds it (`words[index >> 2]`).
uint stencil_byte(uint word, uint index) {
    return (word >> ((index & 3u) * 8u)) & 0xFFu;
}

#endif
