//! How `compare` measures: the table's rounds (every row and BRDF count, interleaved, each
//! time held to the steady clock and its error to forward), the light-size sweep, the stencil
//! rows' per-pass breakdown, and the renderers they use.

use super::*;

/// A renderer of `scene` at the settings' size, with their costs.
pub(super) fn renderer_for<'c>(
    ctx: &'c Context,
    settings: &CompareSettings,
    scene: Scene,
) -> Result<Renderer<'c>> {
    let desc = RendererDesc {
        cost_model: settings.costs,
        brdf_weights: settings.brdf_weights,
        brdfs: settings.brdfs,
        ..RendererDesc::new(settings.width, settings.height)
    };
    Ok(Renderer::with_desc(ctx, scene, &desc)?)
}

/// The talk's table as measured: its rows, how its sampling went, the costs and depth-id
/// counts, and the widest column's renderer, for the breakdown.
pub(super) struct Table<'c> {
    pub(super) rows: Vec<Row>,
    pub(super) sampled: Sampled,
    pub(super) costs: CostModel,
    pub(super) depth_id: Vec<(usize, TileStats)>,
    pub(super) widest: Option<(usize, Renderer<'c>)>,
    pub(super) first_left_out: Option<String>,
}

/// Why the table has no LUT row, if it has none: a model of its widest column that no table
/// can hold (`histencil_vk::lut_refusal`: an engine BRDF whose function takes the tint, that
/// reads the tangent, or that lights where `N.L <= 0`). An engine BRDF that a table can hold is
/// baked by its own GLSL, its white part beside its tinted one.
///
/// # Errors
/// The BRDF probe's, which decides the last of those on the device.
pub(super) fn lut_refusal(ctx: &Context, settings: &CompareSettings) -> Result<Option<String>> {
    let widest = settings.brdf_counts.iter().copied().max().unwrap_or(1);
    for b in brdf_palette(&settings.scene, widest) {
        if let Some(why) = histencil_vk::lut_refusal(ctx, settings.brdfs, &b)? {
            return Ok(Some(why.to_string()));
        }
    }
    Ok(None)
}

/// One round of the table: per column and row the technique's time and the emulator's, per
/// BRDF alone and row, and per column of [`FIRST_ROW`].
#[derive(Default)]
struct RoundTimes {
    cells: Vec<Vec<(f64, Option<f64>)>>,
    singles: Vec<Vec<f64>>,
    first: Vec<f64>,
}

