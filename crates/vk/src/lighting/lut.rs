//! The LUT technique's tables on the GPU: every material's [`Lut`] baked by histencil-brdf (an
//! engine BRDF's filled by its own GLSL at histencil-brdf's grid points), in one storage buffer of values with a header per table (`crates/vk/shaders/include/lut.glsl`), and an
//! evaluator that runs the GLSL lookup on chosen directions so it can be held to
//! [`Lut::lookup`].

use crate::gpu::device::context::Context;
use crate::gpu::device::descriptors::{binding, BindingDesc, BindingKind};
use crate::gpu::device::error::{Error, Result};
use crate::gpu::device::resources::Buffer;
use crate::gpu::device::teardown::{free_or_retire, InFlight};
use crate::gpu::encoder::compute::{pad, CaseKernel};
use crate::shaders;
use crate::{BrdfEvaluator, BrdfModules};
use ash::vk;
use histencil_brdf::lut::{Lut, LutAxes};
use histencil_brdf::{Brdf, Parts, V3};
use std::ops::Deref;

/// Set 3 of the light pipelines: the LUT technique's tables (include/lut.glsl), bound only by
/// the LUT light shader.
pub(crate) const LUT_SET: &[BindingDesc] = &[
    binding(0, BindingKind::StorageBuffer, ""),
    binding(1, BindingKind::StorageBuffer, ""),
];
/// The table lookup evaluator's cases, results and tables; see `lut.rs`.
pub(crate) const LUT_EVAL_SET: &[BindingDesc] = &[
    binding(0, BindingKind::StorageBuffer, ""),
    binding(1, BindingKind::StorageBuffer, ""),
    binding(2, BindingKind::StorageBuffer, ""),
    binding(3, BindingKind::StorageBuffer, ""),
];

/// std430 mirror of `LutTable` in `crates/vk/shaders/include/lut.glsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuLutTable {
    axes: u32,
    resolution: u32,
    /// The table's first float in the values buffer.
    offset: u32,
    curvature: f32,
    /// Floats per grid point: 3 (tinted RGB), 4 with the white part after them.
    channels: u32,
}

/// One table per material, baked at one resolution and uploaded. `C` holds the context:
/// `&Context` or `Arc<Context>` (see [`crate::DeferredLighting`]).
pub struct LutTables<C: Deref<Target = Context>> {
    ctx: C,
    luts: Vec<Lut>,
    resolution: u32,
    headers: Buffer,
    values: Buffer,
    /// From the start: any lighting may bind the tables ([`crate::DeferredLighting::set_lut_tables`]).
    in_flight: InFlight,
}

impl<C: Deref<Target = Context>> LutTables<C> {
    /// Bakes a table of `resolution` points per axis for each of `materials` (a material's
    /// index here is its table index) and uploads them: histencil's own BRDFs only
    /// ([`LutTables::with_modules`] takes an engine's).
    ///
    /// # Errors
    /// [`Error::Lut`] for a resolution histencil-brdf refuses or a material no table can hold,
    /// [`Error::LutTooLarge`] when the values exceed the device's storage-buffer range, and
    /// allocation errors.
    pub fn new(ctx: C, materials: &[Brdf], resolution: u32) -> Result<Self> {
        Self::with_modules(ctx, BrdfModules::builtin(), materials, resolution)
    }

