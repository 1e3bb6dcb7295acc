//! A comparison run as `report.md` (the talk's tables beside ours), `report.json` (every cell,
//! machine-readable) and PNG plots.

use super::{Breakdown, CompareReport, Row, SizePoint};
use crate::image_error::ImageError;
use crate::measure::{Timing, WARM_UP_FRAMES};
use crate::plot::{self, Axis, Series};
use crate::stats::{median_interval, ratio_interval, Verdict, MARGIN, MIN_VERDICT_ROUNDS};
use crate::{write_file, Result};
use histencil_model::TalkFigures;
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The plots `write` draws, relative to the output directory.
pub const PLOTS: [&str; 3] = ["lighting.png", "light-size.png", "speed-vs-error.png"];

impl CompareReport {
    /// Writes `report.md`, `report.json` and the plots (`PLOTS`) into `dir` (created if needed);
    /// returns the paths written.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        let md = dir.join("report.md");
        write_file(&md, self.markdown().as_bytes())?;
        let js = dir.join("report.json");
        crate::write_json(&js, &self.json())?;
        let plots: Vec<PathBuf> = PLOTS.iter().map(|p| dir.join(p)).collect();
        self.plot_lighting(&plots[0])?;
        self.plot_sizes(&plots[1])?;
        self.plot_speed_vs_error(&plots[2])?;
        Ok([md, js].into_iter().chain(plots).collect())
    }

    /// Which BRDFs the columns are: the talk's question is asked of these models.
    fn models_line(&self) -> String {
        let named: Vec<String> = self.models.iter().map(|m| format!("`{m}`")).collect();
        let (first, rest) = named
            .split_first()
            .map_or(("none", &[][..]), |(f, r)| (f.as_str(), r));
        let mut line = format!("Models: the 1-BRDF column is {first}");
        for (i, m) in rest.iter().enumerate() {
            line += &format!(", the {}-BRDF column adds {m}", i + 2);
        }
        let line = if self.engine_brdfs.is_empty() {
            line + " (histencil's own BRDFs)."
        } else {
            let own: Vec<String> = self.engine_brdfs.iter().map(|m| format!("`{m}`")).collect();
            line + &format!(
                ". Shaded with an engine's BRDF set (`--brdfs`: {}); its BRDFs' LUT tables are \
                 filled by their own GLSL on the GPU.",
                own.join(", ")
            )
        };
        let line = match &self.lut_left_out {
            None if self.rows.iter().any(|r| r.name == "lut") => {
                line + &format!(
                    " The LUT row's tables hold {} points per axis: its error against forward is \
                     theirs at that resolution (`histencil sweep --param lut-res` gives it \
                     against resolution).",
                    histencil_vk::DEFAULT_LUT_RESOLUTION
                )
            }
            None => line,
            Some(why) => line + &format!(" The LUT row is left out: {why}."),
        };
        let first = if self.rows.iter().any(|r| r.name == super::FIRST_ROW) {
            format!(
                " The `{}` row is the talk's own branching measurement: per column the uber \
                 shader with that column's BRDFs only compiled in, and every pixel taking the \
                 first (its 1-BRDF cell has one BRDF compiled in), so its overheads are the tax \
                 of branches never taken. The `branching` row compiles every BRDF of the set in \
                 at every column and shades the column's BRDFs: divergence and their own \
                 arithmetic.",
                super::FIRST_ROW
            )
        } else {
            String::new()
        };
        match &self.first_left_out {
            None => line + &first,
            Some(why) => line + &format!(" The `{}` row is left out: {why}.", super::FIRST_ROW),
        }
    }

    /// The talk's question first: each platform's stencil technique against branching at 2
    /// BRDFs and up, the ratio of their times in the same rounds.
    fn talk_verdicts_markdown(&self) -> String {
        let verdicts = super::talk_verdicts(&self.rows);
        if verdicts.is_empty() {
            return String::new();
        }
        let mut md = String::from(
            "## The talk's question: stencil against branching\n\n\
             Each platform's stencil technique over branching, both at the same BRDF count, \
             paired by round (below 1: stencil faster); median [95 % interval], decided at \
             ±5 % as every cell is. The emulated platforms' times are their technique's own, \
             without the emulator's bookkeeping.\n\n",
        );
        let counts: Vec<usize> = {
            let mut c: Vec<usize> = verdicts.iter().map(|v| v.brdfs).collect();
            c.sort_unstable();
            c.dedup();
            c
        };
        let head: Vec<String> = counts.iter().map(|c| brdfs_label(*c)).collect();
        md += &table_head(&head);
        for chunk in verdicts.chunks(counts.len()) {
            let cells: Vec<String> = chunk
                .iter()
                .map(|v| {
                    format!(
                        "{:.3}x [{:.3}, {:.3}] {}",
                        v.ratio.median,
                        v.ratio.lo,
                        v.ratio.hi,
                        v.words()
                    )
                })
                .collect();
            let _ = writeln!(md, "| {} | {} |", chunk[0].technique, cells.join(" | "));
        }
        md.push('\n');
        md
    }

    /// Every figure of the run; all numbers are finite.
    pub fn json(&self) -> Value {
        let c = &self.costs;
        let mut out = json!({
            "device": self.device,
            "driver": self.driver,
            "settings": {
                "scene": self.scene,
                "scene_lights": self.scene_lights,
                "models": self.models,
                "engine_brdfs": self.engine_brdfs,
                "width": self.width,
                "height": self.height,
                "frames": self.frames,
                "warm_up_frames": WARM_UP_FRAMES,
            },
            "table_sampling": sampled_json(&self.sampled),
            "talk_verdicts": super::talk_verdicts(&self.rows).iter().map(|v| json!({
                "technique": v.technique,
                "brdfs": v.brdfs,
                "against": v.against,
                "ratio": interval_json(&v.ratio),
                "verdict": v.words(),
            })).collect::<Vec<_>>(),
            "rows": self.rows.iter().map(row_json).collect::<Vec<_>>(),
            "breakdown": self.breakdowns.iter().map(breakdown_json).collect::<Vec<_>>(),
            "light_sizes": self.sizes.iter().map(size_json).collect::<Vec<_>>(),
            "depth_id_modelled": self.depth_id.iter().map(|(brdfs, s)| json!({
                "brdfs": brdfs,
                "tiles_tested": s.tiles_tested,
                "tiles_rejected": s.tiles_culled,
                "fragments_shaded": s.fragments_shaded,
            })).collect::<Vec<_>>(),
            "cost_model": {
                "calibrated": self.costs_calibrated,
                "pass_overhead_ms": c.pass_overhead_ms,
                "stencil_per_brdf_ms": c.stencil_per_brdf_ms,
                "branch_tax_per_brdf_ms": c.branch_tax_per_brdf_ms,
                "shade_ms": c.shade_ms,
            },
        });
        let mut crossover = serde_json::Map::new();
        if let Some(x) = self.measured_crossover() {
            crossover.insert("measured_coverage".into(), json!(x));
        }
        if let Some(x) = self.costs.crossover_coverage() {
            crossover.insert("model_coverage".into(), json!(x));
        }
        let (stencil_from, branching_until) = self.crossover_bounds();
        if let Some(x) = stencil_from {
            crossover.insert("stencil_surely_faster_from".into(), json!(x));
        }
        if let Some(x) = branching_until {
            crossover.insert("branching_surely_faster_until".into(), json!(x));
        }
        out["crossover"] = Value::Object(crossover);
        // Only what was set: the report's values are all present and finite.
        if let Some(why) = &self.lut_left_out {
            out["settings"]["lut_left_out"] = json!(why);
        }
        if let Some(why) = &self.first_left_out {
            out["settings"]["first_row_left_out"] = json!(why);
        }
        if let Some(n) = &self.lp_num_threads {
            out["settings"]["environment"] = json!({ "LP_NUM_THREADS": n });
        }
        out["settings"]["beside_load_threads"] = json!(self.beside_load);
        if let Some(round) = self.load_from_round {
            out["settings"]["beside_load_from_round"] = json!(round);
        }
        if let Some(stability) = &self.stability {
            out["stability"] = stability.json();
        }
        out["settings"]["depth_bounds"] = json!(self.depth_bounds);
        out
    }

    pub fn markdown(&self) -> String {
        let mut md = String::new();
        let _ = writeln!(
            md,
            "# histencil compare\n\nDevice: **{}** ({}). Scene `{}` ({} lights) at {}x{}. Lighting-pass \
             GPU time over at least {} rounds after a warm-up frame; each round renders one frame of every \
             technique at every BRDF count in turn, so background load hits all alike. Table: \
             median [95 % interval of the median, order statistics; below 6 rounds no interval \
             reaches 95 % and the whole range is shown]; overheads are the median of \
             the per-round ratios to the row's 1-BRDF time, with their interval. Verdicts have \
             a practical margin of ±{:.0} %: faster or slower only where the whole interval lies \
             beyond it, \"within ±{:.0} %\" where it lies wholly inside, and each half of the \
             rounds in the order taken has its median there too (a load that started or stopped \
             part way leaves the halves apart); \"undecided\" otherwise and below {} rounds. \
             Error against the forward reference of the same scene: 8-bit max / mean, and mean \
             FLIP.\n",
            self.device, self.driver, self.scene, self.scene_lights, self.width, self.height,
            self.frames, 100.0 * MARGIN, 100.0 * MARGIN, MIN_VERDICT_ROUNDS
        );
        let _ = writeln!(md, "{}\n", self.models_line());
        let t = &self.sampled;
        if let Some(n) = &self.lp_num_threads {
            let _ = writeln!(md, "Environment: `LP_NUM_THREADS={n}`.\n");
        }
        if self.beside_load > 0 {
            let from = self.load_from_round.map_or(String::new(), |r| {
                format!(
                    ", from the table's round {} on (`--beside-load-from-round`)",
                    r + 1
                )
            });
            let _ = writeln!(
                md,
                "Conditions: {} busy threads ran beside the measurement (`--beside-load`){from}.\n",
                self.beside_load
            );
        }
        if let Some((busy, kept, most)) = self.stability.as_ref().and_then(|s| s.busy_elsewhere()) {
            let _ = writeln!(
                md,
                "Conditions: **not a quiet machine**. Other processes kept up to {most:.2} cores \
                 busy in {busy} of the {kept} kept rounds (retaken while the budget lasted, then \
                 kept flagged unsteady: \"Steady clock\" below). On a CPU driver such a load can \
                 change the techniques' ratios, not only their times; this run's verdicts are \
                 about a busy machine.\n"
            );
        }
        let _ = writeln!(
            md,
            "Depth bounds test: {}.\n",
            if self.depth_bounds {
                "on (each light's shade passes confined to its depth range)"
            } else {
                "off (the device has none, or `--no-depth-bounds`)"
            }
        );
        let _ = writeln!(
            md,
            "Sampling: the table took {} rounds in {:.1} s ({}; at least {} rounds{}); its widest \
             overhead interval is ±{:.1} %. Each light size samples the same way (its rounds are \
             in its row).\n",
            t.rounds,
            t.seconds,
            t.stop.word(),
            self.frames,
            self.target_ci
                .map_or(String::new(), |c| format!(", target ±{:.1} %", 100.0 * c)),
            100.0 * t.widest
        );
        if let Some(p) = &t.prediction {
            let mut predicted = match p.rounds {
                Some(r) => format!("{r} rounds in all would decide the talk's cells"),
                None => "no number of rounds would decide the talk's open cells".to_owned(),
            };
            if p.on_edge > 0 {
                let _ = write!(
                    predicted,
                    " ({} on a margin's edge, which no number of rounds decides)",
                    p.on_edge
                );
            }
            let _ = writeln!(
                md,
                "Budget: a pilot of {} rounds ({:.1} s) predicted that {predicted}, so the \
                 budget was {:.0} s. Outcome: {} rounds, {} of the talk's cells (branching's \
                 and stencil's overheads at 2 BRDFs and up, stencil against branching) still \
                 undecided.\n",
                p.pilot_rounds, p.pilot_seconds, p.budget_seconds, t.rounds, t.open
            );
        }
        md += &self.talk_verdicts_markdown();
        if let Some(stability) = &self.stability {
            md += &stability.markdown();
        }
        md += "## Lighting time against BRDF count\n\n";
        md += "Overheads are against each row's own 1-BRDF time in this run; the error column is \
               the worst over the BRDF counts.\n\n";
        let mut head: Vec<String> = self.rows[0]
            .cells
            .iter()
            .map(|c| brdfs_label(c.brdfs))
            .collect();
        head.push("error max / mean / FLIP".into());
        md += &table_head(&head);
        for row in &self.rows {
            let cells: Vec<String> = (0..row.cells.len()).map(|i| cell_text(row, i)).collect();
            let _ = writeln!(
                md,
                "| {} | {} | {} |",
                row.name,
                cells.join(" | "),
                error_text(&row.worst_error())
            );
        }
        md += &self.single_brdf_markdown();
        md += &self.emulation_markdown();
        md += &self.depth_id_markdown();
        md += "\nThe talk (Develop 2012, huge lights, ms):\n\n\
               | platform | 1 BRDF | 2 BRDFs branching | 3 BRDFs branching | 2 BRDFs stencil | 3 BRDFs stencil |\n\
               |---|---|---|---|---|---|\n";
        for (name, f) in [("Xbox 360", TalkFigures::X360), ("PS3", TalkFigures::PS3)] {
            let rel = |t: f64| {
                format!(
                    "{t:.2} (+{:.2} ms, +{:.0} %)",
                    t - f.one_brdf,
                    100.0 * (t - f.one_brdf) / f.one_brdf
                )
            };
            let _ = writeln!(
                md,
                "| {name} | {:.2} | {} | {} | {} | {} |",
                f.one_brdf,
                rel(f.branching[0]),
                rel(f.branching[1]),
                rel(f.stencil[0]),
                rel(f.stencil[1])
            );
        }
        md += "\n## Per-BRDF breakdown of the stencil technique\n\n\
               Pass-group timestamps at the largest BRDF count (they cost time of their own, so \
               they are measured apart from the table). Totals in ms, then per light (setup, \
               cleanup) and per light and BRDF (mask, render).\n\n\
               | technique | lights x BRDFs | setup | mask | render | cleanup | other | per pass: setup / mask / render / cleanup |\n\
               |---|---|---|---|---|---|---|---|\n";
        for b in &self.breakdowns {
            let per = b.per_pass();
            let other: Vec<String> = b
                .other
                .iter()
                .map(|(g, ms)| format!("{g} {ms:.3}"))
                .collect();
            let _ = writeln!(
                md,
                "| {} | {} x {} | {:.3} | {:.3} | {:.3} | {:.3} | {} | {:.4} / {:.4} / {:.4} / {:.4} |",
                b.name,
                b.lights,
                b.brdfs,
                b.setup_ms,
                b.mask_ms,
                b.render_ms,
                b.cleanup_ms,
                if other.is_empty() { "-".to_owned() } else { other.join(", ") },
                per[0],
                per[1],
                per[2],
                per[3]
            );
        }
        for (name, f) in [("Xbox 360", TalkFigures::X360), ("PS3", TalkFigures::PS3)] {
            let _ = writeln!(
                md,
                "| talk: {name} | per BRDF | | | | | | {} / {} / {} / {} |",
                f.setup, f.mask, f.render, f.cleanup
            );
        }
        let side = self.sizes.first().map_or(16, |p| p.tile_side);
        let _ = write!(
            md,
            "\n## Light size: where branching overtakes stencil\n\n\
             A striped wall in three BRDFs under lights covering the given fraction of the \
             screen each, `2 / coverage` of them (at most 400), so the lit area stays about two \
             screens. Native backend; tiled and depth-id with {side}x{side} tiles (the device's \
             side, `TileSide::for_context`), tiled's mixed tiles per BRDF; the error is the worst \
             of the five techniques.\n\n"
        );
        md += "\
               | coverage | lights | rounds | branching | stencil | adaptive | tiled | depth-id | stencil / branching | faster | adaptive / best | tiled / best | depth-id / tiled | error max / mean / FLIP |\n\
               |---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
        for p in &self.sizes {
            let (ratio, _) = p.stencil_over_branching();
            let best = p.adaptive_over_best_interval();
            let (tiled, tiled_verdict) = p.tiled_over_best();
            let (depth_id, depth_id_verdict) = p.depth_id_over_tiled();
            let _ = writeln!(
                md,
                "| {:.1} % | {} | {} ({}) | {} | {} | {} | {} | {} | {} | {} | {} | {} ({}) | {} ({}) | {} |",
                p.coverage * 100.0,
                p.lights,
                p.sampled.rounds,
                p.sampled.stop.word(),
                interval_text(&median_interval(&p.samples[0])),
                interval_text(&median_interval(&p.samples[1])),
                interval_text(&median_interval(&p.samples[2])),
                interval_text(&median_interval(&p.samples[3])),
                interval_text(&median_interval(&p.samples[4])),
                ratio_text(&ratio),
                p.faster(),
                ratio_text(&best),
                ratio_text(&tiled),
                tiled_verdict.word(),
                ratio_text(&depth_id),
                depth_id_verdict.word(),
                error_text(&p.error)
            );
        }
        let measured = self
            .measured_crossover()
            .map_or("never in the swept range".to_owned(), |x| {
                format!("{:.2} % of the screen", x * 100.0)
            });
        let model = self
            .costs
            .crossover_coverage()
            .map_or("never".to_owned(), |x| format!("{:.2} %", x * 100.0));
        let (stencil_from, branching_until) = self.crossover_bounds();
        let pct = |x: Option<f64>, none: &str| {
            x.map_or(none.to_owned(), |x| format!("{:.2} %", x * 100.0))
        };
        let _ = writeln!(
            md,
            "\nStencil stays faster than branching from {measured} by the medians; with the \
             intervals and the ±5 % margin, branching is faster up to {} and stencil faster \
             from {}: the crossover lies in the band between (its sizes are within the margin or \
             undecided). The adaptive technique's cost \
             model ({}) puts the change at {model}.",
            pct(branching_until, "no swept size"),
            pct(stencil_from, "no swept size on"),
            if self.costs_calibrated {
                "calibrated on this device"
            } else {
                "fitted to the talk's figures"
            }
        );
        md += "\nPlots: `lighting.png`, `light-size.png`, `speed-vs-error.png`.\n";
        md
    }

    /// The table's extra-BRDF columns against what their BRDFs cost alone.
    fn single_brdf_markdown(&self) -> String {
        let columns: Vec<usize> = (0..self.rows[0].cells.len())
            .filter(|&i| self.rows[0].over_single_brdf(i).is_some())
            .collect();
        if columns.is_empty() {
            return String::new();
        }
        let mut md = String::from(
            "\nAn extra BRDF costs its own arithmetic as well as the technique's work: the columns \
             above put (n - 1) / n of the objects in BRDFs other than the 1-BRDF column's, \
             which may cost more or less per pixel. Below, each cell against what its BRDFs \
             cost alone: per round, the row's time on the scene with every object in one BRDF, \
             weighted by that BRDF's share of the cell's surface pixels (exact where every light \
             covers the screen), paired by round. What is left is what the technique adds for \
             the cell's extra BRDFs beyond their arithmetic (the physical limit is about 0 %).\n\n",
        );
        let head: Vec<String> = columns
            .iter()
            .map(|&i| brdfs_label(self.rows[0].cells[i].brdfs))
            .collect();
        md += &table_head(&head);
        // The talk's branching row shades one BRDF at every column: nothing to weigh.
        for row in self.rows.iter().filter(|r| r.name != super::FIRST_ROW) {
            let cells: Vec<String> = columns
                .iter()
                .map(|&i| {
                    let (ratio, verdict) = row.over_single_brdf(i).expect("several BRDFs");
                    percent_text(&ratio, verdict)
                })
                .collect();
            let _ = writeln!(md, "| {} | {} |", row.name, cells.join(" | "));
        }
        md
    }

    /// The emulated rows' technique and bookkeeping side by side, each with its interval, and
    /// the technique against native stencil at the same BRDF count, paired by round.
    /// What the depth-id row's EQUAL tests would reject on a GPU with hierarchical depth.
    fn depth_id_markdown(&self) -> String {
        if self.depth_id.is_empty() {
            return String::new();
        }
        let mut md = String::from(
            "\nThe depth-id row draws one full-screen pass per BRDF at its id's depth with compare \
             EQUAL. Its time above is the device's own, with whatever hierarchical depth the device \
             has (a CPU rasteriser such as llvmpipe has none, and tests depth per pixel); what a \
             GPU's hierarchical depth would reject of the same frame is modelled on the id image the GPU wrote (`histencil_model::depth_id`, 8x8 tiles: \
             a tile whose id range excludes the pass's id is rejected whole), not measured.\n\n\
             | BRDFs | tile tests | rejected (modelled) | fragments shaded |\n\
             |---|---|---|---|\n",
        );
        for (brdfs, s) in &self.depth_id {
            let _ = writeln!(
                md,
                "| {brdfs} | {} | {} ({:.1} %) | {} |",
                s.tiles_tested,
                s.tiles_culled,
                100.0 * s.tiles_culled as f64 / s.tiles_tested.max(1) as f64,
                s.fragments_shaded
            );
        }
        md
    }

    fn emulation_markdown(&self) -> String {
        let native = self.rows.iter().find(|r| r.name == "stencil native");
        let emulated: Vec<&Row> = self
            .rows
            .iter()
            .filter(|r| r.cells.iter().any(|c| !c.bookkeeping.is_empty()))
            .collect();
        let Some(native) = native.filter(|_| !emulated.is_empty()) else {
            return String::new();
        };
        let mut md = String::from(
            "\nThe PS3-like, 360-like and AMD rows time the platform's technique: the lighting pass \
             without the hi-stencil emulator's bookkeeping (resetting its tile surface; after each \
             hi-stencil write the split, the touch draw that finds the tiles it rasterised and \
             the tile update; the copy at each flush; on AMD's, before each draw that tests \
             stencil, the split and the evaluation of its tiles), which a timestamp on each side \
             of it times apart. The AMD rows are modelled from AMD's driver sources, not \
             measured on AMD hardware. Still inside the technique's time: its testing draws reading the tile \
             surface in the fragment shader, where a console tests tiles before shading.\n\n\
             | backend | BRDFs | technique, ms | emulator bookkeeping, ms | bookkeeping / whole | \
             whole lighting, ms | stencil native, ms | technique / native |\n\
             |---|---|---|---|---|---|---|---|\n",
        );
        for row in emulated {
            for (cell, base) in row.cells.iter().zip(&native.cells) {
                if cell.bookkeeping.is_empty() {
                    let _ = writeln!(
                        md,
                        "| {} | {} | {} | none: no hi-stencil in this plan | - | - | {} | {} |",
                        row.name,
                        cell.brdfs,
                        interval_text(&cell.interval()),
                        interval_text(&base.interval()),
                        ratio_text(&ratio_interval(&cell.samples, &base.samples))
                    );
                    continue;
                }
                let whole = cell.with_bookkeeping();
                let share = ratio_interval(&cell.bookkeeping, &whole);
                let ratio = ratio_interval(&cell.samples, &base.samples);
                let _ = writeln!(
                    md,
                    "| {} | {} | {} | {} | {} | {} | {} | {} ({}) |",
                    row.name,
                    cell.brdfs,
                    interval_text(&cell.interval()),
                    interval_text(&median_interval(&cell.bookkeeping)),
                    ratio_text(&share),
                    interval_text(&median_interval(&whole)),
                    interval_text(&base.interval()),
                    ratio_text(&ratio),
                    Verdict::of(&ratio).word()
                );
            }
        }
        md
    }

    fn plot_lighting(&self, path: &Path) -> Result<()> {
        let series: Vec<Series> = self
            .rows
            .iter()
            .map(|r| Series {
                name: r.name.to_owned(),
                points: r
                    .cells
                    .iter()
                    .map(|c| (c.brdfs as f64, c.interval().median))
                    .collect(),
                bars: r
                    .cells
                    .iter()
                    .map(|c| (c.interval().lo, c.interval().hi))
                    .collect(),
            })
            .collect();
        plot::line_chart(
            path,
            &format!("Lighting time against BRDF count ({})", self.device),
            Axis {
                label: "BRDFs in use",
                log: false,
            },
            Axis {
                label: "lighting ms",
                log: false,
            },
            &series,
        )
    }

    fn plot_sizes(&self, path: &Path) -> Result<()> {
        // Per light: each technique's median and interval over the size point's rounds.
        let series = ["branching", "stencil", "adaptive", "tiled", "depth-id"]
            .into_iter()
            .enumerate()
            .map(|(i, name)| {
                let per_light: Vec<(f64, crate::stats::Interval)> = self
                    .sizes
                    .iter()
                    .map(|p| {
                        let n = p.lights.max(1) as f64;
                        let iv = median_interval(&p.samples[i]);
                        (
                            p.coverage * 100.0,
                            crate::stats::Interval {
                                lo: iv.lo / n,
                                median: iv.median / n,
                                hi: iv.hi / n,
                                halves: iv.halves.map(|(a, b)| (a / n, b / n)),
                                ..iv
                            },
                        )
                    })
                    .collect();
                Series {
                    name: name.into(),
                    points: per_light.iter().map(|(c, iv)| (*c, iv.median)).collect(),
                    bars: per_light.iter().map(|(_, iv)| (iv.lo, iv.hi)).collect(),
                }
            })
            .collect::<Vec<_>>();
        plot::line_chart(
            path,
            "Lighting time per light against light size (3 BRDFs)",
            Axis {
                label: "screen coverage per light, %",
                log: true,
            },
            Axis {
                label: "ms per light",
                log: true,
            },
            &series,
        )
    }

    fn plot_speed_vs_error(&self, path: &Path) -> Result<()> {
        let points: Vec<(f64, f64, String)> = self
            .rows
            .iter()
            .map(|r| {
                let last = r.cells.last().expect("cells");
                (
                    last.lighting().median_ms,
                    last.error.mean,
                    r.name.to_owned(),
                )
            })
            .collect();
        plot::pareto_chart(
            path,
            "Speed against error at the largest BRDF count",
            Axis {
                label: "lighting ms",
                log: false,
            },
            Axis {
                label: "mean error, 8-bit steps",
                log: false,
            },
            &points,
        )
    }
}

