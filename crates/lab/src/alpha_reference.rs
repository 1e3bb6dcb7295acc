//! What an alpha-lit frame is measured against.

use crate::measure::frame;
use crate::Result;
use histencil_vk::{masked_error, AlphaMode, Context, FrameDesc, MaskedError, Renderer, Shading};
use image::RgbaImage;

/// The frame with forward-lit alpha entities (the reference), and the scene without them: where
/// the two differ is where the entities cover the frame.
pub struct AlphaReference {
    pub forward: RgbaImage,
    pub background: RgbaImage,
}

impl AlphaReference {
    /// Renders both with `shading` for the opaque scene.
    pub fn render(
        ctx: &Context,
        renderer: &mut Renderer,
        shading: impl Into<Shading>,
    ) -> Result<Self> {
        let shading = shading.into();
        let forward_alpha = FrameDesc {
            alpha: AlphaMode::Forward,
            ..shading.into()
        };
        let forward = frame(renderer, forward_alpha)?;
        let mut without =
            Renderer::with_desc(ctx, renderer.scene().without_alpha(), renderer.desc())?;
        let background = frame(&mut without, shading)?;
        Ok(Self {
            forward,
            background,
        })
    }

    /// `lit`'s error over the pixels the alpha entities cover (`lit` is a frame of the same
    /// renderer, so of the same size).
    pub fn error(&self, lit: &RgbaImage) -> MaskedError {
        masked_error(lit, &self.forward, &self.background).expect("frames of one renderer")
    }
}
