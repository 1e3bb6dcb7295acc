//! An opt-in check of the stencil an engine's G-buffer pass wrote, before lighting reads it.
//!
//! histencil cannot see the engine's G-buffer pass, and a stencil bit written where histencil
//! keeps its own gives a wrong frame with no error anywhere: an engine that wrote bit 5 (the
//! culling bit of its layout) got a frame 200/255 off forward and no validation message. The
//! check copies the stencil out between the G-buffer pass and the lighting and counts, once the
//! frame has finished, the pixels whose stencil breaks the layout: the culling bit set (it must
//! be 0 when lighting starts), a BRDF field naming no slot, and bits nobody declared (free bits
//! histencil may zero). It is a debug aid: a copy of the stencil per frame that asks for it.

use crate::gpu::access::ImageRef;
use crate::gpu::device::context::Context;
use crate::gpu::device::error::{Error, Result};
use crate::gpu::device::resources::Buffer;
use crate::gpu::device::teardown::free_or_retire;
use crate::gpu::encoder::recording::Recording;
use ash::vk;
use histencil_model::StencilLayout;
use std::fmt;
use std::ops::Deref;

/// What the stencil held when lighting was to start, against the layout.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StencilReport {
    /// Pixels checked.
    pub pixels: u64,
    /// The culling bit's index, and the pixels that have it set.
    pub culling_bit: (u8, u64),
    /// Each BRDF field value that names no slot of the layout, with its pixels.
    pub unknown_slots: Vec<(u8, u64)>,
    /// Each bit neither histencil's nor declared the engine's, with the pixels that have it set.
    pub undeclared_bits: Vec<(u8, u64)>,
}

impl StencilReport {
    /// Whether every pixel's stencil fits the layout.
    pub fn is_clean(&self) -> bool {
        self.culling_bit.1 == 0 && self.unknown_slots.is_empty() && self.undeclared_bits.is_empty()
    }

    /// Counts `stencil` (one byte per pixel) against `layout`.
    pub fn of(layout: &StencilLayout, stencil: &[u8]) -> Self {
        let mut counts = [0u64; 256];
        for &s in stencil {
            counts[usize::from(s)] += 1;
        }
        let culling = layout.culling_mask();
        let declared = culling | layout.brdf_mask() | layout.engine_mask();
        let count_where = |test: &dyn Fn(u8) -> bool| -> u64 {
            (0..=255u8)
                .filter(|&s| test(s))
                .map(|s| counts[usize::from(s)])
                .sum()
        };
        let mut unknown_slots = Vec::new();
        if layout.has_brdf_bits() {
            let field_values = 1u32 << layout.brdf_bits();
            for value in layout.brdfs_in_use()..field_values {
                let raw = (value << layout.brdf_shift()) as u8;
                let n = count_where(&|s| s & layout.brdf_mask() == raw);
                if n > 0 {
                    unknown_slots.push((value as u8, n));
                }
            }
        }
        let undeclared_bits = (0..8u8)
            .filter(|b| declared & (1 << b) == 0)
            .map(|b| (b, count_where(&|s| s & (1 << b) != 0)))
            .filter(|(_, n)| *n > 0)
            .collect();
        StencilReport {
            pixels: stencil.len() as u64,
            culling_bit: (
                culling.trailing_zeros() as u8,
                count_where(&|s| s & culling != 0),
            ),
            unknown_slots,
            undeclared_bits,
        }
    }
}

impl fmt::Display for StencilReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_clean() {
            return write!(
                f,
                "the stencil of all {} pixels fits the layout",
                self.pixels
            );
        }
        let mut parts = Vec::new();
        let (bit, n) = self.culling_bit;
        if n > 0 {
            parts.push(format!(
                "{n} pixels have histencil's culling bit (bit {bit}) set, which must be 0 when \
                 lighting starts: the G-buffer pass writes it only through the write mask of \
                 gbuffer_stencil_reference"
            ));
        }
        for (value, n) in &self.unknown_slots {
            parts.push(format!(
                "{n} pixels have BRDF field value {value}, which names no BRDF slot"
            ));
        }
        for (bit, n) in &self.undeclared_bits {
            parts.push(format!(
                "{n} pixels have bit {bit} set, which neither histencil nor the engine declared \
                 (the 360-like platform zeroes it: declare it among the engine's bits)"
            ));
        }
        write!(f, "of {} pixels: {}", self.pixels, parts.join("; "))
    }
}

/// A readback of the stencil for [`StencilReport`], recorded into an engine's frame between its
/// G-buffer pass and the lighting.
pub struct StencilCheck<C: Deref<Target = Context>> {
    ctx: C,
    layout: StencilLayout,
    extent: vk::Extent2D,
    buffer: Buffer,
    /// A copy recorded and not yet read: the GPU may still write the buffer.
    recorded: bool,
}

