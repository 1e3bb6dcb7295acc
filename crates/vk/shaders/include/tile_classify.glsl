// The tiled technique's first pass, one workgroup per TILED_TILE x TILED_TILE tile, on the GPU
// with no readback: the set of BRDFs the tile's pixels use (from the decode hook, or straight
// from histencil's G-buffer, which holds both in two texels) and their depth range; each BRDF's list of the tiles that contain it and the count its shade pass
// dispatches (appended atomically: the order of a list does not matter, each pixel is shaded by
// one workgroup); and the lights that can reach the tile, tested against the view-space box
// that holds the tile's pixel footprints between its nearest and farthest surface.
// The body of the stages tile_classify.comp (16x16 tiles) and tile_classify_8.comp (8x8): each defines
// TILED_TILE, the tile side, and includes this.
#ifndef TILE_CLASSIFY_GLSL
#define TILE_CLASSIFY_GLSL
#include "frame.glsl"
#include "surface_decode.glsl"
#include "tiled.glsl"

layout(local_size_x = TILED_TILE, local_size_y = TILED_TILE) in;

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

void main() {
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
        if (tiled.clear != 0u) {
            imageStore(tiled_hdr, px, vec4(0.0));
        }
        uint model;
        float depth;
        if (tile_surface(px, model, depth)) {
            uint slot = model < TILED_MODELS ? tiled.slot_of_model[model] : ~0u;
            if (slot < 32u) {
                atomicOr(tile_brdfs, 1u << slot);
            }
            atomicMin(tile_near, floatBitsToUint(depth));
            atomicMax(tile_far, floatBitsToUint(depth));
        }
    }
    barrier();
    uint brdfs = tile_brdfs;
    bool mixed = (brdfs & (brdfs - 1u)) != 0u; // more than one bit
    if (mixed && tiled.mixed != TILED_PER_BRDF) {
        if (local == 0u) {
            uint i = atomicAdd(dispatch[4u * TILED_MIXED_SLOT], 1u);
            tile_lists[TILED_MIXED_SLOT * tiled.tiles + i] = tile;
        }
    } else if (local < 32u && (brdfs & (1u << local)) != 0u) {
        uint i = atomicAdd(dispatch[4u * local], 1u);
        tile_lists[local * tiled.tiles + i] = tile;
    }
    // The view-space box of the tile's pixel footprints between its nearest and farthest surface.
    vec3 lo = vec3(0.0);
    vec3 hi = vec3(0.0);
    if (brdfs != 0u) {
        float near = uintBitsToFloat(tile_near);
        float far = uintBitsToFloat(tile_far);
        vec2 p0 = vec2(gl_WorkGroupID.xy * TILED_TILE);
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

#endif
