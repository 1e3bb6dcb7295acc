//! Procedural meshes: object shapes and light volumes. Triangles wind counter-clockwise seen from
//! outside; light volumes *circumscribe* the region they bound, so rasterising them never misses a
//! lit pixel (the light shader's falloff is exactly zero outside the true region).

use std::f32::consts::{PI, TAU};

/// A vertex: object-space position and normal, its texture coordinates, tangent and colour.
///
/// `uv` is glTF's `TEXCOORD_0`: where the material's textures are read, and for an alpha object
/// its place in the lightmap layout (then in `[0, 1]^2`); the built-in shapes put their lightmap
/// layout there, light volumes zero. `uv1` is `TEXCOORD_1`. `tangent` is glTF's `TANGENT`
/// (xyz along +u in object space, w = +-1 the bitangent's sign, `cross(normal, tangent.xyz) * w`),
/// zero where the mesh has no normal-mapped material. `color` is `COLOR_0` as linear RGBA, which
/// multiplies the material's tint; white by default.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Vertex {
    /// Object-space position.
    pub position: [f32; 3],
    /// Object-space unit normal.
    pub normal: [f32; 3],
    /// `TEXCOORD_0` (see the type's doc).
    pub uv: [f32; 2],
    /// `TEXCOORD_1`.
    pub uv1: [f32; 2],
    /// Object-space tangent along +u, `w` the bitangent's sign; zero without a normal map.
    pub tangent: [f32; 4],
    /// `COLOR_0`, linear RGBA, multiplying the tint.
    pub color: [f32; 4],
}

impl Vertex {
    /// A vertex with no second texture coordinate, no tangent and a white colour.
    pub const fn new(position: [f32; 3], normal: [f32; 3], uv: [f32; 2]) -> Self {
        Self {
            position,
            normal,
            uv,
            uv1: [0.0; 2],
            tangent: [0.0; 4],
            color: [1.0; 4],
        }
    }
}

/// An indexed triangle list.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// The vertices the indices refer to.
    pub vertices: Vec<Vertex>,
    /// Three indices per triangle, counter-clockwise seen from outside.
    pub indices: Vec<u32>,
}

impl Mesh {
    /// What makes the mesh unusable as a triangle list, if anything: indices not three per
    /// triangle, an index past the vertices, a position, normal or texture coordinate that is
    /// not finite. What a consumer would otherwise skip or read out of bounds in silence.
    pub fn problem(&self) -> Option<String> {
        if !self.indices.len().is_multiple_of(3) {
            return Some(format!(
                "{} indices, not three per triangle",
                self.indices.len()
            ));
        }
        let count = self.vertices.len();
        if let Some(i) = self.indices.iter().position(|&i| i as usize >= count) {
            return Some(format!(
                "index {i} is {}, past its {count} vertices",
                self.indices[i]
            ));
        }
        let finite =
            |v: &Vertex| (v.position.iter().chain(&v.normal).chain(&v.uv)).all(|x| x.is_finite());
        if let Some(i) = self.vertices.iter().position(|v| !finite(v)) {
            return Some(format!("vertex {i} is not finite"));
        }
        None
    }

    fn push_triangle_fan_quad(
        &mut self,
        corners: [[f32; 3]; 4],
        normal: [f32; 3],
        uvs: [[f32; 2]; 4],
    ) {
        let base = self.vertices.len() as u32;
        for (position, uv) in corners.into_iter().zip(uvs) {
            self.vertices.push(Vertex::new(position, normal, uv));
        }
        self.indices
            .extend_from_slice(&[base, base + 1, base + 2, base, base + 2, base + 3]);
    }

    /// Each triangle's plane distance from `center` (positive when `center` is on the inner side).
    pub fn face_distances(&self, center: glam::Vec3) -> impl Iterator<Item = f32> + '_ {
        self.indices.chunks_exact(3).map(move |t| {
            let p = |i: u32| glam::Vec3::from(self.vertices[i as usize].position);
            let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
            let n = (b - a).cross(c - a).normalize();
            n.dot(a - center)
        })
    }
}

/// The box lightmap layout: face `f` (axis `f / 2`, `-` then `+`) owns cell `(f % 3, f / 3)` of a
/// 3 x 2 grid, inset by this fraction of the cell on every side. The inset is a gutter that the
/// bake fills by extending each face's plane ([`unit_box_bake`]), so bilinear filtering at a face
/// edge reads texels of the same plane instead of a neighbouring face's or empty ones.
pub const BOX_UV_INSET: f32 = 0.125;

