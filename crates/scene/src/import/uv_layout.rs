//! What a translucent primitive's `TEXCOORD_0` must be to serve as its lightmap layout: inside
//! `[0, 1]^2`, every triangle with area owning some area of the layout, and no two triangles on
//! the same texels (each texel is one light probe, at one position).

/// Samples per side of the grid overlaps are found on. A lightmap region is at most 4094 texels
/// a side, but an overlap narrower than 1/1024 of the layout covers under a texel at the
/// coverage-chosen sides (8..=128) and cannot light anything wrongly there.
pub const OVERLAP_GRID: u32 = 1024;

/// Why `uvs` cannot be the lightmap layout of the triangles `indices` over `positions`, if
/// they cannot. Triangles without area in 3D are skipped: they draw nothing.
pub fn layout_problem(positions: &[[f32; 3]], indices: &[u32], uvs: &[[f32; 2]]) -> Option<String> {
    if let Some((i, uv)) = uvs
        .iter()
        .enumerate()
        .find(|(_, uv)| !uv.iter().all(|x| (0.0..=1.0).contains(x)))
    {
        return Some(format!(
            "TEXCOORD_0 of vertex {i} is ({}, {}), outside [0, 1]^2 (a lightmap layout must lie \
             inside its region)",
            uv[0], uv[1]
        ));
    }
    let mut grid = Grid::new(OVERLAP_GRID);
    for (t, tri) in indices.chunks_exact(3).enumerate() {
        let tri = [tri[0], tri[1], tri[2]];
        let p = tri.map(|i| glam::Vec3::from(positions[i as usize]));
        if (p[1] - p[0]).cross(p[2] - p[0]).length_squared() == 0.0 {
            continue;
        }
        let uv = tri.map(|i| uvs[i as usize].map(f64::from));
        let area = cross(sub(uv[1], uv[0]), sub(uv[2], uv[0]));
        if area.abs() < 1e-12 {
            return Some(format!(
                "triangle {t} has no area in TEXCOORD_0 (all its texels would be one probe)"
            ));
        }
        // Counter-clockwise, so the fill rule below owns each shared edge once.
        let uv = if area > 0.0 {
            uv
        } else {
            [uv[0], uv[2], uv[1]]
        };
        if let Some((other, at)) = grid.fill(t as u32, uv) {
            return Some(format!(
                "triangles {other} and {t} overlap in TEXCOORD_0 near ({:.4}, {:.4}): a lightmap \
                 layout must give every texel one surface point",
                at[0], at[1]
            ));
        }
    }
    None
}

type P = [f64; 2];

fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1]]
}

fn cross(a: P, b: P) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// Sample centres `(i + 0.5) / n` with the triangle that covers each.
struct Grid {
    n: u32,
    owner: Vec<u32>,
}

const FREE: u32 = u32::MAX;

impl Grid {
    fn new(n: u32) -> Self {
        Self {
            n,
            owner: vec![FREE; (n * n) as usize],
        }
    }

