//! Lightmaps for an engine's translucent objects and particle systems, through C: each frame the
//! engine hands over its alpha entities as plain structs, histencil plans their regions of the
//! engine's atlas (slices and texels from the CPU error estimate) and lights them into it, and
//! the engine's alpha shaders read the atlas and the entity records (`lightmap_sample.glsl`).

use crate::frame::{lights_into, HistencilImage, HistencilLight, HistencilView};
use crate::gbuffer::brdf_of;
use crate::handles::{self, Kind};
use crate::shaders::{shaders_of, utf8, HistencilShaders};
use crate::{call, check_size, required, slice, Failure, HistencilBrdfParam, HistencilResult};
use crate::{HistencilContext, Outcome};
use ash::vk;
use glam::{Mat4, Vec3};
use histencil::scene::{Mesh, Particle, ParticleLayout, Vertex};
use histencil::{
    plan_entities, AlphaEntity, AlphaEntityKind, AlphaLightmaps, AlphaLightmapsDesc, BrdfModules,
    ChoiceSettings, Context, Light, LightmapFrame, Material, Viewer,
};
use std::ffi::c_char;
use std::sync::Arc;

/// What `histencil_lightmaps_create` makes lightmaps for: fixed for their life.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct HistencilLightmapsDesc {
    /// `sizeof(HistencilLightmapsDesc)`.
    pub size: u32,
    /// The shaders whose BRDF set the entities' materials name (`histencil_shaders_compile` or
    /// `_load`), or null for histencil's own BRDFs.
    pub shaders: *const HistencilShaders,
    /// The atlas's format: a colour format the device blends into
    /// (`VK_FORMAT_R16G16B16A16_SFLOAT` as histencil's own).
    pub atlas_format: vk::Format,
    /// How many frames the engine has in flight: slots 0 to `frames_in_flight - 1`.
    pub frames_in_flight: u32,
    /// The direction map's format for `histencil_lightmaps_record` with a `direction` image, or
    /// `VK_FORMAT_UNDEFINED` for plain lightmaps only.
    pub direction_format: vk::Format,
}

/// A vertex of a translucent object's probe mesh, in object space.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct HistencilVertex {
    /// Its position.
    pub position: [f32; 3],
    /// Its unit normal.
    pub normal: [f32; 3],
    /// Its lightmap coordinate in `[0, 1]^2`: the layout the alpha shader samples with.
    pub uv: [f32; 2],
}

/// A translucent object's mesh in its lightmap UV layout: one probe per texel it covers.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct HistencilMesh {
    /// How many vertices.
    pub vertex_count: u32,
    /// The vertices.
    pub vertices: *const HistencilVertex,
    /// How many indices: three per triangle, counter-clockwise seen from outside.
    pub index_count: u32,
    /// The indices, each below `vertex_count`.
    pub indices: *const u32,
}

/// One sprite of a particle system, in world space.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct HistencilParticle {
    /// Its centre (for a ribbon, a control point).
    pub position: [f32; 3],
    /// Its half-width, positive.
    pub size: f32,
}

/// A translucent object: `mesh`, `transform`, `local_min`, `local_max`.
pub const HISTENCIL_ENTITY_OBJECT: u32 = 0;
/// A particle system: `particles`, `particle_layout` (and `slices`).
pub const HISTENCIL_ENTITY_PARTICLES: u32 = 1;

/// One camera-facing quad around the system.
pub const HISTENCIL_PARTICLES_BILLBOARD: u32 = 0;
/// `slices` such quads stacked through the system's depth (2 to 8).
pub const HISTENCIL_PARTICLES_SLICES: u32 = 1;
/// As many quads as the lighting needs, chosen from the error estimate.
pub const HISTENCIL_PARTICLES_AUTO: u32 = 2;
/// One texel per mote.
pub const HISTENCIL_PARTICLES_DUST: u32 = 3;
/// The particles are a ribbon's control points, in order.
pub const HISTENCIL_PARTICLES_RIBBON: u32 = 4;

