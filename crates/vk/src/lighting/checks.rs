//! What a lighting refuses, and why: descriptions, frames and targets that do not fit, held
//! before anything is made or recorded.

use super::{LightingDesc, LightingFrame};
use crate::gpu::access::{ImageRef, LightingTargets};
use crate::gpu::device::error::{Error, Result};
use crate::gpu::frame::targets::GBUFFER_FORMATS;
use crate::lighting::hooks::{HookSets, LightHooks};
use ash::vk;
use histencil_model::{FramePlan, PassKind, Shader, Step};

pub(super) fn bad(message: String) -> Error {
    Error::BadFrame(message)
}

pub(super) fn bad_setup(message: String) -> Error {
    Error::BadSetup(message)
}

pub(super) fn check_desc(desc: &LightingDesc) -> Result<()> {
    let e = desc.extent;
    if e.width == 0 || e.height == 0 {
        return Err(bad_setup(format!(
            "a {}x{} lighting extent",
            e.width, e.height
        )));
    }
    if !crate::gpu::access::aspect_of(desc.depth_stencil_format)
        .contains(vk::ImageAspectFlags::STENCIL)
    {
        return Err(bad_setup(format!(
            "depth format {:?} has no stencil for the BRDF ids",
            desc.depth_stencil_format
        )));
    }
    if desc.frames_in_flight == 0 {
        return Err(bad_setup("frames_in_flight must be at least 1".into()));
    }
    for (slot, brdf) in desc.brdfs.iter().enumerate() {
        if let Some(first) = desc.brdfs[..slot].iter().position(|b| b == brdf) {
            return Err(bad_setup(format!(
                "{brdf:?} is in BRDF slots {first} and {slot}: one slot per BRDF, so that a BRDF id \
                 names one slot"
            )));
        }
    }
    // A BRDF the light shaders were not compiled with would shade its pixels black in silence.
    let modules = desc.hooks.modules();
    let compiled = || modules.brdfs.iter().zip(modules.brdf_names);
    if let Some(missing) = desc
        .brdfs
        .iter()
        .find(|b| !compiled().any(|(i, n)| *i == b.index() && *n == b.name()))
    {
        let known: Vec<String> = compiled().map(|(i, n)| format!("{n} ({i})")).collect();
        return Err(bad_setup(format!(
            "BRDF `{missing}` (id {}) is not one the light shaders were compiled with ({}): \
             compile them for the engine's BRDF set \
             (histencil_build::compile_light_shaders_for, or histencil::compile_brdf_set with \
             LightHooks::BuiltinWithBrdfs)",
            missing.index(),
            known.join(", ")
        )));
    }
    // Each of the layout's BRDF slots is shaded with the BRDF at its index: a slot with none
    // would have nothing to shade with (a plan's passes name slots, not BRDFs).
    // (A layout has at least one slot: a lighting of no BRDFs, a scene of translucent objects
    // alone, shades nothing, and its plans' indices are held at every frame.)
    let slots = desc.layout.brdfs_in_use() as usize;
    if !desc.brdfs.is_empty() && desc.brdfs.len() != slots {
        return Err(bad_setup(format!(
            "{} BRDFs for a stencil layout with {slots} BRDF slots: give one BRDF per slot \
             (StencilLayout::new with the number of BRDFs)",
            desc.brdfs.len()
        )));
    }
    Ok(())
}

/// Checks that every index a plan holds points into what it indexes: a step's light into the
/// plan's lights, each planned light into the frame's, each pass's BRDF slot into the
/// lighting's BRDFs. A plan is plain data an engine may build or edit by hand, so the recording
/// holds it to these before indexing with them (an index past the end would panic).
pub(super) fn check_plan_indices(
    desc: &LightingDesc,
    plan: &FramePlan,
    lights: usize,
) -> Result<()> {
    if let Some(l) = plan.lights.iter().find(|l| l.input >= lights) {
        return Err(bad(format!(
            "the plan lights input {} of {lights} lights",
            l.input
        )));
    }
    let slots = desc.brdfs.len();
    for (index, step) in plan.steps.iter().enumerate() {
        let Step::Pass { light, pass } = step else {
            continue;
        };
        if *light >= plan.lights.len() {
            return Err(bad(format!(
                "step {index} of the plan draws light {light} of its {} planned lights",
                plan.lights.len()
            )));
        }
        if let PassKind::Mask(Shader::Brdf(slot)) | PassKind::Shade(Shader::Brdf(slot)) = pass.kind
        {
            if slot as usize >= slots {
                return Err(bad(format!(
                    "step {index} of the plan shades BRDF slot {slot}, and this lighting has \
                     {slots} BRDF slots (LightingDesc::brdfs): was the plan made for another \
                     stencil layout?"
                )));
            }
        }
    }
    Ok(())
}

