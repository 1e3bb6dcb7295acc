//! A scene at scale (`histencil scale`): what it takes to load (building or importing the
//! scene, creating the renderer, the device memory that needs) and what its frame costs with
//! the techniques a deferred renderer is judged by: G-buffer, lighting and whole-frame time for
//! the talk's stencil technique on the native and PS3-like backends and for branching, each
//! next to its error against forward.
//!
//! The techniques are timed in interleaved rounds (one frame of each per round) so that drift
//! on a noisy machine falls on all of them alike, and the lighting ratios are taken per round
//! in the same run, with their spread.

use crate::image_error::{image_error, ImageError};
use crate::measure::{frame, Timing, WARM_UP_FRAMES};
use crate::Result;
use histencil_scene::{unit_box, uv_sphere, Material, Mesh, Scene, Shape, SPHERE_DETAIL};
use histencil_vk::{Backend, Context, FlushPolicy, FrameDesc, Renderer, Shading, Technique};
use std::fmt::Write as _;
use std::time::Instant;

/// What `histencil scale` measures.
pub struct ScaleSettings {
    pub scene: Scene,
    /// How long building or importing `scene` took (the caller timed it).
    pub load_ms: f64,
    pub width: u32,
    pub height: u32,
    /// Timed rounds, one frame of every technique each.
    pub rounds: usize,
}

/// The scene's size as the renderer sees it.
pub struct SceneSize {
    pub triangles: usize,
    pub objects: usize,
    pub materials: usize,
    pub lights: usize,
    pub images: usize,
    /// Vertex, index and decoded image bytes on the CPU.
    pub bytes: u64,
}

impl SceneSize {
    pub fn of(scene: &Scene) -> Self {
        // The built-in shapes' triangles, from the meshes the renderer draws for them.
        let (s, r) = SPHERE_DETAIL;
        let builtin = |m: Mesh| m.indices.len() / 3;
        let (cube, sphere) = (builtin(unit_box()), builtin(uv_sphere(s, r)));
        let triangles = scene
            .objects
            .iter()
            .map(|o| match o.shape {
                Shape::Mesh(i) => scene.meshes[i as usize].indices.len() / 3,
                Shape::Box => cube,
                Shape::Sphere => sphere,
            })
            .sum();
        let mut materials: Vec<&Material> = Vec::new();
        for o in &scene.objects {
            if !materials.contains(&&o.material) {
                materials.push(&o.material);
            }
        }
        let mesh_bytes: usize = scene
            .meshes
            .iter()
            .map(|m| std::mem::size_of_val(m.vertices.as_slice()) + 4 * m.indices.len())
            .sum();
        let image_bytes: usize = scene.images.iter().map(|i| i.rgba8.len()).sum();
        Self {
            triangles,
            objects: scene.objects.len(),
            materials: materials.len(),
            lights: scene.lights.len(),
            images: scene.images.len(),
            bytes: (mesh_bytes + image_bytes) as u64,
        }
    }
}

/// One technique's figures.
pub struct ScaleRow {
    pub label: &'static str,
    pub shading: Shading,
    pub gbuffer: Timing,
    /// The lighting: the platform's technique, without the hi-stencil emulator's bookkeeping.
    pub lighting: Timing,
    /// The emulator's bookkeeping in the same rounds, on the emulated backends only.
    pub bookkeeping: Option<Timing>,
    /// Every pass of the frame, tonemap included.
    pub frame: Timing,
    /// `None` for forward itself.
    pub error: Option<ImageError>,
}