fn brdfs_label(n: usize) -> String {
    if n == 1 {
        "1 BRDF".into()
    } else {
        format!("{n} BRDFs")
    }
}

/// `12.345 ms [12.1, 12.6]`: a median with its 95 % interval.
fn interval_text(i: &crate::stats::Interval) -> String {
    format!("{:.3} ms [{:.3}, {:.3}]", i.median, i.lo, i.hi)
}

/// `0.82 [0.79, 0.85]`: a ratio's median with its 95 % interval.
fn ratio_text(i: &crate::stats::Interval) -> String {
    format!("{:.2} [{:.2}, {:.2}]", i.median, i.lo, i.hi)
}

/// `12.345 ms [12.1, 12.6]`, and for a cell over the 1-BRDF one its overhead as the median
/// paired ratio with its interval and the verdict they allow:
/// `(+3.2 % [+1.1, +5.0], slower)`.
fn cell_text(row: &Row, i: usize) -> String {
    let c = row.cells[i].interval();
    let t = format!("{:.3} ms [{:.3}, {:.3}]", c.median, c.lo, c.hi);
    if i == 0 {
        return t;
    }
    let (ratio, verdict) = row.overhead_ratio(i);
    format!(
        "{t} ({}{})",
        percent_text(&ratio, verdict),
        more_rounds(&ratio, verdict)
    )
}