/// Whether recording `plan` needs the hi-stencil emulation: a hi-stencil test, write or flush,
/// or the stencil copy of a 360-like save/restore.
pub(super) fn needs_hi_stencil(plan: &FramePlan) -> bool {
    plan.steps.iter().any(|step| match step {
        Step::Pass { pass, .. } => pass.state.tests_hi_stencil() || pass.state.writes_hi_stencil(),
        Step::FlushHiStencil | Step::SavePreserved { .. } | Step::RestorePreserved { .. } => true,
    })
}

/// Whether `plan` writes hi-stencil: its tile updates read the frame's stencil.
pub(super) fn writes_hi_stencil(plan: &FramePlan) -> bool {
    plan.passes().any(|pass| pass.state.writes_hi_stencil())
}

/// Checks one frame against the lighting's description: the slot, the light count, the plan's
/// light indices and depth convention, and every target's extent and format.
pub(super) fn check_frame(
    desc: &LightingDesc,
    frame: &LightingFrame,
    targets: &LightingTargets,
) -> Result<()> {
    check_slot_view_and_lights(desc, frame.slot, frame.view, frame.lights)?;
    check_plan_indices(desc, frame.plan, frame.lights.len())?;
    if !desc.hi_stencil && needs_hi_stencil(frame.plan) {
        return Err(bad(
            "the plan uses hi-stencil (a PS3-like or 360-like backend), and this lighting was \
             made without it (LightingDesc::hi_stencil)"
                .into(),
        ));
    }
    // The light shader rejects a console's tiles after the early depth and stencil tests, which
    // would already have written stencil: the emulation would diverge from the model. (A GPU
    // hierarchy's rejected tile holds no fragment passing the stencil test, so it cannot.)
    if (frame.plan.passes()).any(|p| p.state.tests_hi_stencil() && p.state.writes_stencil()) {
        return Err(Error::Unsupported(
            "a hi-stencil test in a pass that writes stencil",
        ));
    }
    if frame.plan.depth != frame.view.depth {
        return Err(bad(format!(
            "the plan is for {:?} depth, the view is {:?}",
            frame.plan.depth, frame.view.depth
        )));
    }
    // A plan made for another view or other lights records without complaint and lights the
    // frame wrong: hold it to what it was made for.
    if let Some(made_for) = &frame.plan.made_for {
        let shapes = frame.lights.iter().map(|l| l.shape());
        if let Some(difference) = made_for.difference(frame.view, shapes, &desc.layout) {
            return Err(bad(difference));
        }
    }
    check_targets(desc, &frame.hook_sets, targets)
}

/// What every recording of histencil refuses of a frame's view and lights, said as its refusal
/// does (`the view: ...`, `light 3: ...`): a view the planner cannot use (not finite, singular,
/// no near plane) or a light a scene's validation refuses. The lighting's and the lightmaps'
/// record paths ask it, and an engine can ask it of the inputs its own forward reference shades
/// with (the C API's `histencil_shading_inputs` does), so that a frame histencil refuses is never
/// compared with one shaded from NaN.
pub fn frame_inputs_problem(
    view: &histencil_model::ViewDesc,
    lights: &[histencil_scene::Light],
) -> Option<String> {
    if let Err(e) = histencil_model::View::new(view) {
        return Some(format!("the view: {e}"));
    }
    (lights.iter().enumerate()).find_map(|(i, l)| l.problem().map(|p| format!("light {i}: {p}")))
}

/// Checks a frame's slot, view and lights against the lighting's description: the count, the
/// view as the planner holds it, and every light as a scene's validation holds it. A view or a
/// light made NaN after its frame was planned, or given to a technique that plans nothing (the
/// tiled and depth-id ones), is refused here, not shaded as nothing.
pub(super) fn check_slot_view_and_lights(
    desc: &LightingDesc,
    slot: u32,
    view: &histencil_model::ViewDesc,
    lights: &[histencil_scene::Light],
) -> Result<()> {
    if let Some(problem) = frame_inputs_problem(view, lights) {
        return Err(bad(problem));
    }
    let lights = lights.len();
    if slot >= desc.frames_in_flight {
        return Err(bad(format!(
            "slot {slot} of {} frames in flight",
            desc.frames_in_flight
        )));
    }
    if lights > desc.max_lights as usize {
        return Err(bad(format!(
            "{lights} lights, more than the {} this lighting was made for",
            desc.max_lights
        )));
    }
    Ok(())
}

