//! Lightmap resolution from screen coverage. Lighting on translucent surfaces and particles is
//! low-frequency (it comes from the same lights as the opaque scene, smoothed by the BRDF), so a
//! texel can cover several pixels; what must not happen is a big object on screen getting a
//! handful of probes, or a distant one wasting a large region.
//!
//! The bounds follow DOOM (2016)'s particle lighting, which gives a particle 8, 16 or 32 texels a
//! side by its size on screen; whole objects and systems here span more of the screen than one
//! particle, so the top is 128. Sides are powers of two so that a downgrade (halving) keeps
//! regions aligned to a coarser grid and the atlas fragments less.

/// Screen pixels per lightmap texel, along each axis, before clamping.
pub const PIXELS_PER_TEXEL: f32 = 4.0;
/// The smallest region side: below it bilinear probes cannot follow a light's falloff at all.
pub const MIN_SIDE: u32 = 8;
/// The largest region side.
pub const MAX_SIDE: u32 = 128;

/// The side (texels) of the square region for an entity whose bounds cover `diameter_px`
/// pixels across on screen: one texel per [`PIXELS_PER_TEXEL`] pixels, rounded up to a power of
/// two, within [`MIN_SIDE`]..=[`MAX_SIDE`]. Non-finite or negative sizes get the smallest.
pub fn side_for_coverage(diameter_px: f32) -> u32 {
    if !diameter_px.is_finite() || diameter_px <= 0.0 {
        return MIN_SIDE;
    }
    let wanted = (diameter_px / PIXELS_PER_TEXEL).ceil().min(MAX_SIDE as f32) as u32;
    wanted.max(1).next_power_of_two().clamp(MIN_SIDE, MAX_SIDE)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sides_are_bounded_powers_of_two() {
        for (px, side) in [
            (0.0, 8),
            (-3.0, 8),
            (f32::NAN, 8),
            (f32::INFINITY, 8),
            (10.0, 8),
            (33.0, 16),
            (64.0, 16),
            (65.0, 32),
            (200.0, 64),
            (500.0, 128),
            (1e9, 128),
        ] {
            assert_eq!(side_for_coverage(px), side, "{px} px");
        }
    }

    #[test]
    fn side_never_shrinks_as_coverage_grows() {
        let mut last = 0;
        for i in 0..4000 {
            let side = side_for_coverage(i as f32 * 0.5);
            assert!(side >= last && side.is_power_of_two());
            last = side;
        }
    }
}