/// Every technique at every BRDF count of the settings, and each BRDF alone, sampled in
/// interleaved rounds until `sampling` stops, each round kept by the steady clock; each cell
/// with its error against forward.
pub(super) fn measure_table<'c>(
    ctx: &'c Context,
    settings: &CompareSettings,
    sampling: &Sampling,
    steady: &mut SteadyClock,
    progress: &mut dyn FnMut(&str),
) -> Result<Table<'c>> {
    let lut_left_out = lut_refusal(ctx, settings)?.is_some();
    let rows_spec: Vec<_> = table_rows()
        .into_iter()
        .filter(|(name, _)| !lut_left_out || *name != "lut")
        .collect();
    let mut rows: Vec<Row> = rows_spec
        .iter()
        .map(|(name, _)| Row {
            name,
            cells: vec![],
        })
        .collect();
    let mut costs = None;
    // Every renderer, reference and error first (the error frames warm every technique up),
    // then the timed rounds, interleaved: one frame of every technique at every BRDF count
    // per round, so that a burst of background load lands on all of them alike.
    let mut renderers = Vec::new();
    let mut depth_id = Vec::new();
    for &brdfs in &settings.brdf_counts {
        let mut renderer = renderer_for(ctx, settings, with_brdf_count(&settings.scene, brdfs))?;
        costs.get_or_insert(renderer.cost_model(Backend::Native));
        progress(&format!("{brdfs} BRDF(s): forward reference and errors"));
        let reference = frame(&mut renderer, Shading::Forward)?;
        let mut errors = Vec::new();
        for (_, technique) in &rows_spec {
            errors.push(image_error(&frame(&mut renderer, *technique)?, &reference));
        }
        depth_id.push((brdfs, depth_id_stats(&mut renderer)?));
        renderers.push((brdfs, renderer, errors));
    }
    // Each BRDF of the widest column alone on the same scene (the first is the 1-BRDF
    // column's), each warmed up, and every column's share of surface pixels per BRDF: what the
    // columns would cost if an extra BRDF added only its own arithmetic.
    let max_count = settings.brdf_counts.iter().copied().max().unwrap_or(1);
    let models = brdf_palette(&settings.scene, max_count);
    let palette: Vec<BrdfId> = models.iter().map(|b| b.id()).collect();
    let mut singles = Vec::new();
    for &brdf in models.iter().skip(1) {
        progress(&format!("{} alone: warm-up", brdf.id().name()));
        let mut renderer = renderer_for(ctx, settings, with_one_brdf(&settings.scene, brdf))?;
        for (_, technique) in &rows_spec {
            lighting_ms(&mut renderer, *technique)?;
        }
        singles.push(renderer);
    }
    let mut shares = Vec::new();
    for (_, renderer, _) in &mut renderers {
        shares.push(pixel_shares(renderer, &palette)?);
    }
    // The talk's branching row: per column, the column's BRDFs compiled in, the first shaded.
    let branching_native = Technique::Branching {
        backend: histencil_vk::Backend::Native,
        flush: histencil_vk::FlushPolicy::Auto,
    };
    let mut first_renderers = Vec::new();
    let mut first_left_out = None;
    if settings.first_row {
        match first_row_modules(settings, &palette) {
            Ok(modules) => {
                for (&brdfs, modules) in settings.brdf_counts.iter().zip(modules) {
                    progress(&format!(
                        "{FIRST_ROW}, {brdfs} BRDF(s) compiled in: reference"
                    ));
                    let desc_settings = CompareSettings {
                        brdfs: modules,
                        ..settings.clone()
                    };
                    let scene = with_brdf_count(&settings.scene, 1);
                    let mut renderer = renderer_for(ctx, &desc_settings, scene)?;
                    let reference = frame(&mut renderer, Shading::Forward)?;
                    let error = image_error(&frame(&mut renderer, branching_native)?, &reference);
                    first_renderers.push((brdfs, renderer, error));
                }
            }
            Err(why) => first_left_out = Some(why),
        }
    }
    let first_samples = std::cell::RefCell::new(vec![Vec::new(); first_renderers.len()]);
    let single_samples =
        std::cell::RefCell::new(vec![vec![Vec::new(); rows_spec.len()]; singles.len()]);
    let samples = std::cell::RefCell::new(vec![vec![Vec::new(); rows_spec.len()]; renderers.len()]);
    let mut bookkeeping = vec![vec![Vec::new(); rows_spec.len()]; renderers.len()];
    // The talk's verdicts: each stencil row against branching, at every count above one.
    let branching_row = rows_spec.iter().position(|(n, _)| *n == "branching");
    let against_branching: Vec<usize> = rows_spec
        .iter()
        .enumerate()
        .filter(|(_, (n, _))| n.starts_with("stencil"))
        .map(|(row, _)| row)
        .collect();
    let talk_ratios = |s: &[Vec<Vec<f64>>]| -> Vec<Interval> {
        let Some(b) = branching_row else {
            return Vec::new();
        };
        (1..s.len())
            .flat_map(|count| {
                against_branching
                    .iter()
                    .map(move |&row| ratio_interval(&s[count][row], &s[count][b]))
            })
            .collect()
    };
    // The widths a verdict rests on: every overhead ratio against the 1-BRDF cell, and the
    // talk's verdicts.
    let overhead_widths = || {
        let s = samples.borrow();
        let mut widths: Vec<f64> = (1..s.len())
            .flat_map(|count| {
                let s = &s;
                (0..rows_spec.len()).map(move |row| {
                    ratio_interval(&s[count][row], &s[0][row]).relative_half_width()
                })
            })
            .collect();
        widths.extend(talk_ratios(&s).iter().map(Interval::relative_half_width));
        widths
    };
    // The talk's cells still undecided, each with the rounds its interval predicts it needs.
    let talk_open = || {
        let s = samples.borrow();
        let mut open = Vec::new();
        for count in 1..s.len() {
            for (row, (name, _)) in rows_spec.iter().enumerate() {
                if !TALK_ROWS.contains(name) {
                    continue;
                }
                let ratio = ratio_interval(&s[count][row], &s[0][row]);
                if !Verdict::of(&ratio).decided() {
                    open.push(Verdict::rounds_to_decide(&ratio, crate::stats::MARGIN));
                }
            }
        }
        for ratio in talk_ratios(&s) {
            if !Verdict::of(&ratio).decided() {
                open.push(Verdict::rounds_to_decide(&ratio, crate::stats::MARGIN));
            }
        }
        open
    };
    steady.begin_set("the table", progress)?;
    let mut load = None;
    let table_sampled = sample_deciding(
        sampling,
        |start: &crate::stats::RoundStart| -> Result<()> {
            progress(&format!("the table: {}", start.line()));
            if settings.load_from_round == Some(start.index) && settings.beside_load > 0 {
                progress(&format!(
                    "the table: {} busy threads start beside the measurement",
                    settings.beside_load
                ));
                load = Some(crate::measure::BusyThreads::start(settings.beside_load));
            }
            // One try of the round: every sample of it, committed only if the clock keeps it.
            let mut one_try = || -> Result<RoundTimes> {
                let mut times = RoundTimes::default();
                for (_, renderer, _) in renderers.iter_mut() {
                    let mut column = Vec::new();
                    for (_, technique) in &rows_spec {
                        column.push(lighting_ms(renderer, *technique)?);
                    }
                    times.cells.push(column);
                }
                for renderer in singles.iter_mut() {
                    let mut alone = Vec::new();
                    for (_, technique) in &rows_spec {
                        alone.push(lighting_ms(renderer, *technique)?.0);
                    }
                    times.singles.push(alone);
                }
                for (_, renderer, _) in first_renderers.iter_mut() {
                    times.first.push(lighting_ms(renderer, branching_native)?.0);
                }
                Ok(times)
            };
            let kept = steady.round(start, progress, &mut one_try)?;
            for (count, column) in kept.cells.into_iter().enumerate() {
                for (row, (ms, emulator)) in column.into_iter().enumerate() {
                    samples.borrow_mut()[count][row].push(ms);
                    bookkeeping[count][row].extend(emulator);
                }
            }
            for (single, alone) in kept.singles.into_iter().enumerate() {
                for (row, ms) in alone.into_iter().enumerate() {
                    single_samples.borrow_mut()[single][row].push(ms);
                }
            }
            for (count, ms) in kept.first.into_iter().enumerate() {
                first_samples.borrow_mut()[count].push(ms);
            }
            Ok(())
        },
        overhead_widths,
        talk_open,
    )?;
    drop(load);
    let mut samples = samples.into_inner();
    let single_samples = single_samples.into_inner();
    // Per column, row and round: the shares of each BRDF times its time alone (the first BRDF
    // alone is the 1-BRDF column).
    let single_brdf = |count: usize, row: usize| -> Vec<f64> {
        if count == 0 {
            return Vec::new();
        }
        let alone = |model: usize| -> &Vec<f64> {
            match model {
                0 => &samples[0][row],
                m => &single_samples[m - 1][row],
            }
        };
        (0..samples[count][row].len())
            .map(|round| {
                let weighted = shares[count].iter().enumerate();
                weighted.map(|(m, share)| share * alone(m)[round]).sum()
            })
            .collect()
    };
    let mut single_brdf: Vec<Vec<Vec<f64>>> = (0..renderers.len())
        .map(|count| {
            (0..rows_spec.len())
                .map(|row| single_brdf(count, row))
                .collect()
        })
        .collect();
    for (count, (brdfs, _, errors)) in renderers.iter().enumerate() {
        for (r, (row, error)) in rows.iter_mut().zip(errors).enumerate() {
            row.cells.push(Cell {
                brdfs: *brdfs,
                samples: std::mem::take(&mut samples[count][r]),
                bookkeeping: std::mem::take(&mut bookkeeping[count][r]),
                single_brdf: std::mem::take(&mut single_brdf[count][r]),
                error: *error,
            });
        }
    }
    if !first_renderers.is_empty() {
        let samples = first_samples.into_inner();
        rows.push(Row {
            name: FIRST_ROW,
            cells: first_renderers
                .iter()
                .zip(samples)
                .map(|((brdfs, _, error), samples)| Cell {
                    brdfs: *brdfs,
                    samples,
                    bookkeeping: Vec::new(),
                    single_brdf: Vec::new(),
                    error: *error,
                })
                .collect(),
        });
    }
    let widest = renderers
        .pop()
        .map(|(brdfs, renderer, _)| (brdfs, renderer));
    Ok(Table {
        rows,
        sampled: table_sampled,
        costs: costs.expect("at least one BRDF count"),
        depth_id,
        widest,
        first_left_out,
    })
}