/// The image usages a recording needs of each target, each with the reason (for the refusal).
#[derive(Default)]
pub(super) struct UsageNeeds {
    pub gbuffer: Vec<(vk::ImageUsageFlags, &'static str)>,
    pub depth_stencil: Vec<(vk::ImageUsageFlags, &'static str)>,
    pub hdr: Vec<(vk::ImageUsageFlags, &'static str)>,
}

impl UsageNeeds {
    /// The talk's light passes recording `plan`; `hierarchy` when an AMD GPU's tiles are
    /// emulated (its tile updates read the stencil like the consoles').
    pub fn light_passes(desc: &LightingDesc, plan: &FramePlan, hierarchy: bool) -> Self {
        use vk::ImageUsageFlags as U;
        let mut needs = Self {
            gbuffer: vec![(U::SAMPLED, "the light shaders sample it")],
            depth_stencil: vec![(U::DEPTH_STENCIL_ATTACHMENT, "the light passes attach it")],
            hdr: vec![(U::COLOR_ATTACHMENT, "the light passes add light into it")],
        };
        if writes_hi_stencil(plan) || hierarchy {
            let why = "the hi-stencil emulation's tile update reads its stencil";
            needs.depth_stencil.push((U::SAMPLED, why));
        }
        if desc.hooks.samples_depth() {
            let why = "the engine's decode hook samples its depth";
            needs.depth_stencil.push((U::SAMPLED, why));
        }
        if (plan.steps.iter()).any(|s| matches!(s, Step::SavePreserved { .. })) {
            let why = "the 360-like save copies its stencil out";
            needs.depth_stencil.push((U::TRANSFER_SRC, why));
        }
        needs
    }

    /// The tiled technique's kernels and the depth-id technique's passes (alike here: both
    /// sample the G-buffer, store into the HDR image and, with a decode hook that reads depth,
    /// read it in the light passes' read-only layout).
    pub fn tiled(desc: &LightingDesc) -> Self {
        use vk::ImageUsageFlags as U;
        let mut needs = Self {
            gbuffer: vec![(U::SAMPLED, "the tile classification and shading sample it")],
            depth_stencil: Vec::new(),
            hdr: vec![(U::STORAGE, "the tiled shading stores light into it")],
        };
        if desc.hooks.samples_depth() {
            let why = "the engine's decode hook samples its depth";
            needs.depth_stencil.push((U::SAMPLED, why));
            let why = "its depth is read in DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL, a layout \
                       Vulkan allows only for attachments";
            needs.depth_stencil.push((U::DEPTH_STENCIL_ATTACHMENT, why));
        }
        needs
    }
}

/// Refuses a target made without a usage its recording needs, naming the usage and why: Vulkan
/// itself would only say so after histencil's barriers and views were recorded wrong.
pub(super) fn check_usage(targets: &LightingTargets, needs: &UsageNeeds) -> Result<()> {
    let check = |what: &str, image: &ImageRef, needs: &[(vk::ImageUsageFlags, &str)]| match needs
        .iter()
        .find(|(u, _)| !image.usage.contains(*u))
    {
        Some((usage, why)) => Err(bad(format!(
            "{what} was made without {usage:?} usage (it has {:?}), and {why}",
            image.usage
        ))),
        None => Ok(()),
    };
    for (i, image) in targets.gbuffer.iter().enumerate() {
        check(&format!("G-buffer image {i}"), image, &needs.gbuffer)?;
    }
    check(
        "the depth-stencil target",
        &targets.depth_stencil,
        &needs.depth_stencil,
    )?;
    check("the HDR target", &targets.hdr, &needs.hdr)
}

/// Checks the hook sets and every target's extent and format against the description.
pub(super) fn check_targets(
    desc: &LightingDesc,
    hook_sets: &HookSets,
    targets: &LightingTargets,
) -> Result<()> {
    let expect = |what: &str, image: &ImageRef, format: vk::Format| {
        if image.extent != desc.extent {
            return Err(bad(format!(
                "{what} is {}x{}, the lighting {}x{}",
                image.extent.width, image.extent.height, desc.extent.width, desc.extent.height
            )));
        }
        if image.format != format {
            return Err(bad(format!(
                "{what} is {:?}, the lighting expects {format:?}",
                image.format
            )));
        }
        Ok(())
    };
    desc.hooks.check_sets(hook_sets)?;
    if desc.hooks.is_builtin_decode() {
        let names = [
            "G-buffer albedo",
            "G-buffer normal-depth",
            "G-buffer material",
        ];
        if targets.gbuffer.len() != names.len() {
            return Err(bad(format!(
                "{} G-buffer images, and histencil's G-buffer has {}",
                targets.gbuffer.len(),
                names.len()
            )));
        }
        for ((image, name), format) in targets.gbuffer.iter().zip(names).zip(GBUFFER_FORMATS) {
            expect(name, image, format)?;
        }
    } else if let LightHooks::Engine(engine) = &desc.hooks {
        // The decode reads these through the engine's set; the lighting barriers each one for
        // the light shaders' reads, so one left out would be read in whatever layout it was.
        let formats = &engine.surface_formats;
        if targets.gbuffer.len() != formats.len() {
            return Err(bad(format!(
                "{} surface images in LightingTargets::gbuffer, and the engine's decode hook \
                 reads {} (EngineHooks::new's surface formats)",
                targets.gbuffer.len(),
                formats.len()
            )));
        }
        for (i, (image, format)) in targets.gbuffer.iter().zip(formats).enumerate() {
            expect(&format!("surface image {i}"), image, *format)?;
        }
    }
    expect(
        "the depth-stencil target",
        &targets.depth_stencil,
        desc.depth_stencil_format,
    )?;
    expect("the HDR target", &targets.hdr, desc.hdr_format)
}
