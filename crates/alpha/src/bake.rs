//! A translucent mesh's light probes: one object-space position and normal per texel of its
//! lightmap region, found by rasterising the mesh in its UV layout on the CPU.
//!
//! The probes are what the GPU bake used to draw (the mesh's UV layout as the viewport), with the
//! rules a Vulkan rasteriser follows, so a texel holds a probe exactly where a GPU would have
//! written one: sample points at texel centres, vertex positions snapped to 1/256 of a texel
//! (8 sub-pixel bits, what lavapipe and desktop GPUs use), the top-left rule on shared edges,
//! and a later triangle over an earlier one. Being plain data, an engine's mesh is baked without
//! a pass of its own and the result is testable without a GPU.

use bytemuck::{Pod, Zeroable};
use histencil_scene::Mesh;

/// One texel's probe: `position.w` is 1 where the mesh covers the texel, 0 where nothing does;
/// `normal` is the interpolated (unnormalised) object-space normal, `w` 0.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Probe {
    /// Object-space position where the mesh covers the texel; `w` says whether it does.
    pub position: [f32; 4],
    /// Object-space normal there, unnormalised; `w` 0.
    pub normal: [f32; 4],
}

/// A `width x height` grid of probes, row by row from the region's top-left texel.
#[derive(Clone, Debug, PartialEq)]
pub struct BakedProbes {
    /// Texels across: the region's width.
    pub width: u32,
    /// Texels down: the region's height.
    pub height: u32,
    /// `width * height` probes, uploaded into the entity's region as they are.
    pub probes: Vec<Probe>,
}

/// Sub-texel precision of the snapped vertex positions.
const SUBPIXEL_BITS: u32 = 8;

/// Rasterises `mesh` at `uv * (width, height)` into a `width x height` grid of probes. Triangles
/// whose vertices are not finite, or that have no area, cover nothing.
pub fn bake_probes(mesh: &Mesh, width: u32, height: u32) -> BakedProbes {
    let mut probes = vec![Probe::default(); width as usize * height as usize];
    let scale = f64::from(1u32 << SUBPIXEL_BITS);
    for t in mesh.indices.chunks_exact(3) {
        let Some(v) = t
            .iter()
            .map(|&i| mesh.vertices.get(i as usize))
            .collect::<Option<Vec<_>>>()
        else {
            continue;
        };
        let snapped: Vec<(i64, i64)> = v
            .iter()
            .map(|v| {
                let x = f64::from(v.uv[0]) * f64::from(width) * scale;
                let y = f64::from(v.uv[1]) * f64::from(height) * scale;
                (x.round() as i64, y.round() as i64)
            })
            .collect();
        let finite = v.iter().all(|v| {
            v.uv.iter()
                .chain(&v.position)
                .chain(&v.normal)
                .all(|c| c.is_finite() && c.abs() < 1e6)
        });
        if !finite {
            continue;
        }
        let mut p = [snapped[0], snapped[1], snapped[2]];
        let mut attributes = [v[0], v[1], v[2]];
        let area = edge(p[0], p[1], p[2]);
        if area == 0 {
            continue;
        }
        if area < 0 {
            p.swap(1, 2);
            attributes.swap(1, 2);
        }
        let area = edge(p[0], p[1], p[2]) as f64;
        let one = 1i64 << SUBPIXEL_BITS;
        let half = one / 2;
        // Texels whose centres can lie inside the triangle's box.
        let lo = |c: i64| ((c - half).div_euclid(one) + 1).max(0);
        let hi = |c: i64, n: u32| ((c - half).div_euclid(one)).min(i64::from(n) - 1);
        let (x0, x1) = (
            lo(p.iter().map(|q| q.0).min().unwrap()),
            hi(p.iter().map(|q| q.0).max().unwrap(), width),
        );
        let (y0, y1) = (
            lo(p.iter().map(|q| q.1).min().unwrap()),
            hi(p.iter().map(|q| q.1).max().unwrap(), height),
        );
        for ty in y0..=y1 {
            for tx in x0..=x1 {
                let s = (tx * one + half, ty * one + half);
                let w = [
                    edge(p[1], p[2], s),
                    edge(p[2], p[0], s),
                    edge(p[0], p[1], s),
                ];
                let starts = [p[1], p[2], p[0]];
                let ends = [p[2], p[0], p[1]];
                let inside =
                    (0..3).all(|e| w[e] > 0 || (w[e] == 0 && top_left(starts[e], ends[e])));
                if !inside {
                    continue;
                }
                let b = w.map(|w| w as f64 / area);
                let mix = |f: &dyn Fn(usize) -> [f32; 3]| {
                    let (a, bb, c) = (f(0), f(1), f(2));
                    [0, 1, 2].map(|k| {
                        (b[0] * f64::from(a[k]) + b[1] * f64::from(bb[k]) + b[2] * f64::from(c[k]))
                            as f32
                    })
                };
                let position = mix(&|i| attributes[i].position);
                let normal = mix(&|i| attributes[i].normal);
                probes[(ty as usize) * width as usize + tx as usize] = Probe {
                    position: [position[0], position[1], position[2], 1.0],
                    normal: [normal[0], normal[1], normal[2], 0.0],
                };
            }
        }
    }
    BakedProbes {
        width,
        height,
        probes,
    }
}

