//! A labelled contact sheet: frames side by side in a grid, each under a caption, so a person
//! can see what a run did instead of reading it. Also the stencil byte split into its fields,
//! in false colour, for the demo to put on it.

use crate::plot::text_available;
use histencil_model::StencilLayout;
use image::{GrayImage, Rgb, RgbImage, RgbaImage};
use plotters::prelude::*;

/// Height of the caption band above each tile, in pixels.
const CAPTION: u32 = 30;
const GAP: u32 = 6;

/// Lays `tiles` (captions and same-size frames) out in rows of `columns`, each frame under its
/// caption, on a dark background. Captions need a font ([`text_available`]); without one the
/// bands stay empty.
///
/// # Panics
/// If `tiles` is empty or the frames differ in size: a caller bug.
pub fn contact_sheet(tiles: &[(String, RgbaImage)], columns: usize) -> RgbImage {
    let (w, h) = tiles[0].1.dimensions();
    assert!(tiles.iter().all(|(_, t)| t.dimensions() == (w, h)));
    let columns = columns.clamp(1, tiles.len()) as u32;
    let rows = (tiles.len() as u32).div_ceil(columns);
    let (cell_w, cell_h) = (w + GAP, h + CAPTION + GAP);
    let mut sheet = RgbImage::from_pixel(columns * cell_w + GAP, rows * cell_h + GAP, Rgb([24; 3]));
    let origin = |i: usize| {
        let i = i as u32;
        (GAP + (i % columns) * cell_w, GAP + (i / columns) * cell_h)
    };
    for (i, (_, tile)) in tiles.iter().enumerate() {
        let (x0, y0) = origin(i);
        for (x, y, p) in tile.enumerate_pixels() {
            sheet.put_pixel(x0 + x, y0 + CAPTION + y, Rgb([p.0[0], p.0[1], p.0[2]]));
        }
    }
    if text_available() {
        let (sw, sh) = sheet.dimensions();
        let mut raw = sheet.into_raw();
        {
            let area = BitMapBackend::with_buffer(&mut raw, (sw, sh)).into_drawing_area();
            let style = ("sans-serif", 20).into_font().color(&WHITE);
            for (i, (caption, _)) in tiles.iter().enumerate() {
                let (x0, y0) = origin(i);
                // A caption that cannot be drawn leaves its band empty; the frame is the point.
                let _ = area.draw(&Text::new(
                    caption.clone(),
                    (x0 as i32 + 4, y0 as i32 + 5),
                    style.clone(),
                ));
            }
            let _ = area.present();
        }
        sheet = RgbImage::from_raw(sw, sh, raw).expect("the buffer keeps its size");
    }
    sheet
}

/// The stencil byte in false colour, one field per channel: red where the culling bit is set
/// (it must be clear after lighting), green brighter with the BRDF slot (dim green for slot 0,
/// so surfaces of the first BRDF still show), blue where any engine (preserved) bit is set.
/// `surface` says which pixels hold a surface (row-major); the others are black.
pub fn stencil_colours(stencil: &GrayImage, layout: &StencilLayout, surface: &[bool]) -> RgbaImage {
    let slots = layout.brdfs_in_use().max(1);
    RgbaImage::from_fn(stencil.width(), stencil.height(), |x, y| {
        let v = stencil.get_pixel(x, y).0[0];
        let on = |set: bool| if set { 255 } else { 0 };
        let red = on(v & layout.culling_mask() != 0);
        let blue = on(v & layout.preserved_mask() != 0);
        let green = if surface[(y * stencil.width() + x) as usize] {
            (60 + 195 * layout.brdf_slot(v) / (slots - 1).max(1)).min(255) as u8
        } else {
            0
        };
        image::Rgba([red, green, blue, 255])
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stencil_fields_get_their_own_channels() {
        let layout = StencilLayout::new(3, 0).unwrap(); // culling 0x01, BRDF 0x06
        let stencil = GrayImage::from_raw(4, 1, vec![0x00, 0x02, 0x04 | 0xA0, 0x01]).unwrap();
        let c = stencil_colours(&stencil, &layout, &[false, true, true, true]);
        assert_eq!(c.get_pixel(0, 0).0, [0, 0, 0, 255]);
        let (slot1, slot2) = (c.get_pixel(1, 0).0, c.get_pixel(2, 0).0);
        assert!(slot2[1] > slot1[1] && slot1[1] > 0 && slot1[2] == 0);
        assert_eq!(slot2[2], 255, "engine bits in blue");
        assert_eq!(c.get_pixel(3, 0).0[0], 255, "culling bit in red");
    }

    #[test]
    fn the_sheet_holds_every_tile_under_its_caption() {
        let red = RgbaImage::from_pixel(5, 4, image::Rgba([255, 0, 0, 255]));
        let blue = RgbaImage::from_pixel(5, 4, image::Rgba([0, 0, 255, 255]));
        let tiles = [
            ("a".to_owned(), red.clone()),
            ("b".to_owned(), blue),
            ("c".to_owned(), red),
        ];
        let sheet = contact_sheet(&tiles, 2);
        assert_eq!(
            sheet.dimensions(),
            (2 * (5 + GAP) + GAP, 2 * (4 + CAPTION + GAP) + GAP)
        );
        let at = |i: u32, x: u32, y: u32| {
            let (cx, cy) = (
                GAP + (i % 2) * (5 + GAP),
                GAP + (i / 2) * (4 + CAPTION + GAP),
            );
            sheet.get_pixel(cx + x, cy + CAPTION + y).0
        };
        assert_eq!(at(0, 0, 0), [255, 0, 0]);
        assert_eq!(at(1, 4, 3), [0, 0, 255]);
        assert_eq!(at(2, 2, 2), [255, 0, 0]);
    }
}