/// For an undecided ratio: how many more rounds would decide it at the interval's present rate
/// (`; about 23 more rounds`), or that none would (a median on a margin's edge).
fn more_rounds(ratio: &crate::stats::Interval, verdict: Verdict) -> String {
    if verdict.decided() {
        return String::new();
    }
    match Verdict::rounds_to_decide(ratio, MARGIN) {
        Some(n) => format!(
            "; about {} more rounds",
            n.saturating_sub(ratio.samples).max(1)
        ),
        None => "; on the margin's edge".to_owned(),
    }
}

/// A ratio's interval as a change in percent with its verdict: `+12.3 % [+10.1, +14.0], slower`.
fn percent_text(ratio: &crate::stats::Interval, verdict: Verdict) -> String {
    let pct = |r: f64| 100.0 * (r - 1.0);
    let (m, lo, hi) = (pct(ratio.median), pct(ratio.lo), pct(ratio.hi));
    format!("{m:+.1} % [{lo:+.1}, {hi:+.1}], {}", verdict.word())
}

/// A table's header row, after the `technique` column, and its rule.
fn table_head(columns: &[String]) -> String {
    format!(
        "| technique | {} |\n|---|{}\n",
        columns.join(" | "),
        "---|".repeat(columns.len())
    )
}

/// An interval as the reports store it, with the halves its verdict was held to, so that a
/// merge gives the verdicts the run gave.
pub(super) fn interval_json(i: &crate::stats::Interval) -> Value {
    let mut out = json!({"median": i.median, "lo": i.lo, "hi": i.hi, "samples": i.samples});
    // Absent below two rounds, and for an interval read from an older report: no nulls.
    if let Some((first, second)) = i.halves {
        out["halves"] = json!([first, second]);
    }
    out
}