    /// Marks the samples the counter-clockwise triangle `uv` covers as `t`'s, or returns the
    /// first sample another triangle had. A sample on an edge belongs to the triangle for which
    /// that edge is a top-left edge (the rasteriser's rule), so two triangles sharing an edge
    /// never both take it.
    fn fill(&mut self, t: u32, uv: [P; 3]) -> Option<(u32, P)> {
        let n = f64::from(self.n);
        let lo = |k| uv.iter().map(|p| p[k]).fold(f64::INFINITY, f64::min);
        let hi = |k| uv.iter().map(|p| p[k]).fold(f64::NEG_INFINITY, f64::max);
        // Sample indices whose centres lie inside the box (an empty range when none do).
        let first = |x: f64| (x * n - 0.5).ceil().max(0.0) as i64;
        let last = |x: f64| (x * n - 0.5).floor().min(n - 1.0) as i64;
        let edges = [0, 1, 2].map(|k| (uv[k], uv[(k + 1) % 3]));
        for y in first(lo(1))..=last(hi(1)) {
            for x in first(lo(0))..=last(hi(0)) {
                let p = [(x as f64 + 0.5) / n, (y as f64 + 0.5) / n];
                let inside = edges.iter().all(|&(a, b)| {
                    let d = sub(b, a);
                    let e = cross(d, sub(p, a));
                    // The two triangles on an edge round its edge function differently; a
                    // sample that close to the edge is on it, and the fill rule decides.
                    if e.abs() > 1e-12 * (d[0].abs() + d[1].abs()) {
                        e > 0.0
                    } else {
                        d[1] < 0.0 || (d[1] == 0.0 && d[0] > 0.0)
                    }
                });
                if inside {
                    let slot = &mut self.owner[(y * i64::from(self.n) + x) as usize];
                    if *slot != FREE {
                        return Some((*slot, p));
                    }
                    *slot = t;
                }
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `k x k` grid of quads over `[lo, hi]^2`, each split along a diagonal chosen by `seed`:
    /// a valid layout whose shared edges pass through sample centres.
    fn grid_mesh(k: u32, lo: f32, hi: f32, seed: u32) -> (Vec<[f32; 3]>, Vec<u32>, Vec<[f32; 2]>) {
        let (mut positions, mut uvs, mut indices) = (vec![], vec![], vec![]);
        for y in 0..=k {
            for x in 0..=k {
                let (u, v) = (x as f32 / k as f32, y as f32 / k as f32);
                positions.push([u, v, 0.0]);
                uvs.push([lo + (hi - lo) * u, lo + (hi - lo) * v]);
            }
        }
        for y in 0..k {
            for x in 0..k {
                let i = y * (k + 1) + x;
                let (a, b, c, d) = (i, i + 1, i + k + 1, i + k + 2);
                if (x * 7 + y * 13 + seed).is_multiple_of(2) {
                    indices.extend([a, b, d, a, d, c]);
                } else {
                    indices.extend([a, b, c, b, d, c]);
                }
            }
        }
        (positions, indices, uvs)
    }

    #[test]
    fn valid_layouts_pass_whatever_their_grid_and_diagonals() {
        for (k, seed) in [(1, 0), (2, 1), (3, 0), (8, 5), (16, 2), (64, 3)] {
            for (lo, hi) in [(0.0, 1.0), (0.25, 0.75), (0.0, 0.001)] {
                let (p, i, uv) = grid_mesh(k, lo, hi, seed);
                assert_eq!(
                    layout_problem(&p, &i, &uv),
                    None,
                    "k {k} seed {seed} {lo}..{hi}"
                );
            }
        }
    }

    #[test]
    fn every_kind_of_bad_layout_is_named() {
        for (k, seed) in [(1, 0), (2, 1), (5, 3), (16, 0)] {
            let (p, i, uv) = grid_mesh(k, 0.0, 1.0, seed);
            // All one point: the pane that vanished.
            let same = vec![[0.5, 0.5]; uv.len()];
            assert!(layout_problem(&p, &i, &same).unwrap().contains("no area"));
            // Any vertex pushed outside the unit square, by a little or a lot.
            for (v, out) in [(0, -1e-6), (uv.len() / 2, 1.0 + 1e-6), (uv.len() - 1, 1e30)] {
                let mut bad = uv.clone();
                bad[v][1] = out;
                assert!(layout_problem(&p, &i, &bad)
                    .unwrap()
                    .contains("outside [0, 1]^2"));
                let mut nan = uv.clone();
                nan[v][0] = f32::NAN;
                assert!(layout_problem(&p, &i, &nan).unwrap().contains("outside"));
            }
            // The layout drawn twice (a mesh whose halves share texels), or mirrored onto itself.
            let mut doubled = i.clone();
            doubled.extend(i.iter().rev());
            assert!(layout_problem(&p, &doubled, &uv)
                .unwrap()
                .contains("overlap"));
            // One interior vertex moved across its neighbours folds triangles over each other
            // (with k = 2 its neighbourhood is the whole square: anywhere inside is valid).
            if k >= 3 {
                let mut folded = uv.clone();
                let centre = (k / 2 * (k + 1) + k / 2) as usize;
                folded[centre][0] += 1.5 / k as f32;
                assert!(
                    layout_problem(&p, &i, &folded).unwrap().contains("overlap"),
                    "k {k}"
                );
            }
        }
    }

    #[test]
    fn triangles_without_3d_area_are_skipped() {
        let p = [[0.0; 3]; 3];
        assert_eq!(layout_problem(&p, &[0, 1, 2], &[[0.5; 2]; 3]), None);
    }
}