    /// As [`LutTables::new`], for the BRDFs of `modules`' set: a built-in's table is baked from
    /// its f64 reference on the CPU, an engine BRDF's is filled on the GPU by its own GLSL
    /// (`modules.brdf_eval`) at the same grid points ([`Lut::grid`]) and read back, so that
    /// [`LutTables::luts`] holds what the GPU looks up, whoever baked it. An entry holds both
    /// factors of a BRDF with a white part (glTF's, an engine's `white`): `tint * tinted + white`.
    ///
    /// # Errors
    /// As [`LutTables::new`]; [`Error::Lut`] also for an engine BRDF the set holds no table of
    /// ([`crate::lut_refusal`]: its function takes the tint, it reads the tangent, or it lights
    /// where `N.L <= 0`), and
    /// [`Error::BrdfSet`] for a material of a BRDF the set does not hold.
    pub fn with_modules(
        ctx: C,
        modules: &'static BrdfModules,
        materials: &[Brdf],
        resolution: u32,
    ) -> Result<Self> {
        Lut::check_resolution(resolution)?;
        for b in materials {
            modules
                .set
                .check(b)
                .map_err(|e| Error::BrdfSet(e.to_string()))?;
            if let Some(why) = crate::brdf_modules::lut_refusal(&ctx, modules, b)? {
                return Err(why.into());
            }
        }
        // Before anything is baked: a table past the device's range is refused at once.
        let channels = |b: &Brdf| if modules.set.has_white_part(b) { 4 } else { 3 };
        let bytes: u64 = materials
            .iter()
            .map(|b| {
                u64::from(resolution).pow(LutAxes::of(b).dimensions() as u32) * channels(b) * 4
            })
            .sum();
        let limit = u64::from(ctx.max_storage_buffer_range);
        if bytes > limit {
            return Err(Error::LutTooLarge { bytes, limit });
        }
        let luts = bake(&ctx, modules, materials, resolution)?;
        let mut headers = Vec::with_capacity(luts.len());
        let mut values: Vec<f32> = Vec::new();
        for lut in &luts {
            headers.push(GpuLutTable {
                axes: lut.axes.index(),
                resolution,
                offset: values.len() as u32,
                curvature: lut.curvature_per_mm() as f32,
                channels: if lut.has_white() { 4 } else { 3 },
            });
            if lut.has_white() {
                for (rgb, white) in lut.values.iter().zip(&lut.white) {
                    values.extend(rgb);
                    values.push(*white);
                }
            } else {
                values.extend(lut.values.iter().flatten());
            }
        }
        let owner = ctx;
        let ctx: &Context = &owner;
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let mut headers =
            Buffer::with_data(ctx, "lut-headers", storage, bytemuck::cast_slice(&headers))?;
        let values =
            match Buffer::with_data(ctx, "lut-values", storage, bytemuck::cast_slice(&values)) {
                Ok(b) => b,
                Err(e) => {
                    headers.destroy(ctx);
                    return Err(e);
                }
            };
        let mut in_flight = InFlight::default();
        in_flight.mark();
        Ok(Self {
            ctx: owner,
            luts,
            resolution,
            headers,
            values,
            in_flight,
        })
    }

    /// The baked tables, by table index: what the GPU looks up.
    pub fn luts(&self) -> &[Lut] {
        &self.luts
    }

    /// Grid points per axis of every table, as baked.
    pub fn resolution(&self) -> u32 {
        self.resolution
    }

    /// GPU memory the values take.
    pub fn size_bytes(&self) -> usize {
        self.luts.iter().map(Lut::size_bytes).sum()
    }

    /// The headers and the values: bindings `LUT_BINDING` and `LUT_BINDING + 1` of lut.glsl.
    pub(crate) fn buffers(&self) -> [vk::Buffer; 2] {
        [self.headers.handle, self.values.handle]
    }

    /// Frees the tables now, once the engine's fences say the GPU is done (dropping them
    /// instead leaves them to the context, freed with it or at `Context::free_retired`, since
    /// any lighting may have bound them).
    ///
    /// # Safety
    /// The GPU has finished every command buffer recorded with a lighting pointed at these
    /// tables.
    pub unsafe fn destroy(mut self) {
        self.in_flight.clear();
    }
}

impl<C: Deref<Target = Context>> Drop for LutTables<C> {
    /// Frees the tables, or, unless [`LutTables::destroy`] promised the GPU is done, leaves them
    /// to the context until it is ([`Context::free_retired`], or the context's drop).
    fn drop(&mut self) {
        let mut headers = std::mem::take(&mut self.headers);
        let mut values = std::mem::take(&mut self.values);
        let free = move |ctx: &Context| {
            headers.destroy(ctx);
            values.destroy(ctx);
        };
        free_or_retire(&self.ctx, self.in_flight.any(), free);
    }
}

/// Grid points evaluated per dispatch: 112 bytes of case and 16 of result each, 128 MiB a run
/// at most, and within the case kernels' 65535 workgroups of 64.
const BAKE_BATCH: usize = 1 << 20;

