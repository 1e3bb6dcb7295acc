//! "The talk on today's GPUs": the talk's questions re-asked of every platform, with the CPU
//! simulator as the judge. Each scene's frame is rendered on the device (its G-buffer stencil,
//! with the engine's bits 0xA0, and every light's footprint as the rasteriser made it:
//! `Renderer::simulator_inputs`), then each platform's plan runs on those inputs in the
//! simulator: the consoles' plans with their hi-stencil, the native plan bare, and the native
//! plan on the two AMD models (`histencil_model::amd`, modelled from AMD's driver sources, not
//! measured on AMD hardware). The counts are the simulator's, so they are the same on every
//! device; what a tile culled saves in time needs the hardware itself.
//!
//! Questions: do the engine's bits break culling (the 360's problem: lights lost), only weaken
//! it (fewer tiles culled), or neither; what flush or reset the platform needs; how many BRDFs
//! are culled hierarchically; and tiles tested and culled and fragments shaded per scene.

use crate::{write_file, Result};
use histencil_model::{FlushPolicy, FramePlan, TileStats};
use histencil_scene::Scene;
use histencil_vk::{Context, FrameDesc, Platform as P, Renderer, SimulatorInputs, Technique};
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The engine's bits, as in the talk's 360 story (and `demo`, `check`).
pub const ENGINE_BITS: u8 = 0xA0;

/// One row of the table: one of the renderer's platforms ([`histencil_vk::Platform`]), the
/// one vocabulary of platforms, or NVIDIA's ZCull criterion, a row of its own that runs as the
/// PS3's (a model of a GPU's hierarchy, not a platform the renderer plans for).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Row {
    Of(histencil_vk::Platform),
    /// NVIDIA's ZCull stencil criterion, assumed to cull as the PS3's (the documented fields
    /// are the RSX's; what a region stores and when is not public).
    NvidiaZcull,
}

impl Row {
    /// The table's rows, in its order: the talk's consoles, NVIDIA's criterion, AMD's two
    /// hierarchies and native Vulkan.
    pub const ALL: [Row; 7] = [
        Row::Of(P::X360NoZeroing),
        Row::Of(P::X360),
        Row::Of(P::Ps3),
        Row::NvidiaZcull,
        Row::Of(P::AmdPretest),
        Row::Of(P::AmdAndOr),
        Row::Of(P::Native),
    ];

    /// The native row, which every correct platform shades as.
    pub const NATIVE: Row = Row::Of(P::Native);

    pub fn name(self) -> &'static str {
        match self {
            Row::Of(P::X360NoZeroing) => "360-like, engine bits kept (the talk's failure)",
            Row::Of(P::X360) => "360-like, zeroing (the talk's fix)",
            Row::Of(P::X360SaveRestore) => {
                "360-like, zeroing, the engine's bits saved and restored"
            }
            Row::Of(P::Ps3) => "PS3-like",
            Row::NvidiaZcull => {
                "NVIDIA ZCull's stencil criterion (Turing to Blackwell), assumed to cull as the \
                 PS3's: its fields are the RSX's; what a region holds, and whether the driver \
                 programs it, is not public"
            }
            Row::Of(P::AmdPretest) => "amd-pretest (GFX9-11 with pretests, as PAL allows)",
            Row::Of(P::AmdAndOr) => "amd-andor (GFX12)",
            Row::Of(P::AmdAndOrUnmasked) => "amd-andor-unmasked (GFX12's tiles, read mask ignored)",
            Row::Of(P::Native) => {
                "native: no hierarchical stencil through Vulkan (AMD GFX9-11, Intel, Adreno, Mali, \
                 Apple, PowerVR; NVK)"
            }
        }
    }

    /// What the platform needs between a hierarchy write and a test, and what a change costs.
    pub fn flush_or_reset(self) -> &'static str {
        match self {
            Row::Of(P::X360NoZeroing | P::X360 | P::X360SaveRestore | P::Ps3) => {
                "a flush between each mask pass's hi-stencil write and the shade passes testing it"
            }
            Row::NvidiaZcull => {
                "as the PS3 (assumed); a criterion change invalidates unless told not to \
                 (`NO_INVALIDATE`), at a cost not public"
            }
            Row::Of(P::AmdPretest) => {
                "none within the frame (pretests bound before the G-buffer); changing one needs an \
                 initialisation barrier and a rewrite of the whole stencil"
            }
            Row::Of(P::AmdAndOr | P::AmdAndOrUnmasked) => {
                "none (updated as stencil is written); reset to the full range after any layout \
                 that does not keep it, which this frame never uses"
            }
            Row::Of(P::Native) => "none",
        }
    }

    /// How many BRDFs the hierarchy can cull by their id.
    pub fn brdfs_culled(self) -> &'static str {
        match self {
            Row::Of(P::X360NoZeroing | P::X360 | P::X360SaveRestore | P::Ps3)
            | Row::NvidiaZcull => "every BRDF a light touches (a mask pass and a flush each)",
            Row::Of(P::AmdPretest) => {
                "2 by their id (the two pretests, on the two rarest BRDFs); the others per pixel \
                 only"
            }
            Row::Of(P::AmdAndOr | P::AmdAndOrUnmasked) => {
                "any, wherever a tile's known bits contradict the BRDF's id"
            }
            Row::Of(P::Native) => "0 (per pixel only)",
        }
    }

    /// The renderer's platform this row runs as (NVIDIA's ZCull criterion as the PS3's).
    fn platform(self) -> P {
        match self {
            Row::Of(platform) => platform,
            Row::NvidiaZcull => P::Ps3,
        }
    }

    fn technique(self) -> Technique {
        Technique::Stencil {
            backend: self.platform().backend(),
            flush: FlushPolicy::Auto,
        }
    }
}