/// One translucent object or particle system, as lit this frame.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct HistencilAlphaEntity {
    /// `HISTENCIL_ENTITY_*`.
    pub kind: u32,
    /// An object's probe mesh (null for a particle system).
    pub mesh: *const HistencilMesh,
    /// An object's object-to-world matrix, column-major, finite and invertible.
    pub transform: [f32; 16],
    /// The object-space box of what the object draws: its lights are those reaching it.
    pub local_min: [f32; 3],
    /// Its other corner.
    pub local_max: [f32; 3],
    /// A particle system's `HISTENCIL_PARTICLES_*`.
    pub particle_layout: u32,
    /// With `HISTENCIL_PARTICLES_SLICES`, how many slices.
    pub slices: u32,
    /// How many particles.
    pub particle_count: u32,
    /// The particles (null for an object).
    pub particles: *const HistencilParticle,
    /// The BRDF its probes are lit with, by name, NUL-terminated.
    pub brdf_name: *const c_char,
    /// How many BRDF parameters.
    pub param_count: u32,
    /// The BRDF's parameters by name (an engine BRDF's left out take their defaults).
    pub params: *const HistencilBrdfParam,
    /// Its colour, linear RGB in `[0, 1]`.
    pub tint: [f32; 3],
    /// Its coverage in `[0, 1]`, carried to its record for the alpha shader.
    pub opacity: f32,
}

/// One frame's lightmaps.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct HistencilLightmapFrame {
    /// `sizeof(HistencilLightmapFrame)`.
    pub size: u32,
    /// The frame-in-flight slot, below `frames_in_flight`.
    pub slot: u32,
    /// The camera: particle quads face it, probes are lit towards it.
    pub view: HistencilView,
    /// How many lights.
    pub light_count: u32,
    /// The frame's lights; each entity is lit by those whose range reaches it.
    pub lights: *const HistencilLight,
    /// How many entities.
    pub entity_count: u32,
    /// The entities, in the order their records are written (`histencil_lightmaps_entity_buffer`).
    pub entities: *const HistencilAlphaEntity,
    /// The viewport's height in pixels, which the texel choice estimates the error against.
    pub viewport_height: u32,
}

/// Lightmaps made on a context.
pub struct HistencilLightmaps {
    lightmaps: AlphaLightmaps<Arc<Context>>,
    modules: &'static BrdfModules,
    /// Each frame's lights and meshes, converted from the C structs, kept from frame to frame.
    lights: Vec<Light>,
    meshes: Vec<Mesh>,
    particles: Vec<Particle>,
}

/// The most entities, vertices or indices a frame passes: bounds on what is read.
const MAX_ENTITIES: u32 = 1 << 16;
const MAX_MESH_ELEMENTS: u32 = 1 << 24;

/// Makes lightmaps on `context`: their pipelines, per-slot buffers and sets. Nothing is
/// submitted.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle or pointer, a wrong `size`,
/// `frames_in_flight` outside 1 to 16; `BAD_SETUP` for an atlas or direction format the device
/// cannot blend into; `DEVICE_LIMIT`, `VULKAN` as the device says.
///
/// Thread safety: not at the same time as another call on `context`.
///
/// # Safety
/// `desc` is null or points at a live description; `lightmaps` is null or writable.
#[no_mangle]
pub unsafe extern "C" fn histencil_lightmaps_create(
    context: *mut HistencilContext,
    desc: *const HistencilLightmapsDesc,
    lightmaps: *mut *mut HistencilLightmaps,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        let context = unsafe { handles::get(context, Kind::Context, "context") }?;
        // SAFETY: this fn's # Safety.
        let desc = unsafe { required(desc, "desc") }?;
        if lightmaps.is_null() {
            return Err(Failure::invalid("lightmaps (the out pointer) is null"));
        }
        check_size::<HistencilLightmapsDesc>("HistencilLightmapsDesc", desc.size)?;
        if !(1..=16).contains(&desc.frames_in_flight) {
            return Err(Failure::invalid(format!(
                "HistencilLightmapsDesc.frames_in_flight is {}, outside 1 to 16",
                desc.frames_in_flight
            )));
        }
        // SAFETY: the header's contract: null or a live handle.
        let shaders = unsafe { shaders_of(desc.shaders) }?;
        let modules = shaders.map_or(BrdfModules::builtin(), |s| s.modules);
        let rust_desc = AlphaLightmapsDesc {
            atlas_format: desc.atlas_format,
            frames_in_flight: desc.frames_in_flight,
            direction_format: (desc.direction_format != vk::Format::UNDEFINED)
                .then_some(desc.direction_format),
        };
        let made = AlphaLightmaps::with_modules(context.ctx.clone(), &rust_desc, modules)?;
        let held = HistencilLightmaps {
            lightmaps: made,
            modules,
            lights: Vec::new(),
            meshes: Vec::new(),
            particles: Vec::new(),
        };
        // SAFETY: checked non-null; writable by this fn's # Safety.
        unsafe { lightmaps.write(handles::make(held, Kind::Lightmaps)) };
        Ok(())
    })
}

