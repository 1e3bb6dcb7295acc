// The tiled technique's first pass, one workgroup per TILED_TILE x TILED_TILE tile, on the GPU
// with no readback: the set of BRDFs the tile's pixels use (from the decode hook, or straight
// from histencil's G-buffer, which holds both in two texels) and their depth range; each BRDF's list of the tiles that contain it and the count its shade pass
// dispatches (appended atomically: the order of a list does not matter, each pixel is shaded by
// one workgroup); and the lights that can reach the tile, tested against the view-space box
// that holds the tile's pixel footprints between its nearest and farthest surface.
// Two shapes of the same work, by specialisation (PER_INVOCATION, `TileClassify` in tiled.rs),
// with the same results bit for bit: a workgroup per tile whose invocations each read a pixel
// and combine in shared memory (GPUs), or an invocation per tile that reads its tile's pixels
// in a loop, TILED_TILE x TILED_TILE tiles per workgroup (CPU rasterisers such as llvmpipe,
// which run a workgroup with barriers one invocation at a time, switching at each barrier).
// The body of the stages tile_classify.comp (16x16 tiles) and tile_classify_8.comp (8x8): each defines
// TILED_TILE, the tile side, and includes this.
#ifndef TILE_CLASSIFY_GLSL
#define TILE_CLASSIFY_GLSL
#include "frame.glsl"
#include "surface_decode.glsl"
#include "tiled.glsl"

layout(local_size_x = TILED_TILE, local_size_y = TILED_TILE) in;

// True: an invocation per tile (`classify_alone`); false: a workgroup per tile.
layout(constant_id = 0) const bool PER_INVOCATION = false;

shared uint tile_brdfs;
// The light mask of one chunk of CHUNK_WORDS * 32 lights, ORed together by every invocation.
const uint CHUNK_WORDS = 64u;
shared uint chunk_mask[CHUNK_WORDS];
// Linear depths as float bits: positive floats order as their bits do.
shared uint tile_near;
shared uint tile_far;

const uint INVOCATIONS = TILED_TILE * TILED_TILE;

// The view-space position at linear depth `d` on the ray through framebuffer point `p`.
vec3 view_point(vec2 p, float d) {
    vec2 ndc = p * frame.viewport.zw * 2.0 - 1.0;
    return vec3((ndc + frame.projection.zw) * frame.projection.xy, -1.0) * d;
}

// The BRDF model id and linear depth of the surface under pixel `px`; false where none.
bool tile_surface(ivec2 px, out uint model, out float depth) {
#ifdef HISTENCIL_BUILTIN_DECODE
    depth = texelFetch(gbuffer_normal_depth, px, 0).w;
    model = uint(texelFetch(gbuffer_material, px, 0).w);
    return depth > 0.0;
#else
    Surface s;
    if (!decode_surface(vec2(px) + 0.5, s)) {
        return false;
    }
    model = s.brdf;
    depth = max(-(frame.view * vec4(s.position, 1.0)).z, 0.0);
    return true;
#endif
}

// Pixel `px`'s part in its tile's class: false where it has no surface; else its BRDF slot's
// bit (0 for a BRDF the frame does not light) and the bits of its linear depth (positive floats
// order as their bits do). Clears the pixel when asked, where no shade kernel will write it
// (a kernel writes each pixel of a BRDF in the frame once, without reading it, when clearing).
bool pixel_class(ivec2 px, out uint bit, out uint depth_bits) {
    uint model;
    float depth;
    bit = 0u;
    bool surface = tile_surface(px, model, depth);
    if (surface) {
        uint slot = model < TILED_MODELS ? tiled.slot_of_model[model] : ~0u;
        bit = slot < 32u ? 1u << slot : 0u;
        depth_bits = floatBitsToUint(depth);
    }
    if (tiled.clear != 0u && bit == 0u) {
        imageStore(tiled_hdr, px, vec4(0.0));
    }
    return surface;
}

// Whether `light` can light anything in the view-space box [lo, hi]: directional lights reach
// everything; point and spot lights are zero beyond their range sphere.
bool reaches(Light light, vec3 lo, vec3 hi) {
    if (uint(light.color_kind.w) == LIGHT_DIRECTIONAL) {
        return true;
    }
    vec3 centre = (frame.view * vec4(light.position_radius.xyz, 1.0)).xyz;
    vec3 nearest = clamp(centre, lo, hi);
    vec3 d = centre - nearest;
    // A margin against rounding: a light that misses by less is kept (it adds zero).
    float r = light.position_radius.w * (1.0 + 1e-4) + 1e-4;
    return dot(d, d) <= r * r;
}

// The view-space box of the pixel footprints of tile `t` between linear depths `near_bits` and
// `far_bits` (float bits).
void tile_box(uvec2 t, uint near_bits, uint far_bits, out vec3 lo, out vec3 hi) {
    float near = uintBitsToFloat(near_bits);
    float far = uintBitsToFloat(far_bits);
    vec2 p0 = vec2(t * TILED_TILE);
    vec2 p1 = min(p0 + vec2(TILED_TILE), frame.viewport.xy);
    lo = vec3(3.0e38);
    hi = vec3(-3.0e38);
    for (uint c = 0u; c < 8u; ++c) {
        vec2 p = vec2((c & 1u) != 0u ? p1.x : p0.x, (c & 2u) != 0u ? p1.y : p0.y);
        vec3 v = view_point(p, (c & 4u) != 0u ? far : near);
        lo = min(lo, v);
        hi = max(hi, v);
    }
}