fn error_text(e: &ImageError) -> String {
    format!("{:.0} / {:.3} / {:.4}", e.max, e.mean, e.flip)
}

fn timing_json(t: &Timing) -> Value {
    json!({"median_ms": t.median_ms, "min_ms": t.min_ms, "max_ms": t.max_ms, "spread_ms": t.spread_ms()})
}

fn error_json(e: &ImageError) -> Value {
    json!({"max": e.max, "mean": e.mean, "flip": e.flip})
}

fn row_json(row: &Row) -> Value {
    let cells: Vec<Value> = row
        .cells
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let (ms, pct) = row.overhead(i);
            let (ratio, verdict) = row.overhead_ratio(i);
            let mut cell = json!({
                "brdfs": c.brdfs,
                "lighting": timing_json(&c.lighting()),
                "lighting_interval_ms": interval_json(&c.interval()),
                "lighting_samples_ms": c.samples,
                "bookkeeping_samples_ms": c.bookkeeping,
                "overhead_ms": ms,
                "overhead_percent": pct,
                "overhead_ratio": interval_json(&ratio),
                "verdict_against_1_brdf": verdict.word(),
                "single_brdf_samples_ms": c.single_brdf,
                "error": error_json(&c.error),
            });
            if let Some((ratio, verdict)) = row.over_single_brdf(i) {
                cell["over_single_brdf_ratio"] = interval_json(&ratio);
                cell["verdict_against_single_brdf"] = json!(verdict.word());
            }
            cell
        })
        .collect();
    json!({"technique": row.name, "cells": cells})
}