/// `mesh` as histencil's, each index checked against the vertices.
///
/// # Safety
/// The header's contract: `vertex_count` vertices and `index_count` indices at the pointers.
unsafe fn mesh_of(mesh: &HistencilMesh, at: &str) -> Outcome<Mesh> {
    for (name, count) in [
        ("vertex_count", mesh.vertex_count),
        ("index_count", mesh.index_count),
    ] {
        if count > MAX_MESH_ELEMENTS {
            return Err(Failure::invalid(format!(
                "{at}.mesh.{name} is {count}, past {MAX_MESH_ELEMENTS}"
            )));
        }
    }
    if !mesh.index_count.is_multiple_of(3) {
        return Err(Failure::invalid(format!(
            "{at}.mesh.index_count is {}, not three per triangle",
            mesh.index_count
        )));
    }
    // SAFETY: this fn's # Safety.
    let (vertices, indices) = unsafe {
        (
            slice(mesh.vertices, mesh.vertex_count, "mesh.vertices")?,
            slice(mesh.indices, mesh.index_count, "mesh.indices")?,
        )
    };
    if let Some(i) = indices.iter().position(|&i| i >= mesh.vertex_count) {
        return Err(Failure::invalid(format!(
            "{at}.mesh.indices[{i}] is {}, past its {} vertices",
            indices[i], mesh.vertex_count
        )));
    }
    let finite = |v: &HistencilVertex| {
        v.position
            .iter()
            .chain(&v.normal)
            .chain(&v.uv)
            .all(|x| x.is_finite())
    };
    if let Some(i) = vertices.iter().position(|v| !finite(v)) {
        return Err(bad_frame(format!("{at}.mesh.vertices[{i}] is not finite")));
    }
    Ok(Mesh {
        vertices: (vertices.iter())
            .map(|v| Vertex {
                position: v.position,
                normal: v.normal,
                uv: v.uv,
                uv1: v.uv,
                tangent: [0.0; 4],
                color: [1.0; 4],
            })
            .collect(),
        indices: indices.to_vec(),
    })
}

fn bad_frame(message: String) -> Failure {
    Failure {
        result: HistencilResult::BadFrame,
        message,
    }
}

/// The frame's entities as histencil's, their meshes and particles converted into `meshes` and
/// `particles` (the lightmaps' own, kept from frame to frame).
///
/// # Safety
/// The header's contract for `entities` and every pointer in them.
unsafe fn entities_of<'a>(
    entities: &'a [HistencilAlphaEntity],
    modules: &BrdfModules,
    meshes: &'a mut Vec<Mesh>,
    particles: &'a mut Vec<Particle>,
) -> Outcome<Vec<AlphaEntity<'a>>> {
    meshes.clear();
    particles.clear();
    let mut ranges = Vec::with_capacity(entities.len());
    for (i, e) in entities.iter().enumerate() {
        let at = format!("entities[{i}]");
        match e.kind {
            HISTENCIL_ENTITY_OBJECT => {
                // SAFETY: the header's contract.
                let mesh = unsafe { required(e.mesh, &format!("{at}.mesh")) }?;
                // SAFETY: as above.
                meshes.push(unsafe { mesh_of(mesh, &at) }?);
            }
            HISTENCIL_ENTITY_PARTICLES => {
                if e.particle_count > MAX_MESH_ELEMENTS {
                    return Err(Failure::invalid(format!(
                        "{at}.particle_count is {}, past {MAX_MESH_ELEMENTS}",
                        e.particle_count
                    )));
                }
                // SAFETY: the header's contract: `particle_count` particles at `particles`.
                let given =
                    unsafe { slice(e.particles, e.particle_count, &format!("{at}.particles")) }?;
                let start = particles.len();
                particles.extend(given.iter().map(|p| Particle {
                    position: Vec3::from(p.position),
                    size: p.size,
                }));
                ranges.push(start..particles.len());
            }
            _ => {}
        }
    }
    let (mut next_mesh, mut next_range) = (meshes.iter(), ranges.into_iter());
    let particles: &'a [Particle] = particles;
    let mut out = Vec::with_capacity(entities.len());
    for (i, e) in entities.iter().enumerate() {
        let at = format!("entities[{i}]");
        let kind = match e.kind {
            HISTENCIL_ENTITY_OBJECT => AlphaEntityKind::Object {
                probe_mesh: next_mesh.next().expect("one mesh per object"),
                transform: Mat4::from_cols_array(&e.transform),
                local_bounds: (Vec3::from(e.local_min), Vec3::from(e.local_max)),
            },
            HISTENCIL_ENTITY_PARTICLES => {
                let layout = match e.particle_layout {
                    HISTENCIL_PARTICLES_BILLBOARD => ParticleLayout::Billboard,
                    HISTENCIL_PARTICLES_SLICES => ParticleLayout::Slices { count: e.slices },
                    HISTENCIL_PARTICLES_AUTO => ParticleLayout::Auto,
                    HISTENCIL_PARTICLES_DUST => ParticleLayout::Dust,
                    HISTENCIL_PARTICLES_RIBBON => ParticleLayout::Ribbon,
                    other => {
                        return Err(Failure::invalid(format!(
                            "{at}.particle_layout is {other}, not a HISTENCIL_PARTICLES_* value"
                        )))
                    }
                };
                let range = next_range.next().expect("one range per particle system");
                let particles = &particles[range];
                AlphaEntityKind::Particles { layout, particles }
            }
            other => {
                return Err(Failure::invalid(format!(
                    "{at}.kind is {other}, not a HISTENCIL_ENTITY_* value"
                )))
            }
        };
        // SAFETY: the header's contract: a NUL-terminated name, `param_count` parameters.
        let (name, params) = unsafe {
            (
                utf8(e.brdf_name, &format!("{at}.brdf_name"))?,
                slice(e.params, e.param_count, &format!("{at}.params"))?,
            )
        };
        let material = Material::new(brdf_of(modules, name, params)?, Vec3::from(e.tint));
        out.push(AlphaEntity {
            kind,
            material,
            opacity: e.opacity,
        });
    }
    Ok(out)
}