/// Each material's table: a built-in's baked from its reference on the CPU, an engine BRDF's
/// evaluated at the grid points by the set's own `brdf_eval.comp` (the function every
/// technique shades with, in its two parts; a tabulable BRDF does not take the tint). The
/// evaluator is made at the first engine BRDF, so histencil's own tables touch neither pipeline
/// nor queue.
fn bake(
    ctx: &Context,
    modules: &'static BrdfModules,
    materials: &[Brdf],
    resolution: u32,
) -> Result<Vec<Lut>> {
    let mut evaluator: Option<BrdfEvaluator> = None;
    let mut on_gpu = |b: Brdf| -> Result<Lut> {
        let evaluator = match &mut evaluator {
            Some(e) => e,
            None => evaluator.insert(BrdfEvaluator::with_module(ctx, modules.brdf_eval)?),
        };
        let grid = Lut::grid(b, resolution)?;
        let mut values = Vec::with_capacity(grid.len());
        let mut white = Vec::new();
        for batch in grid.chunks(BAKE_BATCH) {
            let cases: Vec<(Brdf, [V3<f32>; 4])> = batch
                .iter()
                .map(|(dirs, at)| (*at, dirs.map(|d| d.map(|x| x as f32))))
                .collect();
            for p in evaluator.evaluate(ctx, &cases)? {
                values.push(p.tinted);
                white.push(p.white);
            }
        }
        if !modules.set.has_white_part(&b) {
            white.clear();
        }
        Ok(Lut::from_values(b, resolution, values, white)?)
    };
    let baked = materials
        .iter()
        .map(|b| match b {
            Brdf::Engine { .. } => on_gpu(*b),
            _ => Ok(Lut::bake(*b, resolution)?),
        })
        .collect();
    if let Some(mut e) = evaluator {
        e.destroy(ctx);
    }
    baked
}

/// std430 mirror of `LutCase` in `crates/vk/shaders/lut_eval.comp`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct GpuLutCase {
    table: [u32; 4],
    unused: [f32; 4],
    n: [f32; 4],
    t: [f32; 4],
    v: [f32; 4],
    l: [f32; 4],
}

/// Runs `lut_lookup` of lut.glsl, the code the LUT light shader shades with, on chosen cases.
pub struct LutEvaluator {
    kernel: CaseKernel,
}

impl LutEvaluator {
    /// Makes the compute pipeline; the tables are given per call.
    pub fn new(ctx: &Context) -> Result<Self> {
        let kernel = CaseKernel::new(
            ctx,
            "lut-eval",
            LUT_EVAL_SET,
            ("lut-eval-comp", shaders::LUT_EVAL_COMP),
        )?;
        Ok(Self { kernel })
    }

    /// Table `index`'s two factors at directions `[N, T, V, L]`, per case.
    ///
    /// # Panics
    /// If a case names a table `tables` does not have: a caller bug.
    pub fn evaluate(
        &self,
        ctx: &Context,
        tables: &LutTables<impl Deref<Target = Context>>,
        cases: &[(u32, [V3<f32>; 4])],
    ) -> Result<Vec<Parts<f32>>> {
        let gpu: Vec<GpuLutCase> = cases
            .iter()
            .map(|(table, [n, t, v, l])| {
                assert!((*table as usize) < tables.luts.len(), "no table {table}");
                GpuLutCase {
                    table: [*table, 0, 0, 0],
                    unused: [0.0; 4],
                    n: pad(*n),
                    t: pad(*t),
                    v: pad(*v),
                    l: pad(*l),
                }
            })
            .collect();
        let values = self.kernel.run(
            ctx,
            bytemuck::cast_slice(&gpu),
            gpu.len() as u32,
            &tables.buffers(),
        )?;
        Ok(values.into_iter().map(Parts::from_channels).collect())
    }

    /// Frees the pipeline and its layouts; call it once, before the context goes.
    pub fn destroy(&mut self, ctx: &Context) {
        self.kernel.destroy(ctx);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_matches_the_glsl_struct() {
        assert_eq!(std::mem::size_of::<GpuLutTable>(), 20);
        assert_eq!(std::mem::size_of::<GpuLutCase>(), 96);
        assert_eq!(
            std::mem::size_of::<crate::tools::brdf_eval::GpuBrdfCase>(),
            112
        );
    }
}