/// The cube `[-1, 1]^3` with flat normals, each face in its cell of the box lightmap layout.
pub fn unit_box() -> Mesh {
    box_faces(1.0, BOX_UV_INSET)
}

/// The box as the lightmap bake draws it: each face's plane extended to fill its whole cell,
/// positions extrapolated linearly into the gutter, so every texel of the layout holds a probe.
pub fn unit_box_bake() -> Mesh {
    box_faces(1.0 / (1.0 - 2.0 * BOX_UV_INSET), 0.0)
}

/// The six faces at in-plane half-extent `extent`, mapped to their cells inset by `inset`.
fn box_faces(extent: f32, inset: f32) -> Mesh {
    let mut m = Mesh::default();
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let mut normal = [0.0; 3];
            normal[axis] = sign;
            let corner = |a: f32, b: f32| {
                let mut p = [0.0; 3];
                p[axis] = sign;
                p[u] = a * extent;
                p[v] = b * extent;
                p
            };
            let face = axis * 2 + usize::from(sign > 0.0);
            let cell = [(face % 3) as f32, (face / 3) as f32];
            let uv = |a: f32, b: f32| {
                let local = |t: f32| inset + (t + 1.0) * 0.5 * (1.0 - 2.0 * inset);
                [(cell[0] + local(a)) / 3.0, (cell[1] + local(b)) / 2.0]
            };
            let params = [(-1., -1.), (1., -1.), (1., 1.), (-1., 1.)];
            let quad = params.map(|(a, b)| corner(a, b));
            let uvs = params.map(|(a, b)| uv(a, b));
            // (u, v, axis) is right-handed, so this quad faces +axis; reverse it for -axis.
            let (quad, uvs) = if sign > 0.0 {
                (quad, uvs)
            } else {
                (
                    [quad[0], quad[3], quad[2], quad[1]],
                    [uvs[0], uvs[3], uvs[2], uvs[1]],
                )
            };
            m.push_triangle_fan_quad(quad, normal, uvs);
        }
    }
    m
}

/// The segments around and rings from pole to pole of the scene's sphere shape (drawn, and
/// baked for lightmaps).
pub const SPHERE_DETAIL: (u32, u32) = (48, 24);

/// A UV sphere of radius 1 with smooth normals: `segments` around, `rings` from pole to pole.
pub fn uv_sphere(segments: u32, rings: u32) -> Mesh {
    let mut m = Mesh::default();
    for r in 0..=rings {
        let theta = PI * r as f32 / rings as f32;
        for s in 0..=segments {
            let phi = TAU * s as f32 / segments as f32;
            let p = [
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            ];
            let uv = [s as f32 / segments as f32, r as f32 / rings as f32];
            m.vertices.push(Vertex::new(p, p, uv));
        }
    }
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let (a, b) = (r * row + s, (r + 1) * row + s);
            if r != 0 {
                m.indices.extend_from_slice(&[a, b, a + 1]);
            }
            if r != rings - 1 {
                m.indices.extend_from_slice(&[a + 1, b, b + 1]);
            }
        }
    }
    m
}

/// A point-light volume: a UV sphere scaled so every face lies outside the unit sphere.
pub fn light_sphere(segments: u32, rings: u32) -> Mesh {
    let mut m = uv_sphere(segments, rings);
    let inradius = m
        .face_distances(glam::Vec3::ZERO)
        .fold(f32::INFINITY, f32::min);
    // A hair of margin so float rounding in the vertex shader cannot cut into the sphere.
    let scale = 1.0001 / inradius;
    for v in &mut m.vertices {
        v.position = v.position.map(|c| c * scale);
    }
    m
}