/// Plans the frame's entities' regions of `atlas` (each entity's slices and texels from the CPU
/// error estimate at `viewport_height`, halved where the atlas is full) and lights them into
/// it, after clearing it to black; with a non-null `direction`, also the direction map (the
/// lightmaps were made with its format). Leaves each image's state in it for the engine's next
/// barrier. The entity records the alpha shader reads are in `histencil_lightmaps_entity_buffer`.
/// Nothing is submitted; on an error nothing is recorded.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle, a null pointer, a wrong `size`, an
/// unknown entity kind or particle layout, a mesh index past its vertices; `BAD_FRAME` for a
/// slot past `frames_in_flight`, an entity, light or view histencil cannot light (the message
/// names it), an atlas of another format, too small for the regions even halved, or without
/// `COLOR_ATTACHMENT`; `BAD_SETUP` for a BRDF the shaders' set lacks or parameters out of range;
/// `IN_FLIGHT` for a slot recorded and not declared finished.
///
/// Cannot be checked: as `histencil_lighting_record` (a recording command buffer outside a
/// render pass, images that are what they say, in the states they say).
///
/// Thread safety: not at the same time as another call on `lightmaps`.
///
/// # Safety
/// `frame` and `atlas` are null or point at live structs whose pointers hold what they say;
/// `direction` is null or points at a live image.
#[no_mangle]
pub unsafe extern "C" fn histencil_lightmaps_record(
    lightmaps: *mut HistencilLightmaps,
    command_buffer: vk::CommandBuffer,
    frame: *const HistencilLightmapFrame,
    atlas: *mut HistencilImage,
    direction: *mut HistencilImage,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        let held = unsafe { handles::get(lightmaps, Kind::Lightmaps, "lightmaps") }?;
        // SAFETY: this fn's # Safety.
        let frame = unsafe { required(frame, "frame") }?;
        // SAFETY: this fn's # Safety: null or live and writable.
        let c_atlas = unsafe { atlas.as_mut() }.ok_or_else(|| Failure::invalid("atlas is null"))?;
        // SAFETY: as above.
        let c_direction = unsafe { direction.as_mut() };
        if command_buffer == vk::CommandBuffer::null() {
            return Err(Failure::invalid("command_buffer is VK_NULL_HANDLE"));
        }
        check_size::<HistencilLightmapFrame>("HistencilLightmapFrame", frame.size)?;
        if frame.entity_count > MAX_ENTITIES {
            return Err(Failure::invalid(format!(
                "HistencilLightmapFrame.entity_count is {}, past {MAX_ENTITIES}",
                frame.entity_count
            )));
        }
        // SAFETY: the header's contract: `light_count` lights, `entity_count` entities.
        let c_entities = unsafe {
            lights_into(
                frame.lights,
                frame.light_count,
                "HistencilLightmapFrame",
                &mut held.lights,
            )?;
            slice(
                frame.entities,
                frame.entity_count,
                "HistencilLightmapFrame.entities",
            )?
        };
        let mut atlas_ref = c_atlas.to_ref(|| "atlas".into())?;
        let mut direction_ref = match &c_direction {
            Some(d) => Some(d.to_ref(|| "direction".into())?),
            None => None,
        };
        // SAFETY: the header's contract for every entity's pointers.
        let entities = unsafe {
            entities_of(
                c_entities,
                held.modules,
                &mut held.meshes,
                &mut held.particles,
            )
        }?;
        let view = frame.view.to_view();
        let viewer = Viewer::from_view(&view).ok_or_else(|| {
            bad_frame("the view's world-to-view matrix cannot be inverted".into())
        })?;
        let plan = plan_entities(
            &entities,
            &viewer,
            &held.lights,
            frame.viewport_height,
            atlas_ref.extent.width.min(atlas_ref.extent.height),
            &ChoiceSettings::default(),
        )
        .map_err(|e| bad_frame(e.to_string()))?;
        let rust_frame = LightmapFrame {
            slot: frame.slot,
            view: &view,
            lights: &held.lights,
            entities: &entities,
            layout: &plan.layout,
            timestamps: false,
        };
        // SAFETY: the header's contract for this call is `record`'s # Safety.
        unsafe {
            match &mut direction_ref {
                Some(d) => held.lightmaps.record_directional(
                    command_buffer,
                    &rust_frame,
                    &mut atlas_ref,
                    d,
                ),
                None => held
                    .lightmaps
                    .record(command_buffer, &rust_frame, &mut atlas_ref),
            }
        }?;
        c_atlas.left_as(&atlas_ref);
        if let (Some(c), Some(d)) = (c_direction, &direction_ref) {
            c.left_as(d);
        }
        Ok(())
    })
}

