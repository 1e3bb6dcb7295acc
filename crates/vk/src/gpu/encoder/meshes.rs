//! Meshes on the GPU ([`GpuMesh`]): the scene's object shapes ([`Meshes`]); the lighting's
//! light volumes are `passes::light_volumes`'.

use crate::gpu::device::context::Context;
use crate::gpu::device::error::Result;
use crate::gpu::device::resources::Buffer;
use crate::gpu::device::teardown::build;
use crate::gpu::encoder::recording::Recording;
use crate::gpu::encoder::upload::{upload, BufferUpload};
use ash::vk;
use gpu_allocator::MemoryLocation;
use histencil_scene::{unit_box, uv_sphere, Mesh, Shape, SPHERE_DETAIL};

#[derive(Default)]
pub struct GpuMesh {
    pub vertices: Buffer,
    pub indices: Buffer,
    pub index_count: u32,
}

impl GpuMesh {
    /// Device-local vertex and index buffers sized for `mesh`, not yet filled.
    fn allocate(ctx: &Context, name: &str, mesh: &Mesh) -> Result<Self> {
        let buffer = |what: &str, bytes: usize, usage| {
            Buffer::new(
                ctx,
                &format!("{name}-{what}"),
                bytes as u64,
                usage | vk::BufferUsageFlags::TRANSFER_DST,
                MemoryLocation::GpuOnly,
            )
        };
        build(ctx, |m: &mut Self| {
            let vertex_bytes = std::mem::size_of_val(mesh.vertices.as_slice());
            m.vertices = buffer(
                "vertices",
                vertex_bytes,
                vk::BufferUsageFlags::VERTEX_BUFFER,
            )?;
            let index_bytes = std::mem::size_of_val(mesh.indices.as_slice());
            m.indices = buffer("indices", index_bytes, vk::BufferUsageFlags::INDEX_BUFFER)?;
            m.index_count = mesh.indices.len() as u32;
            Ok(())
        })
    }

    /// `meshes` in device-local memory, filled through one staging upload named `name`. A
    /// failure half way frees what was made.
    pub(crate) fn upload_all(
        ctx: &Context,
        name: &str,
        meshes: &[(String, &Mesh)],
    ) -> Result<Vec<Self>> {
        build(ctx, |made: &mut Vec<GpuMesh>| {
            for (mesh_name, mesh) in meshes {
                made.push(GpuMesh::allocate(ctx, mesh_name, mesh)?);
            }
            let bytes: Vec<(Vec<u8>, Vec<u8>)> =
                meshes.iter().map(|(_, m)| mesh_bytes(m)).collect();
            let uploads: Vec<BufferUpload> = made
                .iter()
                .zip(&bytes)
                .flat_map(|(gpu, (vertices, indices))| {
                    [
                        BufferUpload {
                            dst: gpu.vertices.handle,
                            bytes: vertices,
                        },
                        BufferUpload {
                            dst: gpu.indices.handle,
                            bytes: indices,
                        },
                    ]
                })
                .collect();
            upload(ctx, name, &uploads, &[])
        })
    }

    /// `mesh` in host-visible memory, written through its mapping: no submission, so no use of
    /// the queue. A failure half way frees what was made.
    pub(crate) fn host_visible(ctx: &Context, name: &str, mesh: &Mesh) -> Result<Self> {
        let (vertices, indices) = mesh_bytes(mesh);
        build(ctx, |m: &mut Self| {
            let usage = vk::BufferUsageFlags::VERTEX_BUFFER;
            m.vertices = Buffer::with_data(ctx, &format!("{name}-vertices"), usage, &vertices)?;
            let usage = vk::BufferUsageFlags::INDEX_BUFFER;
            m.indices = Buffer::with_data(ctx, &format!("{name}-indices"), usage, &indices)?;
            m.index_count = mesh.indices.len() as u32;
            Ok(())
        })
    }

    /// Binds and draws the whole mesh.
    pub(crate) fn draw(&self, rec: &Recording) {
        let (vertices, indices) = (self.vertices.handle, self.indices.handle);
        // SAFETY: the passes draw a mesh inside a rendering with a graphics pipeline bound
        // whose vertex input reads binding 0, with its sets and state (the passes' contract).
        // The buffers are live, made with VERTEX_BUFFER / INDEX_BUFFER usage and filled before
        // any draw (uploaded and waited for, or written through their mapping); `index_count`
        // u32 indices, each naming a vertex of the mesh (`Scene::validate` checks imported
        // meshes; the built-in shapes are made so).
        unsafe { rec.draw_mesh(vertices, indices, self.index_count) };
    }

    pub(crate) fn destroy(&mut self, ctx: &Context) {
        self.vertices.destroy(ctx);
        self.indices.destroy(ctx);
    }
}

/// The vertex buffer's bytes (every `Vertex` field, in order, as `VertexInput::Mesh` reads
/// them) and the index buffer's.
fn mesh_bytes(mesh: &Mesh) -> (Vec<u8>, Vec<u8>) {
    let vertices = mesh
        .vertices
        .iter()
        .flat_map(|v| {
            v.position
                .iter()
                .chain(&v.normal)
                .chain(&v.uv)
                .chain(&v.uv1)
                .chain(&v.tangent)
                .chain(&v.color)
                .flat_map(|f| f.to_ne_bytes())
        })
        .collect();
    let indices = mesh.indices.iter().flat_map(|i| i.to_ne_bytes()).collect();
    (vertices, indices)
}

pub struct Meshes {
    pub unit_box: GpuMesh,
    pub sphere: GpuMesh,
    /// The scene's imported meshes (`Shape::Mesh`), in `Scene::meshes` order.
    pub imported: Vec<GpuMesh>,
}

impl Meshes {
    /// The built-in shapes and the scene's `imported` meshes. A failure half way frees the
    /// meshes made so far.
    pub fn new(ctx: &Context, imported: &[Mesh]) -> Result<Self> {
        let builtin = [unit_box(), uv_sphere(SPHERE_DETAIL.0, SPHERE_DETAIL.1)];
        let builtin_names = ["box-mesh", "sphere-mesh"].map(String::from);
        let imported_names = (0..imported.len()).map(|i| format!("imported-mesh-{i}"));
        let names = builtin_names.into_iter().chain(imported_names);
        let named: Vec<(String, &Mesh)> = names.zip(builtin.iter().chain(imported)).collect();
        let mut made = GpuMesh::upload_all(ctx, "mesh-upload", &named)?.into_iter();
        let mut next = || made.next().expect("two built-in meshes");
        let (unit_box, sphere) = (next(), next());
        Ok(Self {
            unit_box,
            sphere,
            imported: made.collect(),
        })
    }

    pub fn shape(&self, shape: Shape) -> &GpuMesh {
        match shape {
            Shape::Box => &self.unit_box,
            Shape::Sphere => &self.sphere,
            Shape::Mesh(i) => &self.imported[i as usize],
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for m in [&mut self.unit_box, &mut self.sphere]
            .into_iter()
            .chain(&mut self.imported)
        {
            m.destroy(ctx);
        }
    }
}

crate::gpu::device::teardown::destroy_by_method!(Meshes);

crate::gpu::device::teardown::destroy_by_method!(GpuMesh);