/// The simulator's counts for one platform on one scene, with and without the engine's bits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneCounts {
    pub with_bits: TileStats,
    pub without_bits: TileStats,
    /// Fragments the native plan shades with the engine's bits: what every correct platform
    /// shades.
    pub expected_fragments: u64,
    /// The same frame, with the engine's bits, rendered on the device with the platform's
    /// hierarchy emulated on the GPU (consoles' hi-stencil, AMD's tiles) and counted there:
    /// must equal `with_bits`, or the emulation and the model disagree.
    pub gpu: TileStats,
}

impl SceneCounts {
    /// "breaks" (fewer fragments shaded than the frame needs: lights lost), "weakens" (fewer
    /// tiles culled than without the bits) or "no".
    pub fn engine_bits_effect(&self) -> &'static str {
        if self.with_bits.fragments_shaded != self.expected_fragments {
            "breaks"
        } else if self.with_bits.tiles_culled < self.without_bits.tiles_culled {
            "weakens"
        } else {
            "no"
        }
    }
}

/// Every platform on every scene.
#[derive(Clone, Debug)]
pub struct TodaysGpusReport {
    pub device: String,
    pub driver: String,
    pub width: u32,
    pub height: u32,
    pub tile_size: u32,
    pub scenes: Vec<String>,
    /// Per row ([`Row::ALL`] order), per scene.
    pub counts: Vec<(Row, Vec<SceneCounts>)>,
    /// Per scene: the depth-id technique's passes (BRDFs in the frame) and what a hierarchical
    /// depth would cull of them (`histencil_model::depth_id`), with the engine's bits, from the
    /// G-buffer; then the same model on the id image the GPU wrote.
    pub depth_id: Vec<(usize, TileStats, TileStats)>,
    /// Per scene: what the native plan's draws cost Adreno's LRZ ([`LrzCost`]).
    pub lrz: Vec<LrzCost>,
}

/// What a plan's draws cost a Qualcomm Adreno's low-resolution Z (LRZ), by the rules of Mesa's
/// turnip (`src/freedreno/vulkan/tu_lrz.cc`): a draw that writes stencil runs without the LRZ
/// test (and, writing depth too, would leave LRZ invalid for the rest of the render pass); a
/// draw that tests stencil with a compare other than ALWAYS writes no LRZ. The light passes
/// write no depth, so what the talk's technique costs an Adreno is the test on its mask draws.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LrzCost {
    /// Light-volume and full-screen draws in the plan.
    pub draws: usize,
    /// Draws that write stencil: no LRZ test for them.
    pub without_test: usize,
    /// Draws that test stencil: no LRZ write for them.
    pub without_write: usize,
    /// Draws that write both depth and stencil: LRZ invalid after them.
    pub invalidating: usize,
}

