//! Evaluates BRDF cases on the GPU with the GLSL spelling (`crates/vk/shaders/brdf_eval.comp`), so the
//! shipping shader code can be held to the f64 reference. One dispatch per call.

use crate::gpu::device::context::Context;
use crate::gpu::device::descriptors::{binding, BindingDesc, BindingKind};
use crate::gpu::device::error::Result;
use crate::gpu::encoder::compute::{pad, CaseKernel};
use crate::shaders;
use histencil_brdf::{Brdf, Parts, V3};

/// The BRDF evaluator's cases (read) and results (written); see `brdf_eval.rs`.
pub(crate) const BRDF_EVAL_SET: &[BindingDesc] = &[
    binding(0, BindingKind::StorageBuffer, "cases"),
    binding(1, BindingKind::StorageBuffer, "results"),
];

/// std430 mirror of `BrdfCase` in `crates/vk/shaders/brdf_eval.comp`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct GpuBrdfCase {
    model: [u32; 4],
    params: [f32; 4],
    /// A surface colour in xyz, and w 1 to evaluate the value of a surface of that colour
    /// (`brdf_eval_tinted`) instead of the two parts.
    tint: [f32; 4],
    n: [f32; 4],
    t: [f32; 4],
    v: [f32; 4],
    l: [f32; 4],
}

/// A BRDF, a surface colour and directions `[N, T, V, L]`: one case of
/// [`BrdfEvaluator::evaluate_tinted`].
pub type TintedCase = (Brdf, [f32; 3], [V3<f32>; 4]);

fn case(brdf: &Brdf, tint: Option<[f32; 3]>, [n, t, v, l]: &[V3<f32>; 4]) -> GpuBrdfCase {
    let tint = tint.map_or([0.0; 4], |[r, g, b]| [r, g, b, 1.0]);
    GpuBrdfCase {
        model: [brdf.model_index(), 0, 0, 0],
        params: brdf.packed_params().map(|p| p as f32),
        tint,
        n: pad(*n),
        t: pad(*t),
        v: pad(*v),
        l: pad(*l),
    }
}

/// The BRDF evaluation kernel; buffers are made per call.
pub struct BrdfEvaluator {
    kernel: CaseKernel,
}

impl BrdfEvaluator {
    /// Makes the compute pipeline that runs `brdf_eval.comp`.
    pub fn new(ctx: &Context) -> Result<Self> {
        Self::with_module(ctx, shaders::BRDF_EVAL_COMP)
    }

    /// As [`BrdfEvaluator::new`], with `brdf_eval.comp` compiled for a BRDF set
    /// ([`crate::BrdfModules::brdf_eval`]): it evaluates the set's engine BRDFs too.
    pub fn with_module(ctx: &Context, spirv: &'static [u8]) -> Result<Self> {
        let kernel = CaseKernel::new(ctx, "brdf-eval", BRDF_EVAL_SET, ("brdf-eval-comp", spirv))?;
        Ok(Self { kernel })
    }

    /// `f_r * cos(theta_L)` of each case in its two parts, `tint * tinted + white`
    /// ([`histencil_brdf::Parts`]; scalar models repeat their value in the tinted channels). An
    /// engine BRDF whose function takes the tint has no parts: it gives a white surface's value
    /// as `tinted` and 0 as `white`, which no other tint scales; use
    /// [`BrdfEvaluator::evaluate_tinted`] for it.
    pub fn evaluate(
        &self,
        ctx: &Context,
        cases: &[(Brdf, [V3<f32>; 4])],
    ) -> Result<Vec<Parts<f32>>> {
        let gpu: Vec<GpuBrdfCase> = cases
            .iter()
            .map(|(brdf, dirs)| case(brdf, None, dirs))
            .collect();
        let values = self
            .kernel
            .run(ctx, bytemuck::cast_slice(&gpu), gpu.len() as u32, &[])?;
        Ok(values.into_iter().map(Parts::from_channels).collect())
    }

    /// `f_r * cos(theta_L)` of each case's surface of colour `tint`, as every technique
    /// shades it (`brdf_eval_tinted`): the only spelling of an engine BRDF whose function takes
    /// the tint, which has no parts.
    pub fn evaluate_tinted(&self, ctx: &Context, cases: &[TintedCase]) -> Result<Vec<[f32; 3]>> {
        let gpu: Vec<GpuBrdfCase> = cases
            .iter()
            .map(|(brdf, tint, dirs)| case(brdf, Some(*tint), dirs))
            .collect();
        let values = self
            .kernel
            .run(ctx, bytemuck::cast_slice(&gpu), gpu.len() as u32, &[])?;
        Ok(values.into_iter().map(|[r, g, b, _]| [r, g, b]).collect())
    }

    /// Frees the pipeline and its layouts; call it once, before the context goes.
    pub fn destroy(&mut self, ctx: &Context) {
        self.kernel.destroy(ctx);
    }
}