/// The light-size sweep: at each coverage of the settings, branching, stencil, adaptive, tiled
/// and depth-id interleaved until `sampling` stops, with their worst error against forward.
pub(super) fn measure_sizes(
    ctx: &Context,
    settings: &CompareSettings,
    sampling: &Sampling,
    steady: &mut SteadyClock,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<SizePoint>> {
    let aspect = settings.width as f32 / settings.height as f32;
    let side = TileSide::for_context(ctx);
    let mut sizes = Vec::new();
    for &coverage in &settings.light_sizes {
        progress(&format!("light size {:.1} %", coverage * 100.0));
        let mut scene = light_size_scene(coverage, aspect);
        // An engine's set: the wall striped in its BRDFs instead of histencil's three.
        histencil_scene::retarget_brdfs(&mut scene, &settings.brdfs.set);
        let lights = scene.lights.len();
        let mut renderer = renderer_for(ctx, settings, scene)?;
        let reference = frame(&mut renderer, Shading::Forward)?;
        let mut error = ImageError::default();
        for technique in size_techniques(side) {
            error = error.worst(image_error(&frame(&mut renderer, technique)?, &reference));
        }
        // Interleaved, as the table; tracked: every pair's ratio.
        let samples = std::cell::RefCell::new([vec![], vec![], vec![], vec![], vec![]]);
        let pair_widths = || {
            let s = samples.borrow();
            [(1, 0), (2, 0), (2, 1), (3, 0), (3, 1), (4, 3)]
                .map(|(a, b)| ratio_interval(&s[a], &s[b]).relative_half_width())
                .to_vec()
        };
        let stencil_open = || {
            let s = samples.borrow();
            let ratio = ratio_interval(&s[1], &s[0]);
            if Verdict::of(&ratio).decided() {
                Vec::new()
            } else {
                vec![Verdict::rounds_to_decide(&ratio, crate::stats::MARGIN)]
            }
        };
        let set = format!("light size {:.1} %", coverage * 100.0);
        steady.begin_set(&set, progress)?;
        let sampled = sample_deciding(
            sampling,
            |start: &crate::stats::RoundStart| -> Result<()> {
                progress(&format!("{set}: {}", start.line()));
                let mut one_try = || -> Result<Vec<f64>> {
                    let techniques = size_techniques(side).into_iter();
                    let times = techniques.map(|t| lighting_ms(&mut renderer, t).map(|(ms, _)| ms));
                    times.collect()
                };
                let kept = steady.round(start, progress, &mut one_try)?;
                for (i, ms) in kept.into_iter().enumerate() {
                    samples.borrow_mut()[i].push(ms);
                }
                Ok(())
            },
            pair_widths,
            stencil_open,
        )?;
        let samples = samples.into_inner();
        let timings = samples.clone().map(Timing::from_samples);
        sizes.push(SizePoint {
            coverage,
            lights,
            branching: timings[0],
            stencil: timings[1],
            adaptive: timings[2],
            tiled: timings[3],
            depth_id: timings[4],
            tile_side: side.pixels(),
            error,
            samples,
            sampled,
        });
    }
    Ok(sizes)
}

/// The depth-id row's frame counted: the model's hierarchical depth on the GPU's id image.
fn depth_id_stats(renderer: &mut Renderer) -> Result<TileStats> {
    let (_, technique) = table_rows()
        .into_iter()
        .find(|(name, _)| *name == "depth-id")
        .expect("a depth-id row");
    let desc = FrameDesc {
        tile_stats: true,
        ..FrameDesc::from(technique)
    };
    let stats = renderer.render_frame(&desc)?.tile_stats;
    Ok(stats.expect("a depth-id frame counts"))
}

/// The most rounds one measurement set takes, whatever its target and budget.
pub const MAX_ROUNDS: usize = 400;

/// Each of `palette`'s share of the surface pixels `renderer`'s G-buffer holds (zero for a
/// BRDF it does not use; pixels of BRDFs outside the palette are not counted).
fn pixel_shares(renderer: &mut Renderer, palette: &[BrdfId]) -> Result<Vec<f64>> {
    let readback = Readback {
        brdf_ids: true,
        ..Readback::NONE
    };
    let branching = Technique::Branching {
        backend: Backend::Native,
        flush: FlushPolicy::Auto,
    };
    let ids = renderer
        .render(branching, readback)?
        .images
        .brdf_ids
        .ok_or_else(|| crate::LabError::Settings("no BRDF ids read back".into()))?;
    let mut counts = vec![0usize; palette.len()];
    for id in ids.into_iter().flatten() {
        if let Some(i) = palette.iter().position(|p| *p == id) {
            counts[i] += 1;
        }
    }
    let total = counts.iter().sum::<usize>().max(1) as f64;
    Ok(counts.into_iter().map(|c| c as f64 / total).collect())
}

/// Branching, stencil and adaptive on the native backend, and tiled and depth-id with tiles of
/// `side`: the light-size sweep's five.
fn size_techniques(side: TileSide) -> [Technique; 5] {
    let (backend, flush) = (Backend::Native, FlushPolicy::Auto);
    [
        Technique::Branching { backend, flush },
        Technique::Stencil { backend, flush },
        Technique::Adaptive { backend, flush },
        Technique::Tiled {
            mixed: MixedTiles::PerBrdf,
            side,
        },
        Technique::DepthId { side },
    ]
}

/// The median pass-group times of `technique` (timestamps between steps; they cost time of
/// their own, so these are measured apart from the table's times).
pub(super) fn breakdown(
    renderer: &mut Renderer,
    name: &'static str,
    technique: Technique,
    brdfs: usize,
    frames: usize,
) -> Result<Breakdown> {
    let timed = FrameDesc {
        pass_timing: true,
        ..technique.into()
    };
    let lighting = renderer
        .measure(timed, frames.max(1))?
        .lighting
        .unwrap_or_default();
    let mut b = Breakdown {
        name,
        brdfs,
        lights: lighting.per_light.len(),
        setup_ms: 0.0,
        mask_ms: 0.0,
        render_ms: 0.0,
        cleanup_ms: 0.0,
        other: vec![],
    };
    for (group, ms) in lighting.groups {
        match group.as_str() {
            "setup" => b.setup_ms += ms,
            "cleanup" => b.cleanup_ms += ms,
            g if g.starts_with("mask-") => b.mask_ms += ms,
            g if g.starts_with("shade-") => b.render_ms += ms,
            _ => b.other.push((group, ms)),
        }
    }
    Ok(b)
}