impl LrzCost {
    /// The count over `plan`'s passes. Pure.
    pub fn of(plan: &FramePlan) -> LrzCost {
        let mut cost = LrzCost::default();
        for step in &plan.steps {
            let histencil_model::Step::Pass { pass, .. } = step else {
                continue;
            };
            let state = &pass.state;
            cost.draws += 1;
            let writes = state.writes_stencil();
            let tests = [state.front, state.back]
                .iter()
                .flatten()
                .any(|f| f.compare != histencil_model::CompareOp::Always);
            cost.without_test += usize::from(writes);
            cost.without_write += usize::from(tests);
            cost.invalidating += usize::from(writes && state.depth.write);
        }
        cost
    }
}

impl TodaysGpusReport {
    /// Where the GPU's own counts differ from the model's: `(platform or technique, scene)`.
    pub fn disagreements(&self) -> Vec<(String, String)> {
        let mut out = Vec::new();
        for (platform, per_scene) in &self.counts {
            for (scene, c) in self.scenes.iter().zip(per_scene) {
                if c.gpu != c.with_bits {
                    out.push((platform.name().to_owned(), scene.clone()));
                }
            }
        }
        for (scene, (_, model, gpu)) in self.scenes.iter().zip(&self.depth_id) {
            if model != gpu {
                out.push(("depth-id".to_owned(), scene.clone()));
            }
        }
        out
    }
}

/// The simulator's counts of `platform` on `inputs` (captured with some engine bits).
fn counts_of(inputs: &SimulatorInputs, row: Row, plan: &FramePlan) -> TileStats {
    let backend = row.platform().backend();
    inputs.predict_on(plan, backend).0.stats
}

/// The statistics of `technique`'s frame with the engine's bits, counted on the device.
fn gpu_counts(renderer: &mut Renderer, technique: Technique) -> Result<TileStats> {
    let desc = FrameDesc {
        preserved_pattern: ENGINE_BITS,
        tile_stats: true,
        ..FrameDesc::from(technique)
    };
    let stats = renderer.render_frame(&desc)?.tile_stats;
    Ok(stats.expect("a counting frame of a planned or depth-id technique"))
}

/// Runs every platform on every scene at `width` x `height`.
///
/// # Errors
/// Rendering and capture errors (a device without a 32-bit float depth buffer cannot capture).
pub fn run_todays_gpus(
    ctx: &Context,
    scenes: &[Scene],
    width: u32,
    height: u32,
    progress: &mut dyn FnMut(&str),
) -> Result<TodaysGpusReport> {
    let mut counts: Vec<(Row, Vec<SceneCounts>)> =
        Row::ALL.iter().map(|p| (*p, Vec::new())).collect();
    let mut tile_size = 0;
    let mut depth_id = Vec::new();
    let mut lrz = Vec::new();
    for scene in scenes {
        progress(&scene.name);
        let renderer = &mut Renderer::new(ctx, scene.clone(), width, height)?;
        let capture = |renderer: &mut Renderer, bits: u8| {
            let desc = FrameDesc {
                preserved_pattern: bits,
                ..FrameDesc::from(Row::NATIVE.technique())
            };
            renderer.simulator_inputs(desc)
        };
        let with_bits = capture(renderer, ENGINE_BITS)?;
        let without_bits = capture(renderer, 0)?;
        tile_size = with_bits.tile_size;
        let passes = with_bits.layout.brdfs_in_use() as usize;
        let side = histencil_vk::TileSide::for_context(ctx);
        let gpu_ids = gpu_counts(renderer, Technique::DepthId { side })?;
        depth_id.push((passes, with_bits.predict_depth_id(), gpu_ids));
        // The plans follow the lights and the view, not the engine's bits: one per platform.
        let plans = Row::ALL
            .iter()
            .map(|p| renderer.plan(p.technique()))
            .collect::<histencil_vk::Result<Vec<FramePlan>>>()?;
        let native_at = Row::ALL.iter().position(|p| *p == Row::NATIVE);
        let native_plan = &plans[native_at.expect("native is a row")];
        let native = counts_of(&with_bits, Row::NATIVE, native_plan);
        lrz.push(LrzCost::of(native_plan));
        for ((platform, per_scene), plan) in counts.iter_mut().zip(&plans) {
            per_scene.push(SceneCounts {
                with_bits: counts_of(&with_bits, *platform, plan),
                without_bits: counts_of(&without_bits, *platform, plan),
                expected_fragments: native.fragments_shaded,
                gpu: gpu_counts(renderer, platform.technique())?,
            });
        }
    }
    Ok(TodaysGpusReport {
        device: ctx.device_name().to_owned(),
        driver: ctx.driver().to_string(),
        width,
        height,
        tile_size,
        scenes: scenes.iter().map(|s| s.name.clone()).collect(),
        counts,
        depth_id,
        lrz,
    })
}

