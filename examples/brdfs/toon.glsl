// A toon ramp: Lambert's cosine quantised into p.x bands (rounded: a G-buffer may store 3 as
// 2.99998), each step a smoothstep p.y of a band wide, albedo p.z. Continuous in N.L (a hard
// step would turn the last bit of a normal into a whole band between two exact renderings of
// the same surface).
#ifndef EXAMPLE_TOON_GLSL
#define EXAMPLE_TOON_GLSL

vec3 toon(vec4 p, vec3 N, vec3 T, vec3 V, vec3 L) {
    float c = dot(N, L);
    if (c <= 0.0) {
        return vec3(0.0);
    }
    float bands = max(floor(p.x + 0.5), 1.0);
    float x = min(c, 1.0) * bands;
    float band = floor(x);
    float edge = 0.5 * p.y;
    float ramp = (band + smoothstep(0.5 - edge, 0.5 + edge, x - band)) / bands;
    return vec3(p.z * INV_PI * ramp);
}

#endif