/// Writes the storage buffer of `slot`'s entity records (what the last frame recorded through
/// `slot` wrote, one `AlphaEntityRecord` per entity in the frame's order: the alpha shader's
/// `lightmap_sample.glsl` reads it) into `buffer`.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle or a null `buffer`; `BAD_FRAME` for a
/// slot past `frames_in_flight`.
///
/// Thread safety: not at the same time as another call on `lightmaps`.
///
/// # Safety
/// `buffer` is null or writable.
#[no_mangle]
pub unsafe extern "C" fn histencil_lightmaps_entity_buffer(
    lightmaps: *mut HistencilLightmaps,
    slot: u32,
    buffer: *mut vk::Buffer,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        let held = unsafe { handles::get(lightmaps, Kind::Lightmaps, "lightmaps") }?;
        if buffer.is_null() {
            return Err(Failure::invalid("buffer is null"));
        }
        let found = held.lightmaps.entity_buffer(slot).ok_or_else(|| {
            bad_frame(format!(
                "slot {slot} is past the lightmaps' {} frames in flight",
                held.lightmaps.desc().frames_in_flight
            ))
        })?;
        // SAFETY: checked non-null; writable by this fn's # Safety.
        unsafe { buffer.write(found) };
        Ok(())
    })
}

/// Says the GPU has finished the frame last recorded into `slot`, as
/// `histencil_lighting_slot_finished` does for a lighting.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle; `BAD_FRAME` for a slot past
/// `frames_in_flight`.
///
/// Thread safety: not at the same time as another call on `lightmaps`.
///
/// # Safety
/// Every command buffer that recorded `slot` through these lightmaps has finished executing, or
/// will never be submitted.
#[no_mangle]
pub unsafe extern "C" fn histencil_lightmaps_slot_finished(
    lightmaps: *mut HistencilLightmaps,
    slot: u32,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        let held = unsafe { handles::get(lightmaps, Kind::Lightmaps, "lightmaps") }?;
        // SAFETY: this fn's # Safety is `slot_finished`'s.
        unsafe { held.lightmaps.slot_finished(slot) }?;
        Ok(())
    })
}

/// Frees the lightmaps. Refused with `IN_FLIGHT` while a slot is not declared finished: they
/// stay whole and usable.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle; `IN_FLIGHT` as above.
///
/// Thread safety: not at the same time as another call on `lightmaps`.
///
/// # Safety
/// `lightmaps` is null or a handle from `histencil_lightmaps_create` (a freed one is refused).
#[no_mangle]
pub unsafe extern "C" fn histencil_lightmaps_destroy(
    lightmaps: *mut HistencilLightmaps,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        let held = unsafe { handles::get(lightmaps, Kind::Lightmaps, "lightmaps") }?;
        // Refused before the handle is taken, so the lightmaps stay whole.
        crate::refuse_destroy_in_flight(
            held.lightmaps.in_flight(),
            "histencil_lightmaps_slot_finished",
        )?;
        // SAFETY: as above.
        let held = unsafe { handles::take(lightmaps, Kind::Lightmaps, "lightmaps") }?;
        held.lightmaps
            .destroy()
            .map_err(|refused| Failure::from(refused.error))?;
        Ok(())
    })
}