fn breakdown_json(b: &Breakdown) -> Value {
    let per = b.per_pass();
    let other: serde_json::Map<String, Value> = b
        .other
        .iter()
        .map(|(g, ms)| (g.clone(), json!(ms)))
        .collect();
    json!({
        "technique": b.name,
        "brdfs": b.brdfs,
        "lights": b.lights,
        "total_ms": {"setup": b.setup_ms, "mask": b.mask_ms, "render": b.render_ms,
                     "cleanup": b.cleanup_ms, "other": other},
        "per_pass_ms": {"setup": per[0], "mask": per[1], "render": per[2], "cleanup": per[3]},
    })
}

fn size_json(p: &SizePoint) -> Value {
    json!({
        "coverage": p.coverage,
        "lights": p.lights,
        "branching": timing_json(&p.branching),
        "stencil": timing_json(&p.stencil),
        "adaptive": timing_json(&p.adaptive),
        "adaptive_over_best": p.adaptive_over_best(),
        "adaptive_over_best_interval": interval_json(&p.adaptive_over_best_interval()),
        "tiled": timing_json(&p.tiled),
        "tiled_tile_side": p.tile_side,
        "tiled_over_best": interval_json(&p.tiled_over_best().0),
        "depth_id": timing_json(&p.depth_id),
        "depth_id_over_best": interval_json(&p.depth_id_over_best().0),
        "depth_id_over_tiled": interval_json(&p.depth_id_over_tiled().0),
        "stencil_over_branching": interval_json(&p.stencil_over_branching().0),
        "faster": p.faster(),
        "samples_ms": {
            "branching": p.samples[0],
            "stencil": p.samples[1],
            "adaptive": p.samples[2],
            "tiled": p.samples[3],
            "depth_id": p.samples[4],
        },
        "sampling": sampled_json(&p.sampled),
        "error": error_json(&p.error),
    })
}

/// How sampling ended; the widest interval only when there is one (at least two rounds).
fn sampled_json(s: &crate::stats::Sampled) -> Value {
    let mut out = json!({
        "rounds": s.rounds,
        "stopped": s.stop.word(),
        "seconds": s.seconds,
    });
    if s.widest.is_finite() {
        out["widest_relative_half_width"] = json!(s.widest);
    }
    out["undecided"] = json!(s.open);
    if let Some(p) = &s.prediction {
        out["prediction"] = json!({
            "pilot_rounds": p.pilot_rounds,
            "pilot_seconds": p.pilot_seconds,
            "rounds": p.rounds,
            "on_margin_edge": p.on_edge,
            "budget_seconds": p.budget_seconds,
        });
    }
    out
}