pub struct ScaleReport {
    pub device: String,
    /// The driver as Vulkan names it (name, build, conformance) and the validation layer: two
    /// builds of one driver share a device name.
    pub driver: String,
    pub width: u32,
    pub height: u32,
    pub rounds: usize,
    pub size: SceneSize,
    pub load_ms: f64,
    /// `Renderer::new`: validation, uploads through staging, mips, pipelines.
    pub create_ms: f64,
    /// The most device memory held at once while the renderer was made (staging included),
    /// and what it holds once made.
    pub peak_bytes: u64,
    pub held_bytes: u64,
    pub rows: Vec<ScaleRow>,
    /// Per-round lighting time of each stencil row over branching's: `(label, ratios)`.
    pub ratios: Vec<(&'static str, Timing)>,
}

fn techniques() -> [(&'static str, Shading); 4] {
    let flush = FlushPolicy::Auto;
    [
        ("forward (reference)", Shading::Forward),
        (
            "stencil, native",
            Technique::Stencil {
                backend: Backend::Native,
                flush,
            }
            .into(),
        ),
        (
            "stencil, PS3-like",
            Technique::Stencil {
                backend: Backend::Ps3,
                flush,
            }
            .into(),
        ),
        (
            "branching, native",
            Technique::Branching {
                backend: Backend::Native,
                flush,
            }
            .into(),
        ),
    ]
}

/// Measures `settings.scene`. `step` is told what is being done.
pub fn run_scale(
    ctx: &Context,
    settings: ScaleSettings,
    step: &mut dyn FnMut(&str),
) -> Result<ScaleReport> {
    let size = SceneSize::of(&settings.scene);
    let rounds = settings.rounds.max(1);
    step("creating the renderer");
    let before = ctx.memory_in_use();
    let start = Instant::now();
    let mut renderer = Renderer::new(ctx, settings.scene, settings.width, settings.height)?;
    let create_ms = start.elapsed().as_secs_f64() * 1e3;
    let (peak_bytes, held_bytes) = (ctx.memory_peak() - before, ctx.memory_in_use() - before);

    let techniques = techniques();
    let mut images = Vec::new();
    for (label, technique) in techniques {
        step(label);
        for _ in 0..WARM_UP_FRAMES {
            renderer.render_frame(&FrameDesc::from(technique))?;
        }
        images.push(frame(&mut renderer, technique)?);
    }
    // samples[technique] = (gbuffer, lighting without bookkeeping, frame, bookkeeping) per round.
    let mut samples = vec![(Vec::new(), Vec::new(), Vec::new(), Vec::new()); techniques.len()];
    for round in 0..rounds {
        step(&format!("round {} of {rounds}", round + 1));
        for (&(_, shading), s) in techniques.iter().zip(&mut samples) {
            let t = renderer.render_frame(&FrameDesc::from(shading))?.timings;
            let pass = |name| t.pass_ms(name).unwrap_or(0.0);
            s.0.push(pass(histencil_vk::passes::names::GBUFFER));
            s.1.push(t.technique_ms(shading.lighting_passes()));
            s.2.push(t.total_ms());
            s.3.extend(t.bookkeeping_ms);
        }
    }
    let branching = techniques.len() - 1;
    let ratios = (1..branching)
        .map(|i| {
            let per_round = samples[i]
                .1
                .iter()
                .zip(&samples[branching].1)
                .map(|(s, b)| s / b)
                .collect();
            (techniques[i].0, Timing::from_samples(per_round))
        })
        .collect();
    let rows = techniques
        .iter()
        .zip(samples)
        .zip(&images)
        .enumerate()
        .map(
            |(i, (((label, technique), (g, l, f, b)), image))| ScaleRow {
                label,
                shading: *technique,
                gbuffer: Timing::from_samples(g),
                lighting: Timing::from_samples(l),
                bookkeeping: (!b.is_empty()).then(|| Timing::from_samples(b)),
                frame: Timing::from_samples(f),
                error: (i > 0).then(|| image_error(image, &images[0])),
            },
        )
        .collect();
    Ok(ScaleReport {
        device: ctx.device_name().to_owned(),
        driver: ctx.driver().to_string(),
        width: settings.width,
        height: settings.height,
        rounds,
        size,
        load_ms: settings.load_ms,
        create_ms,
        peak_bytes,
        held_bytes,
        rows,
        ratios,
    })
}

fn mib(bytes: u64) -> f64 {
    bytes as f64 / f64::from(1 << 20)
}

impl ScaleReport {
    /// The report in markdown.
    pub fn markdown(&self) -> String {
        let s = &self.size;
        let mut out = format!(
            "{}x{} on {} ({}); {} rounds, one frame of each technique per round; times are GPU \
             timestamps, median (min-max) in ms\n\n",
            self.width, self.height, self.device, self.driver, self.rounds
        );
        let _ = writeln!(
            out,
            "Scene: {} triangles, {} objects, {} materials, {} lights, {} images ({:.1} MiB of \
             meshes and images on the CPU)\n",
            s.triangles,
            s.objects,
            s.materials,
            s.lights,
            s.images,
            mib(s.bytes)
        );
        let _ = writeln!(
            out,
            "Load: scene {:.0} ms, renderer {:.0} ms (uploads, mips, pipelines); device memory \
             {:.1} MiB at peak (staging included), {:.1} MiB held\n",
            self.load_ms,
            self.create_ms,
            mib(self.peak_bytes),
            mib(self.held_bytes)
        );
        out.push_str(
            "| technique | G-buffer | lighting (forward: its pass; emulated backends: the \
             technique + the emulator's bookkeeping) | frame | error vs forward (max / mean, \
             8-bit) |\n|---|---|---|---|---|\n",
        );
        let t = |t: &Timing| format!("{:.2} ({:.2}-{:.2})", t.median_ms, t.min_ms, t.max_ms);
        for r in &self.rows {
            let error = r.error.map_or("reference".to_owned(), |e| {
                format!("{:.0} / {:.4}", e.max, e.mean)
            });
            // Forward draws no G-buffer.
            let gbuffer = if r.shading == Shading::Forward {
                "-".to_owned()
            } else {
                t(&r.gbuffer)
            };
            let lighting = match &r.bookkeeping {
                Some(b) => format!("{} + {}", t(&r.lighting), t(b)),
                None => t(&r.lighting),
            };
            let _ = writeln!(
                out,
                "| {} | {} | {} | {} | {} |",
                r.label,
                gbuffer,
                lighting,
                t(&r.frame),
                error
            );
        }
        out.push_str("\nLighting time over branching's, per round:\n\n");
        for (label, ratio) in &self.ratios {
            let _ = writeln!(
                out,
                "- {label}: {:.3} ({:.3}-{:.3})",
                ratio.median_ms, ratio.min_ms, ratio.max_ms
            );
        }
        out
    }
}