// Appends `tile` to the list of each BRDF in `brdfs`, or to the mixed tiles' list when it has
// several and those are shaded once, branching.
void list_tile(uint tile, uint brdfs) {
    bool mixed = (brdfs & (brdfs - 1u)) != 0u; // more than one bit
    if (mixed && tiled.mixed != TILED_PER_BRDF) {
        uint i = atomicAdd(dispatch[4u * TILED_MIXED_SLOT], 1u);
        tile_lists[TILED_MIXED_SLOT * tiled.tiles + i] = tile;
        return;
    }
    while (brdfs != 0u) {
        uint slot = uint(findLSB(brdfs));
        brdfs &= brdfs - 1u;
        uint i = atomicAdd(dispatch[4u * slot], 1u);
        tile_lists[slot * tiled.tiles + i] = tile;
    }
}

// An invocation per tile: it reads the tile's pixels itself, in a loop, and tests every light.
// Depths are compared as float bits, as the workgroup's atomics do, so both give the same box.
void classify_alone() {
    uvec2 t = gl_GlobalInvocationID.xy;
    if (t.x >= tiled.tiles_x || t.y * tiled.tiles_x >= tiled.tiles) {
        return;
    }
    uint tile = t.y * tiled.tiles_x + t.x;
    ivec2 p0 = ivec2(t * TILED_TILE);
    ivec2 p1 = min(p0 + ivec2(TILED_TILE), ivec2(frame.viewport.xy));
    uint brdfs = 0u;
    uint near_bits = floatBitsToUint(3.0e38);
    uint far_bits = 0u;
    for (int y = p0.y; y < p1.y; ++y) {
        for (int x = p0.x; x < p1.x; ++x) {
            uint bit;
            uint depth;
            if (pixel_class(ivec2(x, y), bit, depth)) {
                brdfs |= bit;
                near_bits = min(near_bits, depth);
                far_bits = max(far_bits, depth);
            }
        }
    }
    list_tile(tile, brdfs);
    vec3 lo = vec3(0.0);
    vec3 hi = vec3(0.0);
    if (brdfs != 0u) {
        tile_box(t, near_bits, far_bits, lo, hi);
    }
    uint count = frame.counts.x;
    for (uint w = 0u; w < tiled.words; ++w) {
        uint mask = 0u;
        if (brdfs != 0u) {
            uint end = min(count, (w + 1u) * 32u);
            for (uint l = w * 32u; l < end; ++l) {
                if (reaches(lights[l], lo, hi)) {
                    mask |= 1u << (l % 32u);
                }
            }
        }
        tile_lights[tile * tiled.words + w] = mask;
    }
}

// A workgroup per tile: each invocation reads one pixel.
void classify_together() {
    uint local = gl_LocalInvocationIndex;
    uint tile = gl_WorkGroupID.y * tiled.tiles_x + gl_WorkGroupID.x;
    if (local == 0u) {
        tile_brdfs = 0u;
        tile_near = floatBitsToUint(3.0e38);
        tile_far = 0u;
    }
    barrier();
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(frame.viewport.xy);
    if (all(lessThan(px, size))) {
        uint bit;
        uint depth;
        if (pixel_class(px, bit, depth)) {
            if (bit != 0u) {
                atomicOr(tile_brdfs, bit);
            }
            atomicMin(tile_near, depth);
            atomicMax(tile_far, depth);
        }
    }
    barrier();
    uint brdfs = tile_brdfs;
    if (local == 0u) {
        list_tile(tile, brdfs);
    }
    // The view-space box of the tile's pixel footprints between its nearest and farthest surface.
    vec3 lo = vec3(0.0);
    vec3 hi = vec3(0.0);
    if (brdfs != 0u) {
        tile_box(gl_WorkGroupID.xy, tile_near, tile_far, lo, hi);
    }
    // The light mask, a chunk of lights at a time: every invocation tests its share of the
    // chunk's lights and ORs its bits in (OR is order-free, so the mask is the same whatever the
    // order), then the chunk's words are written out.
    uint count = frame.counts.x;
    for (uint first = 0u; first < tiled.words; first += CHUNK_WORDS) {
        if (local < CHUNK_WORDS) {
            chunk_mask[local] = 0u;
        }
        barrier();
        if (brdfs != 0u) {
            uint end = min(count, (first + CHUNK_WORDS) * 32u);
            for (uint l = first * 32u + local; l < end; l += INVOCATIONS) {
                if (reaches(lights[l], lo, hi)) {
                    atomicOr(chunk_mask[l / 32u - first], 1u << (l % 32u));
                }
            }
        }
        barrier();
        if (local < CHUNK_WORDS && first + local < tiled.words) {
            tile_lights[tile * tiled.words + first + local] = chunk_mask[local];
        }
        barrier();
    }
}

void main() {
    // Branches on the constant itself (`!PER_INVOCATION` would be an OpSpecConstantOp, which
    // naga cannot read); the barriers of the workgroup shape stay in uniform control flow.
    if (PER_INVOCATION) {
        classify_alone();
    } else {
        classify_together();
    }
}

#endif