impl TodaysGpusReport {
    pub fn markdown(&self) -> String {
        let mut md = format!(
            "# The talk on today's GPUs\n\nWritten by `histencil todays-gpus`. Every count is the \
             CPU simulator's, running each platform's plan on frames captured on **{}** ({}): \
             each scene's G-buffer stencil, with the engine's bits 0x{ENGINE_BITS:02X} in the \
             preserved bits, and its lights' footprints, at {}x{}, {}x{} tiles. The AMD rows are \
             modelled from AMD's driver sources (PAL; `crates/model/src/amd.rs` names the file \
             and line of each rule), not measured on AMD hardware. \"Engine bits\": *breaks* \
             where fewer fragments are shaded than the frame needs (lights lost), *weakens* \
             where fewer tiles are culled than without the bits, *no* otherwise.\n\n",
            self.device, self.driver, self.width, self.height, self.tile_size, self.tile_size
        );
        md += "| platform | engine bits break culling? | flush / reset needed | BRDFs culled hierarchically |";
        for s in &self.scenes {
            let _ = write!(md, " `{s}`: tiles culled / tested, fragments shaded |");
        }
        md += "\n|---|---|---|---|";
        md += &"---|".repeat(self.scenes.len());
        md += "\n";
        for (platform, per_scene) in &self.counts {
            let effects: Vec<&str> = per_scene
                .iter()
                .map(SceneCounts::engine_bits_effect)
                .collect();
            let effect = ["breaks", "weakens", "no"]
                .into_iter()
                .find(|e| effects.contains(e))
                .unwrap_or("no");
            let _ = write!(
                md,
                "| {} | {effect} | {} | {} |",
                platform.name(),
                platform.flush_or_reset(),
                platform.brdfs_culled()
            );
            for c in per_scene {
                let s = &c.with_bits;
                let pct = if s.tiles_tested > 0 {
                    format!(
                        " ({:.0} %)",
                        100.0 * s.tiles_culled as f64 / s.tiles_tested as f64
                    )
                } else {
                    String::new()
                };
                let _ = write!(
                    md,
                    " {} / {}{pct}, {} |",
                    s.tiles_culled, s.tiles_tested, s.fragments_shaded
                );
            }
            md += "\n";
        }
        md += "\n## What engines ship instead: depth-id\n\nBevy's deferred lighting: each pixel's \
               lighting-pass id (here its BRDF slot + 1) copied into a 16-bit depth target, one \
               full-screen pass per id with compare EQUAL, each pixel looping over its tile's \
               lights. A GPU's hierarchical depth keeps each tile's id range and rejects the \
               tiles whose range excludes the pass's id; llvmpipe has none, so these rejections \
               are modelled (`histencil_model::depth_id`), on the same captured frames. No \
               flush, no stencil bits, the engine's bits untouched; an id range is not a set, so \
               a tile holding ids 1 and 3 is not rejected for 2.\n\n| scene | passes | tiles \
               culled / tested | fragments shaded |\n|---|---|---|---|\n";
        for (scene, (passes, s, _)) in self.scenes.iter().zip(&self.depth_id) {
            let _ = writeln!(
                md,
                "| `{scene}` | {passes} | {} / {} ({:.0} %) | {} |",
                s.tiles_culled,
                s.tiles_tested,
                100.0 * s.tiles_culled as f64 / s.tiles_tested.max(1) as f64,
                s.fragments_shaded
            );
        }
        let disagreements = self.disagreements();
        if disagreements.is_empty() {
            md += "\nEvery count above was also taken on the device itself, from the same frames \
                   rendered with each platform's hierarchy emulated on the GPU (the consoles' \
                   hi-stencil; AMD's tiles evaluated before each stencil-testing draw; the \
                   depth-id model run on the id image the GPU wrote): the GPU's counts equal \
                   the simulator's on every platform and scene.\n";
        } else {
            let list: Vec<String> = disagreements
                .iter()
                .map(|(p, s)| format!("{p} on `{s}`"))
                .collect();
            let _ = writeln!(
                md,
                "\n**The GPU's own counts differ from the simulator's** for {}: see the JSON.",
                list.join(", ")
            );
        }
        md += "\n## Adreno: what the mask passes cost LRZ\n\nA Qualcomm Adreno culls by a low-resolution \
               depth (LRZ) that holds no stencil. By the rules of Mesa's turnip \
               (`tu_lrz.cc`), a draw that writes stencil runs without the LRZ test, and a draw \
               that tests stencil writes no LRZ; one writing depth and stencil would leave LRZ \
               invalid after it. Counted on the native plan of each scene (an Adreno is the \
               native platform): the light passes write no depth, so the talk's technique costs \
               LRZ the test on its mask draws, and nothing after them.\n\n| scene | draws | \
               without the LRZ test (write stencil) | without LRZ writes (test stencil) | \
               leaving LRZ invalid |\n|---|---|---|---|---|\n";
        for (scene, c) in self.scenes.iter().zip(&self.lrz) {
            let _ = writeln!(
                md,
                "| `{scene}` | {} | {} | {} | {} |",
                c.draws, c.without_test, c.without_write, c.invalidating
            );
        }
        md += "\nNot yet in this table: the per-extra-BRDF cost of the talk's technique and of \
               the depth-id technique, which need timings on the hardware itself \
               (`histencil compare` on it).\n";
        md
    }