impl<C: Deref<Target = Context>> StencilCheck<C> {
    /// A check of `layout` (the lighting's: `DeferredLighting::desc().layout`) for targets of
    /// `extent`: one host-readable byte per pixel.
    ///
    /// # Errors
    /// A zero extent, and allocation errors.
    pub fn new(ctx: C, layout: StencilLayout, extent: vk::Extent2D) -> Result<Self> {
        let pixels = u64::from(extent.width) * u64::from(extent.height);
        if pixels == 0 {
            return Err(Error::BadSetup("a stencil check of a zero extent".into()));
        }
        let buffer = Buffer::readback(&ctx, "stencil-check", pixels)?;
        Ok(StencilCheck {
            ctx,
            layout,
            extent,
            buffer,
            recorded: false,
        })
    }

    /// Records a copy of `depth_stencil`'s stencil, as the engine's G-buffer pass left it, into
    /// the check's buffer, and leaves `depth_stencil.state` where the copy left it (the
    /// lighting's barrier starts from there).
    ///
    /// # Errors
    /// [`Error::BadFrame`] for an image of another extent, without a stencil aspect or without
    /// `TRANSFER_SRC` usage; [`Error::InFlight`] while the last copy was not read.
    ///
    /// # Safety
    /// As `DeferredLighting::record`: `cmd` is recording outside any render pass on the check's
    /// device, `depth_stencil` is live with the usage and state it says.
    pub unsafe fn record(
        &mut self,
        cmd: vk::CommandBuffer,
        depth_stencil: &mut ImageRef,
    ) -> Result<()> {
        if self.recorded {
            return Err(Error::InFlight(
                "the last stencil copy was not read: read it (after the frame's fence) first"
                    .into(),
            ));
        }
        if depth_stencil.extent != self.extent {
            return Err(Error::BadFrame(format!(
                "the depth-stencil image is {}x{}, the check {}x{}",
                depth_stencil.extent.width,
                depth_stencil.extent.height,
                self.extent.width,
                self.extent.height
            )));
        }
        if !depth_stencil
            .aspect()
            .contains(vk::ImageAspectFlags::STENCIL)
        {
            return Err(Error::BadFrame(format!(
                "the depth-stencil image's format {:?} has no stencil",
                depth_stencil.format
            )));
        }
        if !depth_stencil
            .usage
            .contains(vk::ImageUsageFlags::TRANSFER_SRC)
        {
            return Err(Error::BadFrame(
                "the depth-stencil image was made without TRANSFER_SRC usage, which the \
                 stencil check copies it with"
                    .into(),
            ));
        }
        let ctx: &Context = &self.ctx;
        // SAFETY: this fn's # Safety is `Recording::new`'s.
        let recording = unsafe { Recording::new(ctx, cmd) };
        recording.step("stencil-check", |rec| {
            rec.copy_image_to_buffer(depth_stencil, vk::ImageAspectFlags::STENCIL, &self.buffer);
            rec.host_readable(vk::PipelineStageFlags2::COPY);
        });
        self.recorded = true;
        Ok(())
    }

    /// The report of the last copy.
    ///
    /// # Errors
    /// [`Error::BadFrame`] when no copy was recorded since the last read.
    ///
    /// # Safety
    /// The command buffer of the last [`StencilCheck::record`] has finished executing.
    pub unsafe fn read(&mut self) -> Result<StencilReport> {
        if !self.recorded {
            return Err(Error::BadFrame(
                "no stencil copy was recorded to read".into(),
            ));
        }
        self.recorded = false;
        Ok(StencilReport::of(&self.layout, self.buffer.read()))
    }
}

impl<C: Deref<Target = Context>> Drop for StencilCheck<C> {
    /// Frees the buffer, or leaves it to the context while a copy may still be pending.
    fn drop(&mut self) {
        let mut buffer = std::mem::take(&mut self.buffer);
        free_or_retire(&self.ctx, self.recorded, move |ctx| buffer.destroy(ctx));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_report_names_the_culling_bit_unknown_slots_and_undeclared_bits() {
        // Five BRDFs: culling bit 0, BRDF field bits 1 to 3, the engine's bits 4 and 5.
        let layout = StencilLayout::new(5, 2).unwrap();
        let clean = [0x00, 0x02, 0x08, 0x30];
        assert!(StencilReport::of(&layout, &clean).is_clean());
        // Only bits 4 and 5 were asked for; 6 and 7 are the engine's too in the talk's layout.
        let bad = [0x01, 0x01, 0x0c, 0x0e, 0x02];
        let report = StencilReport::of(&layout, &bad);
        assert_eq!(report.culling_bit, (0, 2));
        assert_eq!(report.unknown_slots, vec![(6, 1), (7, 1)]);
        let text = report.to_string();
        assert!(
            text.contains("2 pixels have histencil's culling bit (bit 0)"),
            "{text}"
        );
        assert!(text.contains("BRDF field value 6"), "{text}");
    }
}