/// Twice the signed area of `(a, b, p)`: positive when `p` is on the inner side of `a -> b` for a
/// triangle wound with positive area (y down).
fn edge(a: (i64, i64), b: (i64, i64), p: (i64, i64)) -> i64 {
    (b.0 - a.0) * (p.1 - a.1) - (b.1 - a.1) * (p.0 - a.0)
}

/// Vulkan's top-left rule for an edge of a positively wound triangle (y down): a sample on the
/// edge is inside when the edge is a top edge (horizontal, running right) or a left edge
/// (running up).
fn top_left(a: (i64, i64), b: (i64, i64)) -> bool {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    dy < 0 || (dy == 0 && dx > 0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use histencil_scene::{unit_box_bake, uv_sphere, Vertex};

    fn covered(b: &BakedProbes) -> usize {
        b.probes.iter().filter(|p| p.position[3] == 1.0).count()
    }

    #[test]
    fn the_box_bake_covers_every_texel_on_its_faces_planes() {
        for side in [8, 16, 32, 128] {
            let baked = bake_probes(&unit_box_bake(), side, side);
            assert_eq!(covered(&baked), (side * side) as usize, "{side}");
            for p in &baked.probes {
                // Every probe lies on one face's plane: the coordinate along its normal is +-1.
                let n = p.normal;
                let axis = (0..3).find(|&k| n[k] != 0.0).unwrap();
                assert_eq!(p.position[axis].abs(), 1.0, "{p:?}");
                assert_eq!(n[axis].abs(), 1.0);
            }
        }
    }

    #[test]
    fn sphere_probes_lie_on_the_sphere() {
        let baked = bake_probes(&uv_sphere(48, 24), 32, 32);
        assert!(covered(&baked) >= 32 * 32 * 9 / 10, "{}", covered(&baked));
        for p in baked.probes.iter().filter(|p| p.position[3] == 1.0) {
            let r = glam::Vec3::from_slice(&p.position[..3]).length();
            assert!((0.99..=1.0001).contains(&r), "{r}");
        }
    }

    /// Two triangles sharing a diagonal through texel centres: each centre is covered once, by
    /// the top-left rule, so the pair covers exactly the texels of the square.
    #[test]
    fn shared_edges_cover_each_texel_once() {
        let v = |x: f32, y: f32| Vertex::new([x, y, 0.0], [0.0, 0.0, 1.0], [x, y]);
        let mesh = Mesh {
            vertices: vec![v(0.0, 0.0), v(1.0, 0.0), v(1.0, 1.0), v(0.0, 1.0)],
            indices: vec![0, 1, 2, 0, 2, 3],
        };
        // Diagonal x = y passes through every (i + 0.5, i + 0.5) centre.
        let one = bake_probes(
            &Mesh {
                indices: vec![0, 1, 2],
                ..mesh.clone()
            },
            8,
            8,
        );
        let other = bake_probes(
            &Mesh {
                indices: vec![0, 2, 3],
                ..mesh.clone()
            },
            8,
            8,
        );
        assert_eq!(covered(&one) + covered(&other), 64);
        assert_eq!(covered(&bake_probes(&mesh, 8, 8)), 64);
        // Interpolation: the probe at texel (i, j) is at its centre in uv.
        let all = bake_probes(&mesh, 8, 8);
        let p = all.probes[3 * 8 + 5].position;
        assert_eq!(p, [5.5 / 8.0, 3.5 / 8.0, 0.0, 1.0]);
    }

    #[test]
    fn broken_triangles_cover_nothing() {
        let v = |u: f32| Vertex::new([u, 0.0, 0.0], [0.0, 0.0, 1.0], [u, u]);
        let degenerate = Mesh {
            vertices: vec![v(0.0), v(0.5), v(1.0), v(f32::NAN)],
            indices: vec![0, 1, 2, 0, 1, 3, 0, 1, 99],
        };
        assert_eq!(covered(&bake_probes(&degenerate, 16, 16)), 0);
        assert_eq!(bake_probes(&degenerate, 0, 0).probes.len(), 0);
    }
}