/// A spot-light volume: apex at the origin, axis +Z, closed by a cap at `z = 1` whose polygon
/// circumscribes the unit circle. The renderer scales x, y by `range * tan(outer)` and z by range.
pub fn light_cone(sides: u32) -> Mesh {
    let mut m = Mesh::default();
    let r = 1.0001 / (PI / sides as f32).cos();
    let ring = |i: u32| {
        let a = TAU * i as f32 / sides as f32;
        [r * a.cos(), r * a.sin(), 1.0001]
    };
    m.vertices
        .push(Vertex::new([0.0; 3], [0.0, 0.0, -1.0], [0.0; 2]));
    let cap_center = m.vertices.len() as u32;
    m.vertices
        .push(Vertex::new([0.0, 0.0, 1.0001], [0.0, 0.0, 1.0], [0.0; 2]));
    for i in 0..sides {
        m.vertices
            .push(Vertex::new(ring(i), [0.0, 0.0, 1.0], [0.0; 2]));
    }
    for i in 0..sides {
        let a = 2 + i;
        let b = 2 + (i + 1) % sides;
        // Side: apex, then the ring counter-clockwise seen from outside.
        m.indices.extend_from_slice(&[0, b, a]);
        // Cap, seen from +Z.
        m.indices.extend_from_slice(&[cap_center, a, b]);
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mesh_with_an_index_past_its_vertices_or_a_nan_says_so() {
        assert_eq!(uv_sphere(8, 4).problem(), None);
        let mut m = unit_box();
        m.indices[4] = m.vertices.len() as u32;
        assert!(
            m.problem().unwrap().contains("index 4"),
            "{:?}",
            m.problem()
        );
        let mut m = unit_box();
        m.indices.pop();
        assert!(m.problem().unwrap().contains("three per triangle"));
        let mut m = unit_box();
        m.vertices[2].normal[1] = f32::NAN;
        assert!(m.problem().unwrap().contains("vertex 2"));
    }

    fn assert_outward(m: &Mesh, name: &str) {
        let inside = if name == "light cone" {
            glam::Vec3::new(0.0, 0.0, 0.5)
        } else {
            glam::Vec3::ZERO
        };
        for (i, d) in m.face_distances(inside).enumerate() {
            assert!(
                d > 0.0,
                "{name}: face {i} faces inward (plane distance {d})"
            );
        }
    }

    #[test]
    fn meshes_wind_outward() {
        assert_outward(&unit_box(), "box");
        assert_outward(&light_sphere(16, 8), "light sphere");
        assert_outward(&light_cone(12), "light cone");
        // UV sphere faces all face away from the centre too.
        assert_outward(&uv_sphere(16, 8), "uv sphere");
    }

    #[test]
    fn box_faces_keep_to_their_cells_and_the_bake_fills_them() {
        let (faces, bake) = (unit_box(), unit_box_bake());
        for (f, (quad, baked)) in faces
            .vertices
            .chunks_exact(4)
            .zip(bake.vertices.chunks_exact(4))
            .enumerate()
        {
            let cell = [(f % 3) as f32 / 3.0, (f / 3) as f32 / 2.0];
            for v in quad {
                let local = [(v.uv[0] - cell[0]) * 3.0, (v.uv[1] - cell[1]) * 2.0];
                for t in local {
                    assert!(
                        (t - BOX_UV_INSET).abs() < 1e-6 || (t - 1.0 + BOX_UV_INSET).abs() < 1e-6
                    );
                }
            }
            // The bake quad covers the whole cell, on the same plane, along the same uv axes.
            for (v, b) in quad.iter().zip(baked) {
                assert_eq!(v.normal, b.normal);
                let axis = v.normal.iter().position(|n| *n != 0.0).unwrap();
                assert_eq!(v.position[axis], b.position[axis]);
            }
            let span = |q: &[Vertex], i: usize| {
                q.iter().map(|v| v.uv[i]).fold(f32::MIN, f32::max)
                    - q.iter().map(|v| v.uv[i]).fold(f32::MAX, f32::min)
            };
            assert!((span(baked, 0) - 1.0 / 3.0).abs() < 1e-6);
            assert!((span(baked, 1) - 0.5).abs() < 1e-6);
        }
    }

    #[test]
    fn light_sphere_circumscribes_the_unit_sphere() {
        let m = light_sphere(12, 6);
        let min = m
            .face_distances(glam::Vec3::ZERO)
            .fold(f32::INFINITY, f32::min);
        assert!(min >= 1.0, "inradius {min}");
        assert!(min < 1.01);
    }

    #[test]
    fn light_cone_circumscribes_the_unit_disc_at_z1() {
        let m = light_cone(10);
        // Cap faces sit at z = 1.0001 and the side planes pass outside radius z at height z.
        for t in m.indices.chunks_exact(3) {
            let p = |i: u32| glam::Vec3::from(m.vertices[i as usize].position);
            let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
            let n = (b - a).cross(c - a).normalize();
            if n.z.abs() > 0.99 {
                continue;
            }
            // The point on the cone surface at height 1 in this face's direction lies inside.
            let dir = glam::Vec3::new(n.x, n.y, 0.0).normalize();
            let on_cone = glam::Vec3::new(dir.x, dir.y, 1.0);
            assert!(n.dot(on_cone - a) <= 1e-5, "cone face cuts the unit cone");
        }
    }
}
