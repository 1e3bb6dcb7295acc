//! Hi-stencil emulation: a coarse surface with one "may pass" flag per tile.
//!
//! Model of the hardware, chosen to be conservative where the hardware is and stale where it is:
//! - a write-enabled draw re-evaluates every tile it covers: the tile may pass when *any* pixel
//!   of the tile passes the hi-stencil compare on its current stencil value. The result goes to
//!   the *pending* surface;
//! - a test-enabled draw rejects every fragment in a tile that the *active* surface marks as
//!   failing;
//! - a flush copies pending to active. The update is asynchronous: without a flush, a write
//!   becomes active only when the next write-enabled draw starts (the latest point hardware
//!   could retire it). So a test after an unflushed write sees the state of the write before,
//!   which is what `FlushPolicy::Never` exposes.

/// Counts of the emulation, summed over a run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TileStats {
    /// Tiles covered by hi-stencil-testing draws (once per draw).
    pub tiles_tested: u64,
    /// Of those, tiles the active surface rejected.
    pub tiles_culled: u64,
    /// Fragments that ran a light shader (passed every test of a colour-writing pass).
    pub fragments_shaded: u64,
    /// Hi-stencil flushes run (pending state made active).
    pub flushes: u64,
}

/// The coarse surface.
#[derive(Clone, Debug)]
pub struct TileSurface {
    tile_size: u32,
    tiles_x: u32,
    tiles_y: u32,
    pending: Vec<bool>,
    active: Vec<bool>,
    unflushed: bool,
}

impl TileSurface {
    /// A surface over `width` x `height` pixels; every tile may pass (a cleared surface).
    ///
    /// # Panics
    /// If `tile_size` is zero.
    pub fn new(width: u32, height: u32, tile_size: u32) -> Self {
        assert!(tile_size > 0, "tile size must be positive");
        let tiles_x = width.div_ceil(tile_size);
        let tiles_y = height.div_ceil(tile_size);
        let count = (tiles_x * tiles_y) as usize;
        Self {
            tile_size,
            tiles_x,
            tiles_y,
            pending: vec![true; count],
            active: vec![true; count],
            unflushed: false,
        }
    }

    /// Side of a tile in pixels.
    pub fn tile_size(&self) -> u32 {
        self.tile_size
    }

    /// Tiles over the surface, row by row.
    pub fn tile_count(&self) -> usize {
        self.active.len()
    }

    /// The tile holding pixel (x, y).
    pub fn tile_of(&self, x: u32, y: u32) -> usize {
        ((y / self.tile_size) * self.tiles_x + x / self.tile_size) as usize
    }

    /// Pixel rectangle `[x0, x1) x [y0, y1)` of a tile, clipped to the surface.
    pub fn tile_pixels(&self, tile: usize, width: u32, height: u32) -> (u32, u32, u32, u32) {
        let tx = tile as u32 % self.tiles_x;
        let ty = tile as u32 / self.tiles_x;
        debug_assert!(ty < self.tiles_y);
        let x0 = tx * self.tile_size;
        let y0 = ty * self.tile_size;
        (
            x0,
            y0,
            (x0 + self.tile_size).min(width),
            (y0 + self.tile_size).min(height),
        )
    }

    /// Whether the active surface lets fragments of `tile` through.
    pub fn passes(&self, tile: usize) -> bool {
        self.active[tile]
    }

    /// Starts a write-enabled draw: retires an unflushed earlier write (see the module doc).
    pub fn begin_write(&mut self) {
        if self.unflushed {
            self.active.copy_from_slice(&self.pending);
        }
        self.unflushed = true;
    }

    /// Records the evaluated compare of a covered tile into pending state.
    pub fn write(&mut self, tile: usize, may_pass: bool) {
        self.pending[tile] = may_pass;
    }

    /// Makes the pending surface active: what a hi-stencil flush does on the hardware.
    pub fn flush(&mut self) {
        self.active.copy_from_slice(&self.pending);
        self.unflushed = false;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_unflushed_write_is_invisible_until_the_next_write() {
        let mut s = TileSurface::new(16, 8, 8);
        s.begin_write();
        s.write(1, false);
        assert!(s.passes(1), "stale before a flush");
        s.begin_write();
        assert!(!s.passes(1), "retired by the next write");
        s.write(1, true);
        s.flush();
        assert!(s.passes(1));
    }

    #[test]
    fn partial_tiles_at_the_edge() {
        let s = TileSurface::new(10, 3, 4);
        assert_eq!(s.tile_count(), 3);
        assert_eq!(s.tile_of(9, 2), 2);
        assert_eq!(s.tile_pixels(2, 10, 3), (8, 0, 10, 3));
    }
}
