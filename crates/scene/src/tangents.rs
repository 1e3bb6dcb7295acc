//! Tangents for a normal-mapped primitive that has none, generated as glTF asks: MikkTSpace
//! (the `bevy_mikktspace` crate: the reference algorithm in safe Rust, byte-identical to the C
//! one, and no vector library an engine's own could clash with), so a normal map baked by the
//! usual tools reads back the surface it was baked from.
//!
//! glTF's texture space has its origin at the top left and its normal maps' +Y up the image, so
//! its bitangent `cross(N, T) * w` points along decreasing V; MikkTSpace's points along
//! increasing V (OpenGL's origin at the bottom left). MikkTSpace is therefore given `(u, 1 - v)`,
//! as glTF exporters do: the tangent is the same, its sign `w` is glTF's. Every supplied tangent
//! of the sample model NormalTangentMirrorTest (5240 triangles) has its bitangent along -dP/dV.

use crate::{Mesh, Vertex};
use std::collections::HashMap;

/// How the mesh's fitted vertices map back to the file's own space, where tangents are made,
/// and how a tangent made there maps into the fitted mesh.
pub(crate) struct Space<'a> {
    pub position: &'a dyn Fn([f32; 3]) -> [f32; 3],
    pub normal: &'a dyn Fn([f32; 3]) -> [f32; 3],
    pub tangent: &'a dyn Fn([f32; 4]) -> [f32; 4],
}

struct Corners<'a> {
    mesh: &'a Mesh,
    uv_set: u32,
    space: &'a Space<'a>,
    /// One tangent per triangle corner.
    tangents: Vec<[f32; 4]>,
}

impl Corners<'_> {
    fn vertex(&self, face: usize, vert: usize) -> &Vertex {
        &self.mesh.vertices[self.mesh.indices[face * 3 + vert] as usize]
    }
}

impl bevy_mikktspace::Geometry for Corners<'_> {
    fn num_faces(&self) -> usize {
        self.mesh.indices.len() / 3
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        (self.space.position)(self.vertex(face, vert).position)
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        (self.space.normal)(self.vertex(face, vert).normal)
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        let v = self.vertex(face, vert);
        let [u, v] = if self.uv_set == 0 { v.uv } else { v.uv1 };
        [u, 1.0 - v]
    }

    /// A corner the algorithm gives nothing (a degenerate triangle with no neighbour to
    /// borrow from) keeps a zero tangent, which `generate` replaces.
    fn set_tangent(
        &mut self,
        tangent: Option<bevy_mikktspace::TangentSpace>,
        face: usize,
        vert: usize,
    ) {
        if let Some(t) = tangent {
            self.tangents[face * 3 + vert] = t.tangent_encoded();
        }
    }
}

/// Gives every vertex of `mesh` a tangent made from texture coordinate set `uv_set`. Vertices
/// whose corners get different tangents (a UV seam, a mirrored half) are split; corners that
/// agree share a vertex again. A corner the algorithm leaves without a usable tangent (a
/// triangle with no UV area) gets one perpendicular to its normal, so the shader never
/// normalises zero.
pub(crate) fn generate(mesh: &mut Mesh, uv_set: u32, space: &Space) -> Result<(), String> {
    let corners = mesh.indices.len();
    let mut geometry = Corners {
        mesh,
        uv_set,
        space,
        tangents: vec![[0.0; 4]; corners],
    };
    // A panic inside the algorithm (an index it did not expect) must not take the importer
    // down; it has no error of its own to return yet.
    let made = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        bevy_mikktspace::generate_tangents(&mut geometry)
    }));
    if !matches!(made, Ok(Ok(()))) {
        return Err("tangent generation failed on this geometry".into());
    }
    let tangents = geometry.tangents;
    let mut vertices: Vec<Vertex> = Vec::with_capacity(mesh.vertices.len());
    let mut seen: HashMap<(u32, [u32; 4]), u32> = HashMap::new();
    let mut indices = Vec::with_capacity(corners);
    for (corner, &index) in mesh.indices.iter().enumerate() {
        let mut v = mesh.vertices[index as usize];
        let made = tangents[corner];
        v.tangent = if made[..3].iter().all(|x| x.is_finite())
            && made[..3].iter().map(|x| x * x).sum::<f32>() > 1e-12
        {
            (space.tangent)(made)
        } else {
            perpendicular(v.normal)
        };
        let key = (index, v.tangent.map(f32::to_bits));
        let slot = *seen.entry(key).or_insert_with(|| {
            vertices.push(v);
            vertices.len() as u32 - 1
        });
        indices.push(slot);
    }
    mesh.vertices = vertices;
    mesh.indices = indices;
    Ok(())
}

/// A unit tangent perpendicular to the unit normal `n`, handedness +1.
fn perpendicular(n: [f32; 3]) -> [f32; 4] {
    let n = glam::Vec3::from(n);
    n.any_orthonormal_vector().extend(1.0).to_array()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn identity() -> Space<'static> {
        Space {
            position: &|p| p,
            normal: &|n| n,
            tangent: &|t| t,
        }
    }

    /// A quad in the xy plane facing +z, u along +x and v along +y: the tangent is +x, and
    /// glTF's bitangent `cross(N, T) * w` points along decreasing v, -y, so w = -1. Mirrored in
    /// u, the tangent turns to -x and w to +1.
    #[test]
    fn a_planar_quad_gets_its_uv_axes() {
        let quad = |u_sign: f32| Mesh {
            vertices: [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
                .map(|[x, y]| Vertex::new([x, y, 0.0], [0.0, 0.0, 1.0], [u_sign * x, y]))
                .to_vec(),
            indices: vec![0, 1, 2, 0, 2, 3],
        };
        for (sign, expected) in [(1.0, [1.0, 0.0, 0.0, -1.0]), (-1.0, [-1.0, 0.0, 0.0, 1.0])] {
            let mut mesh = quad(sign);
            generate(&mut mesh, 0, &identity()).unwrap();
            assert_eq!(mesh.vertices.len(), 4, "corners that agree share vertices");
            for v in &mesh.vertices {
                let t = v.tangent;
                let close = t.iter().zip(expected).all(|(a, b)| (a - b).abs() < 1e-5);
                assert!(close, "{t:?} against {expected:?}");
                // glTF's convention: the bitangent points along -v.
                let b = glam::Vec3::from(v.normal).cross(glam::Vec3::new(t[0], t[1], t[2])) * t[3];
                assert!((b + glam::Vec3::Y).length() < 1e-5, "{b}");
            }
        }
    }

    #[test]
    fn degenerate_uvs_still_give_unit_tangents() {
        let mut mesh = Mesh {
            vertices: [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]
                .map(|[x, y]| Vertex::new([x, y, 0.0], [0.0, 0.0, 1.0], [0.5, 0.5]))
                .to_vec(),
            indices: vec![0, 1, 2],
        };
        generate(&mut mesh, 0, &identity()).unwrap();
        for v in &mesh.vertices {
            let t = glam::Vec3::new(v.tangent[0], v.tangent[1], v.tangent[2]);
            assert!((t.length() - 1.0).abs() < 1e-4, "{t}");
            assert!(t.dot(glam::Vec3::Z).abs() < 1e-4);
        }
    }
}
