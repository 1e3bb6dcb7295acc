//! What a lightmap frame must fit to be recorded: its entities' regions, lights and atlas, held
//! before anything is written or recorded.

use super::lightmaps::{AlphaLightmapsDesc, LightmapFrame};
use crate::gpu::access::ImageRef;
use crate::gpu::device::error::{Error, Result};
use ash::vk;

/// A direction map fits when these lightmaps make one, in their format, at the atlas's extent.
pub(super) fn check_direction(
    desc: &AlphaLightmapsDesc,
    atlas: &ImageRef,
    direction: &ImageRef,
) -> Result<()> {
    let Some(format) = desc.direction_format else {
        return Err(bad(
            "these lightmaps were made without a direction format (AlphaLightmapsDesc)".into(),
        ));
    };
    if !direction
        .usage
        .contains(vk::ImageUsageFlags::COLOR_ATTACHMENT)
    {
        return Err(bad(format!(
            "the direction map was made without COLOR_ATTACHMENT usage (it has {:?}), and the \
             lightmap pass clears and draws into it",
            direction.usage
        )));
    }
    if direction.format != format {
        return Err(bad(format!(
            "the direction map is {:?}, these lightmaps make {format:?}",
            direction.format
        )));
    }
    if direction.extent != atlas.extent {
        return Err(bad(format!(
            "the direction map is {}x{}, the atlas {}x{}",
            direction.extent.width,
            direction.extent.height,
            atlas.extent.width,
            atlas.extent.height
        )));
    }
    Ok(())
}

/// Checks one frame against the lightmaps and the atlas: the slot, the view and the lights,
/// each entity and its region, the atlas's format and size.
pub(super) fn check_frame(
    desc: &AlphaLightmapsDesc,
    frame: &LightmapFrame,
    atlas: &ImageRef,
    set: &histencil_brdf::BrdfSet,
) -> Result<()> {
    if !atlas.usage.contains(vk::ImageUsageFlags::COLOR_ATTACHMENT) {
        return Err(bad(format!(
            "the lightmap atlas was made without COLOR_ATTACHMENT usage (it has {:?}), and the \
             lightmap pass clears and draws into it",
            atlas.usage
        )));
    }
    if frame.slot >= desc.frames_in_flight {
        return Err(bad(format!(
            "slot {} of {} frames in flight",
            frame.slot, desc.frames_in_flight
        )));
    }
    // As the lighting's record paths: a NaN light or view lights an atlas with NaN or nothing,
    // in silence.
    if let Some(problem) = crate::frame_inputs_problem(frame.view, frame.lights) {
        return Err(bad(problem));
    }
    if atlas.format != desc.atlas_format {
        return Err(bad(format!(
            "the lightmap atlas is {:?}, the lightmaps expect {:?}",
            atlas.format, desc.atlas_format
        )));
    }
    let (w, h) = frame.layout.atlas.size();
    let e = atlas.extent;
    if e.width < w || e.height < h {
        return Err(bad(format!(
            "the lightmap atlas is {}x{}, the layout needs {w}x{h}",
            e.width, e.height
        )));
    }
    let regions = &frame.layout.regions;
    if regions.len() != frame.entities.len() {
        return Err(bad(format!(
            "{} entities and {} lightmap regions",
            frame.entities.len(),
            regions.len()
        )));
    }
    for (i, (entity, r)) in frame.entities.iter().zip(regions).enumerate() {
        if let Some(problem) = entity.problem() {
            return Err(bad(format!("alpha entity {i}: {problem}")));
        }
        // A BRDF the lightmap shaders were not compiled with would light it black in silence.
        if let Err(e) = set.check(&entity.material.brdf) {
            return Err(bad(format!("alpha entity {i}: {e}")));
        }
        let s = r.shape;
        let width = u64::from(s.columns) * u64::from(s.tile_width);
        let height = u64::from(s.tiles.div_ceil(s.columns.max(1))) * u64::from(s.tile_height);
        let fits = s.tiles >= 1
            && (1..=s.tiles).contains(&s.columns)
            && s.tile_width >= 1
            && s.tile_height >= 1
            && width <= u64::from(r.region.width)
            && height <= u64::from(r.region.height)
            && u64::from(r.region.x) + width <= u64::from(e.width)
            && u64::from(r.region.y) + height <= u64::from(e.height);
        let texels = u64::from(s.tile_width) * u64::from(s.tile_height);
        let holds_motes = match entity.desc().kind {
            histencil_alpha::EntityKind::Particles {
                layout: histencil_scene::ParticleLayout::Dust,
                count,
            } => texels >= u64::from(count),
            _ => true,
        };
        if !(fits && holds_motes) {
            return Err(bad(format!(
                "alpha entity {i}: its region {:?} ({} tiles of {}x{}, {} to a row) does not fit \
                 the atlas or its particles",
                r.region, s.tiles, s.tile_width, s.tile_height, s.columns
            )));
        }
    }
    Ok(())
}

pub(super) fn bad(message: String) -> Error {
    Error::BadFrame(message)
}

/// Bytes a baked probe takes in the probes' storage buffer (`include/alpha.glsl`'s `Probe`).
const PROBE_BYTES: u64 = 32;

/// The largest lightmap side this device holds the probes of for one translucent object: the
/// object's `side x side` probes are bound as one storage buffer, which
/// `maxStorageBufferRange` bounds (2048 at the spec's guaranteed 128 MiB), and at most
/// [`histencil_alpha::MAX_FORCED_SIDE`], which fills the largest atlas.
pub fn max_lightmap_side(ctx: &crate::Context) -> u32 {
    let probes = u64::from(ctx.max_storage_buffer_range) / PROBE_BYTES;
    let side = probes
        .isqrt()
        .min(u64::from(histencil_alpha::MAX_FORCED_SIDE));
    side as u32
}

/// Refuses a forced lightmap side past [`max_lightmap_side`], naming the device's maximum.
pub(crate) fn check_lightmap_side(ctx: &crate::Context, side: u32) -> Result<()> {
    let max = max_lightmap_side(ctx);
    if side > max {
        return Err(Error::DeviceLimit(format!(
            "lightmap resolution {side}: an object's {side}x{side} probes need {} bytes, past \
             this device's maxStorageBufferRange ({}); at most {max} on this device",
            u64::from(side).pow(2) * PROBE_BYTES,
            ctx.max_storage_buffer_range
        )));
    }
    Ok(())
}

/// Refuses a frame whose probes, all entities together, pass the device's storage-buffer range,
/// naming how many texels fit (before anything is grown or recorded).
pub(super) fn check_probe_bytes(ctx: &crate::Context, probes: usize) -> Result<()> {
    let bytes = probes as u64 * PROBE_BYTES;
    let range = u64::from(ctx.max_storage_buffer_range);
    if bytes > range {
        return Err(Error::DeviceLimit(format!(
            "the frame's translucent objects have {probes} probes ({bytes} bytes), past this \
             device's maxStorageBufferRange ({range}): at most {} texels of objects a frame \
             (smaller lightmap resolutions, or fewer objects)",
            range / PROBE_BYTES
        )));
    }
    Ok(())
}