    pub fn json(&self) -> Value {
        let stats = |s: &TileStats| {
            json!({"tiles_tested": s.tiles_tested, "tiles_culled": s.tiles_culled,
                   "fragments_shaded": s.fragments_shaded, "flushes": s.flushes})
        };
        json!({
            "device": self.device,
            "driver": self.driver,
            "width": self.width,
            "height": self.height,
            "tile_size": self.tile_size,
            "engine_bits": ENGINE_BITS,
            "scenes": self.scenes,
            "adreno_lrz": self.lrz.iter().map(|c| json!({
                "draws": c.draws, "without_lrz_test": c.without_test,
                "without_lrz_write": c.without_write, "leaving_lrz_invalid": c.invalidating,
            })).collect::<Vec<_>>(),
            "depth_id": self.depth_id.iter().map(|(passes, s, gpu)| json!({
                "passes": passes, "stats": stats(s), "gpu_ids_stats": stats(gpu),
            })).collect::<Vec<_>>(),
            "gpu_disagreements": self.disagreements().iter()
                .map(|(p, s)| json!({"platform": p, "scene": s})).collect::<Vec<_>>(),
            "platforms": self.counts.iter().map(|(p, per_scene)| json!({
                "platform": p.name(),
                "flush_or_reset": p.flush_or_reset(),
                "brdfs_culled": p.brdfs_culled(),
                "scenes": per_scene.iter().map(|c| json!({
                    "with_engine_bits": stats(&c.with_bits),
                    "without_engine_bits": stats(&c.without_bits),
                    "fragments_the_frame_needs": c.expected_fragments,
                    "engine_bits": c.engine_bits_effect(),
                    "gpu_emulation": stats(&c.gpu),
                })).collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
        })
    }

    /// Writes `todays-gpus.md` and `todays-gpus.json` into `dir`.
    ///
    /// # Errors
    /// I/O errors.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        let md = dir.join("todays-gpus.md");
        write_file(&md, self.markdown().as_bytes())?;
        let js = dir.join("todays-gpus.json");
        crate::write_json(&js, &self.json())?;
        Ok(vec![md, js])
    }
}
