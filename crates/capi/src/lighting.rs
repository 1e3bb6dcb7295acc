//! The lighting: made once from a description, planned and recorded into the engine's command
//! buffer each frame, told when a slot's frame has finished, resized and destroyed.

use crate::frame::{
    HistencilFrame, HistencilStepTime, HistencilTargets, HISTENCIL_PLATFORM_NATIVE,
    HISTENCIL_PLATFORM_PS3, HISTENCIL_PLATFORM_X360, HISTENCIL_PLATFORM_X360_SAVE_RESTORE,
    HISTENCIL_TECHNIQUE_BRANCHING, HISTENCIL_TECHNIQUE_DEPTH_ID, HISTENCIL_TECHNIQUE_LUT,
    HISTENCIL_TECHNIQUE_STENCIL, HISTENCIL_TECHNIQUE_TILED,
};
use crate::handles::{self, Kind};
use crate::shaders::{brdf_named, shaders_of, HistencilShaders};
use crate::{call, check_size, required, slice, Failure, HistencilResult, Outcome};
use ash::vk;
use histencil::{
    plan_frame, Backend, BrdfModules, BrdfParams, BrdfSource, Context, DeferredLighting,
    EngineHooks, FlushPolicy, HookSetLayout, HookSets, LightHooks, LightingDesc, LightingFrame,
    MixedTiles, PlanInputs, PlanSettings, StencilLayout, TechniqueChoice, TileClassify, TileSide,
    TiledFrame, View,
};
use std::ffi::{c_char, CStr};
use std::sync::Arc;

/// What `histencil_lighting_create` makes a lighting for.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct HistencilLightingDesc {
    /// `sizeof(HistencilLightingDesc)`.
    pub size: u32,
    /// How many BRDFs: each takes one stencil slot, in this order.
    pub brdf_count: u32,
    /// The BRDFs' names, NUL-terminated UTF-8: histencil's own (`lambert`, `ggx`, ...) and
    /// those of `shaders`.
    pub brdf_names: *const *const c_char,
    /// histencil's shaders compiled for the engine's BRDFs and hooks (`histencil_shaders_compile`
    /// or `histencil_shaders_load`), or null for histencil's own BRDFs, G-buffer and no shadows.
    pub shaders: *const HistencilShaders,
    /// How many stencil bits the engine keeps for itself at least (0 to 6): every bit above
    /// histencil's culling bit and BRDF field is the engine's, the bits outside the write mask
    /// `histencil_lighting_stencil_reference` gives. Lighting preserves them on every platform
    /// but `HISTENCIL_PLATFORM_X360`, which zeroes them as the 360 did
    /// (`HISTENCIL_PLATFORM_X360_SAVE_RESTORE` brings them back).
    pub engine_stencil_bits: u32,
    /// The targets' width.
    pub width: u32,
    /// The targets' height.
    pub height: u32,
    /// The depth-stencil image's format (with stencil).
    pub depth_stencil_format: vk::Format,
    /// The HDR image's format (`VK_FORMAT_R16G16B16A16_SFLOAT` for every technique).
    pub hdr_format: vk::Format,
    /// How many frames the engine has in flight: slots 0 to `frames_in_flight - 1`.
    pub frames_in_flight: u32,
    /// The most lights a frame passes.
    pub max_lights: u32,
    /// Non-zero to emulate the consoles' hi-stencil (the PS3-like and 360-like platforms).
    pub hi_stencil: u32,
    /// The layouts the engine binds its hooks' resources with: required when `shaders` were
    /// compiled with hooks, else null (or given, to bind histencil's own decode's G-buffer
    /// images in a set of the engine's).
    pub hooks: *const HistencilHooks,
}

/// The descriptor set layouts an engine binds its hooks' resources with, and the images its
/// decode hook reads. Vulkan cannot be asked what a layout holds, so the engine says: every
/// resource the hooks' shaders declare in sets 1 and 4 is held to these bindings when the
/// lighting is made (the binding exists, its type serves the shader, its count covers the
/// array, it is visible to the stage), and a mismatch is refused naming module, set, binding
/// and types, not left to the driver.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct HistencilHooks {
    /// `sizeof(HistencilHooks)`.
    pub size: u32,
    /// The decode hook's layout (set 1), made by the engine from `decode_bindings`.
    pub decode_layout: vk::DescriptorSetLayout,
    /// How many bindings `decode_layout` was made with.
    pub decode_binding_count: u32,
    /// The `pBindings` `decode_layout` was made with.
    pub decode_bindings: *const vk::DescriptorSetLayoutBinding<'static>,
    /// The visibility hook's layout (set 4), or `VK_NULL_HANDLE` when it reads no resource of
    /// its own (or reads them in set 1, beside the decode's).
    pub visibility_layout: vk::DescriptorSetLayout,
    /// How many bindings `visibility_layout` was made with (0 without one).
    pub visibility_binding_count: u32,
    /// The `pBindings` `visibility_layout` was made with (null without one).
    pub visibility_bindings: *const vk::DescriptorSetLayoutBinding<'static>,
    /// How many images the decode reads: `HistencilTargets.gbuffer_count` each frame.
    pub surface_format_count: u32,
    /// Their formats, in `HistencilTargets.gbuffer` order.
    pub surface_formats: *const vk::Format,
    /// How the decode reads each BRDF's parameters: 0 from the pixel itself (the G-buffer
    /// carries them, or a material index whose row of BRDF id and parameters the hook reads, as
    /// the book's two-target hook does: `histencil_material_rows_write` writes them and
    /// `histencil_lighting_check_materials` holds them to the lighting's BRDFs), else
    /// from rows indexed by BRDF id, ids 0 to `brdf_param_rows - 1` (`BRDF_ID_COUNT` in
    /// `brdf_set/ids.glsl` sizes them). A lighting shading an id without a row is refused: its
    /// surfaces would be unlit with no error anywhere.
    pub brdf_param_rows: u32,
}

/// A lighting made on a context, with the names it was made with.
pub struct HistencilLighting {
    pub(crate) lighting: DeferredLighting<Arc<Context>>,
    /// Each frame's lights, shapes and boxes, converted from the C structs into these, kept
    /// from frame to frame: a frame through C allocates nothing the Rust API's does not.
    lights: Vec<histencil::Light>,
    shapes: Vec<histencil::LightShape>,
    bounds: Vec<Vec<histencil::Aabb>>,
    /// The shaders it lights with, whose set names its BRDFs.
    pub(crate) modules: &'static BrdfModules,
    /// How the tiled techniques classify on this context's driver (the quirk table).
    classify: TileClassify,
    /// The group names `histencil_lighting_step_timings` last handed out.
    step_names: Vec<std::ffi::CString>,
}

/// The most BRDFs a description names: histencil's eight and an engine's sixteen.
const MAX_BRDFS: u32 = 24;
/// The most frames in flight a description asks for.
const MAX_FRAMES_IN_FLIGHT: u32 = 16;

/// `count` NUL-terminated names at `names`, as UTF-8.
///
/// # Safety
/// `names` is null or points at `count` pointers, each null or a NUL-terminated string.
unsafe fn names<'a>(names: *const *const c_char, count: u32, what: &str) -> Outcome<Vec<&'a str>> {
    // SAFETY: this fn's # Safety.
    let pointers = unsafe { slice(names, count, what) }?;
    let mut out = Vec::with_capacity(pointers.len());
    for (i, &p) in pointers.iter().enumerate() {
        if p.is_null() {
            return Err(Failure::invalid(format!("{what}[{i}] is null")));
        }
        // SAFETY: this fn's # Safety: a non-null entry is a NUL-terminated string.
        let name = unsafe { CStr::from_ptr(p) }.to_str();
        out.push(name.map_err(|_| Failure::invalid(format!("{what}[{i}] is not UTF-8")))?);
    }
    Ok(out)
}

fn lighting_desc(desc: &HistencilLightingDesc) -> Outcome<(LightingDesc, &'static BrdfModules)> {
    check_size::<HistencilLightingDesc>("HistencilLightingDesc", desc.size)?;
    let ranges = [
        ("brdf_count", desc.brdf_count, 1, MAX_BRDFS),
        (
            "frames_in_flight",
            desc.frames_in_flight,
            1,
            MAX_FRAMES_IN_FLIGHT,
        ),
    ];
    for (name, value, min, max) in ranges {
        if !(min..=max).contains(&value) {
            return Err(Failure::invalid(format!(
                "HistencilLightingDesc.{name} is {value}, outside {min} to {max}"
            )));
        }
    }
    // SAFETY: the header's contract: `brdf_count` names at `brdf_names`.
    let names = unsafe { names(desc.brdf_names, desc.brdf_count, "brdf_names") }?;
    // SAFETY: the header's contract: null or a live handle.
    let shaders = unsafe { shaders_of(desc.shaders) }?;
    let modules = shaders.map_or(BrdfModules::builtin(), |s| s.modules);
    let brdfs = names
        .into_iter()
        .map(|n| brdf_named(modules, n))
        .collect::<Outcome<Vec<_>>>()?;
    let layout = StencilLayout::new(desc.brdf_count, desc.engine_stencil_bits)
        .map_err(histencil::Error::from)?;
    let desc = LightingDesc {
        layout,
        brdfs,
        extent: vk::Extent2D {
            width: desc.width,
            height: desc.height,
        },
        depth_stencil_format: desc.depth_stencil_format,
        hdr_format: desc.hdr_format,
        frames_in_flight: desc.frames_in_flight,
        max_lights: desc.max_lights,
        hi_stencil: desc.hi_stencil != 0,
        // SAFETY: the header's contract: null or a live struct whose pointers hold what it says.
        hooks: match unsafe { desc.hooks.as_ref() } {
            Some(hooks) => LightHooks::Engine(engine_hooks(hooks, modules)?),
            None if shaders.is_some_and(|s| s.engine_hooks) => {
                return Err(Failure {
                    result: HistencilResult::BadSetup,
                    message: "the shaders call the engine's hooks: HistencilLightingDesc.hooks \
                              gives the layouts their resources are bound with"
                        .into(),
                })
            }
            None if std::ptr::eq(modules, BrdfModules::builtin()) => LightHooks::Builtin,
            None => LightHooks::BuiltinWithBrdfs(modules.light),
        },
    };
    Ok((desc, modules))
}

/// The most bindings a hook layout may list, and images a decode may read.
const MAX_HOOK_BINDINGS: u32 = 64;

/// `hooks` as the Rust API takes them, every pointer and count checked.
fn engine_hooks(hooks: &HistencilHooks, modules: &BrdfModules) -> Outcome<EngineHooks> {
    check_size::<HistencilHooks>("HistencilHooks", hooks.size)?;
    let counts = [
        ("decode_binding_count", hooks.decode_binding_count),
        ("visibility_binding_count", hooks.visibility_binding_count),
        ("surface_format_count", hooks.surface_format_count),
    ];
    for (name, value) in counts {
        if value > MAX_HOOK_BINDINGS {
            return Err(Failure::invalid(format!(
                "HistencilHooks.{name} is {value}, past {MAX_HOOK_BINDINGS}"
            )));
        }
    }
    if hooks.decode_layout == vk::DescriptorSetLayout::null() {
        return Err(Failure::invalid(
            "HistencilHooks.decode_layout is VK_NULL_HANDLE",
        ));
    }
    // SAFETY: the header's contract: each count of entries at its pointer.
    let (decode, visibility, formats) = unsafe {
        (
            slice(
                hooks.decode_bindings,
                hooks.decode_binding_count,
                "decode_bindings",
            )?,
            slice(
                hooks.visibility_bindings,
                hooks.visibility_binding_count,
                "visibility_bindings",
            )?,
            slice(
                hooks.surface_formats,
                hooks.surface_format_count,
                "surface_formats",
            )?,
        )
    };
    let has_visibility = hooks.visibility_layout != vk::DescriptorSetLayout::null();
    if !has_visibility && !visibility.is_empty() {
        return Err(Failure::invalid(
            "HistencilHooks.visibility_bindings are given without a visibility_layout",
        ));
    }
    let decode = HookSetLayout {
        layout: hooks.decode_layout,
        bindings: decode,
    };
    let visibility = has_visibility.then_some(HookSetLayout {
        layout: hooks.visibility_layout,
        bindings: visibility,
    });
    // SAFETY: the header's contract for the layouts (live, made from these bindings on the
    // context's device, outliving the lighting); the modules are this version's shaders.
    let made = unsafe { EngineHooks::new(modules.light, decode, visibility, formats) }?;
    Ok(made.with_brdf_params(match hooks.brdf_param_rows {
        0 => BrdfParams::PerPixel,
        rows => BrdfParams::Rows(rows),
    }))
}

/// Makes a lighting on `context`: its pipeline layout, light volumes, per-slot buffers and sets
/// (light pipelines are made at the first frame that needs them). Nothing is submitted.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle, a null pointer, a wrong `size` or a
/// count out of range; `BAD_SETUP` for a BRDF name neither histencil nor `shaders` holds, more
/// engine stencil bits than the stencil has beside the BRDFs, a zero extent or a depth format
/// without stencil, hooked shaders without `hooks`, a hook resource its layout does not serve
/// (naming module, set and binding), a decode without parameter rows for a BRDF it shades;
/// `DEVICE_LIMIT`, `VULKAN` as the device says.
///
/// Cannot be checked: that `hooks`' layouts are live, were made from exactly the bindings given,
/// on the context's device, and outlive the lighting.
///
/// Thread safety: not at the same time as another call on `context`.
///
/// # Safety
/// `desc` is null or points at a live description whose pointers hold what it says; `lighting`
/// is null or writable; `desc.hooks`, when given, as "cannot be checked" says.
#[no_mangle]
pub unsafe extern "C" fn histencil_lighting_create(
    context: *mut crate::HistencilContext,
    desc: *const HistencilLightingDesc,
    lighting: *mut *mut HistencilLighting,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule: no other call uses `context` now.
        let context = unsafe { handles::get(context, Kind::Context, "context") }?;
        // SAFETY: this fn's # Safety.
        let desc = unsafe { required(desc, "desc") }?;
        if lighting.is_null() {
            return Err(Failure::invalid("lighting (the out pointer) is null"));
        }
        let (desc, modules) = lighting_desc(desc)?;
        let classify = TileClassify::for_context(&context.ctx);
        let made = DeferredLighting::new(context.ctx.clone(), &desc)?;
        let handle = handles::make(
            HistencilLighting {
                lighting: made,
                lights: Vec::new(),
                shapes: Vec::new(),
                bounds: Vec::new(),
                modules,
                classify,
                step_names: Vec::new(),
            },
            Kind::Lighting,
        );
        // SAFETY: checked non-null above; writable by this fn's # Safety.
        unsafe { lighting.write(handle) };
        Ok(())
    })
}

/// The stencil reference and write mask the engine's G-buffer pass draws a surface of BRDF
/// `brdf_name` with (its slot's bits; the engine's own bits are outside the mask).
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle or pointer; `BAD_SETUP` for a BRDF the
/// lighting was not made with.
///
/// Thread safety: not at the same time as another call on `lighting`.
///
/// # Safety
/// `brdf_name` is null or NUL-terminated; `reference` and `write_mask` are null or writable.
#[no_mangle]
pub unsafe extern "C" fn histencil_lighting_stencil_reference(
    lighting: *mut HistencilLighting,
    brdf_name: *const c_char,
    reference: *mut u8,
    write_mask: *mut u8,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        let held = unsafe { handles::get(lighting, Kind::Lighting, "lighting") }?;
        // SAFETY: this fn's # Safety: one NUL-terminated name, or null.
        let name = unsafe { names(&brdf_name, 1, "brdf_name") }?[0];
        if reference.is_null() || write_mask.is_null() {
            return Err(Failure::invalid("reference or write_mask is null"));
        }
        let brdf = brdf_named(held.modules, name)?;
        let (r, m) = held
            .lighting
            .desc()
            .stencil_reference(brdf)
            .ok_or_else(|| Failure {
                result: HistencilResult::BadSetup,
                message: format!("the lighting was not made with BRDF `{name}`"),
            })?;
        // SAFETY: checked non-null; writable by this fn's # Safety.
        unsafe {
            reference.write(r);
            write_mask.write(m);
        }
        Ok(())
    })
}

/// Plans `frame` (which lights to draw, per BRDF, on the platform asked) and records its
/// lighting into `command_buffer`, against `targets`, whose image states it then updates to
/// where the commands leave them. Nothing is submitted; on an error nothing is recorded.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle, a null pointer, a wrong `size`, an
/// unknown technique, platform, light kind or falloff, or counts that do not match;
/// `BAD_FRAME` for a slot past `frames_in_flight`, more lights than `max_lights`, a light or
/// view histencil cannot light with, targets of another extent or format or without the usages
/// the technique needs, a hi-stencil platform on a lighting made without `hi_stencil`, the LUT
/// technique before `histencil_lighting_set_lut_tables`; `IN_FLIGHT` for a slot recorded and
/// not declared finished.
///
/// Cannot be checked (the engine's to keep): that `command_buffer` is recording, outside a
/// render pass, on a graphics and compute queue family of the context's device; that the images
/// are live, of the extent, format and usages they say, and in the states they say when the
/// commands run; that the context outlives the command buffer's execution.
///
/// Thread safety: not at the same time as another call on `lighting`; other lightings may record
/// on other threads.
///
/// # Safety
/// `frame` and `targets` are null or point at live structs whose pointers hold what they say.
#[no_mangle]
pub unsafe extern "C" fn histencil_lighting_record(
    lighting: *mut HistencilLighting,
    command_buffer: vk::CommandBuffer,
    frame: *const HistencilFrame,
    targets: *mut HistencilTargets,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        let held = unsafe { handles::get(lighting, Kind::Lighting, "lighting") }?;
        // SAFETY: this fn's # Safety.
        let frame = unsafe { required(frame, "frame") }?;
        // SAFETY: this fn's # Safety: null or a live, writable struct.
        let c_targets =
            unsafe { targets.as_mut() }.ok_or_else(|| Failure::invalid("targets is null"))?;
        if command_buffer == vk::CommandBuffer::null() {
            return Err(Failure::invalid("command_buffer is VK_NULL_HANDLE"));
        }
        check_size::<HistencilFrame>("HistencilFrame", frame.size)?;
        let mut targets = c_targets.to_targets()?;
        frame.lights_into(&mut held.lights)?;
        let lights = &held.lights;
        let view = frame.view.to_view();
        let slot = frame.slot;
        let clear_hdr = frame.clear_hdr != 0;
        let technique = match frame.technique {
            HISTENCIL_TECHNIQUE_STENCIL => Some(TechniqueChoice::Stencil),
            HISTENCIL_TECHNIQUE_BRANCHING | HISTENCIL_TECHNIQUE_LUT => {
                Some(TechniqueChoice::Branching)
            }
            HISTENCIL_TECHNIQUE_TILED | HISTENCIL_TECHNIQUE_DEPTH_ID => None,
            t => {
                return Err(Failure::invalid(format!(
                    "HistencilFrame.technique is {t}, not a HISTENCIL_TECHNIQUE_* value"
                )))
            }
        };
        let depth_id = frame.technique == HISTENCIL_TECHNIQUE_DEPTH_ID;
        let lut = frame.technique == HISTENCIL_TECHNIQUE_LUT;
        let timestamps = frame.timestamps != 0;
        let set = |s: vk::DescriptorSet| (s != vk::DescriptorSet::null()).then_some(s);
        let hook_sets = HookSets {
            decode: set(frame.decode_set),
            visibility: set(frame.visibility_set),
        };
        let lighting = &mut held.lighting;
        match technique {
            Some(technique) => {
                let backend = match frame.platform {
                    HISTENCIL_PLATFORM_NATIVE => Backend::Native,
                    HISTENCIL_PLATFORM_PS3 => Backend::Ps3,
                    HISTENCIL_PLATFORM_X360 => Backend::X360 {
                        zero_preserved: true,
                        save_restore: false,
                    },
                    HISTENCIL_PLATFORM_X360_SAVE_RESTORE => Backend::X360 {
                        zero_preserved: true,
                        save_restore: true,
                    },
                    p => {
                        return Err(Failure::invalid(format!(
                            "HistencilFrame.platform is {p}, not a HISTENCIL_PLATFORM_* value"
                        )))
                    }
                };
                frame.bounds_into(lighting.desc().brdfs.len(), &mut held.bounds)?;
                held.shapes.clear();
                held.shapes.extend(lights.iter().map(|l| l.shape()));
                let planned_view = View::new(&view).map_err(|e| Failure {
                    result: HistencilResult::BadFrame,
                    message: format!("the view: {e}"),
                })?;
                let inputs = PlanInputs {
                    lights: &held.shapes,
                    brdf_bounds: &held.bounds,
                    view: &planned_view,
                };
                let settings = PlanSettings {
                    technique,
                    caps: backend.platform().caps(),
                    flush: FlushPolicy::Auto,
                };
                let layout = lighting.desc().layout;
                let plan =
                    plan_frame(&layout, &inputs, &settings).map_err(histencil::Error::from)?;
                let frame = LightingFrame {
                    slot,
                    view: &view,
                    lights,
                    plan: &plan,
                    clear_hdr,
                    timestamps,
                    brdf_source: if lut {
                        BrdfSource::Table
                    } else {
                        BrdfSource::Formula
                    },
                    tile_stats: false,
                    hook_sets,
                };
                // SAFETY: the header's contract for this call, which is `record`'s # Safety:
                // a recording command buffer of the context's device, outside a render pass,
                // true image states, a context outliving the execution.
                unsafe { lighting.record(command_buffer, &frame, &mut targets) }?;
            }
            None => {
                let frame = TiledFrame {
                    slot,
                    view: &view,
                    lights,
                    clear_hdr,
                    side: TileSide::Sixteen,
                    mixed: MixedTiles::PerBrdf,
                    classify: held.classify,
                    hook_sets,
                };
                // SAFETY: as above: `record_tiled`'s and `record_depth_id`'s # Safety are
                // `record`'s.
                unsafe {
                    if depth_id {
                        lighting.record_depth_id(command_buffer, &frame, &mut targets)
                    } else {
                        lighting.record_tiled(command_buffer, &frame, &mut targets)
                    }
                }?;
            }
        }
        c_targets.left_as(&targets);
        Ok(())
    })
}

/// Says the GPU has finished the frame last recorded into `slot` (the engine waited for its
/// fence), so the slot may be recorded again and the lighting resized or destroyed once every
/// slot is finished. A slot never recorded, or declared twice, is harmless.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle; `BAD_FRAME` for a slot past
/// `frames_in_flight`.
///
/// Cannot be checked: that the GPU has finished (histencil sees no fence; the engine's word is
/// taken, and a lie frees or rewrites what the GPU still reads).
///
/// Thread safety: not at the same time as another call on `lighting`.
///
/// # Safety
/// Every command buffer that recorded `slot` through this lighting has finished executing, or
/// will never be submitted.
#[no_mangle]
pub unsafe extern "C" fn histencil_lighting_slot_finished(
    lighting: *mut HistencilLighting,
    slot: u32,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        let held = unsafe { handles::get(lighting, Kind::Lighting, "lighting") }?;
        // SAFETY: this fn's # Safety is `slot_finished`'s.
        unsafe { held.lighting.slot_finished(slot) }?;
        Ok(())
    })
}

/// The GPU times of the last frame recorded into `slot` with `HistencilFrame.timestamps`, by
/// group of steps, once the GPU has finished it (waits for the query results). Called with a
/// null `times`, writes how many groups there are into `count`; else writes at most `*count`
/// groups and the number written. 0 groups when that frame had no timestamps.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle or a null `count`; `BAD_FRAME` for a
/// slot past `frames_in_flight`; `VULKAN` when the results cannot be read.
///
/// Cannot be checked: that the frame has finished (the engine's fence).
///
/// Thread safety: not at the same time as another call on `lighting`.
///
/// # Safety
/// `count` is null or writable; `times` is null or holds `*count` writable entries.
#[no_mangle]
pub unsafe extern "C" fn histencil_lighting_step_timings(
    lighting: *mut HistencilLighting,
    slot: u32,
    times: *mut HistencilStepTime,
    count: *mut u32,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        let held = unsafe { handles::get(lighting, Kind::Lighting, "lighting") }?;
        // SAFETY: this fn's # Safety: null or writable.
        let count = unsafe { count.as_mut() }.ok_or_else(|| Failure::invalid("count is null"))?;
        let frames = held.lighting.desc().frames_in_flight;
        if slot >= frames {
            return Err(Failure {
                result: HistencilResult::BadFrame,
                message: format!("slot {slot} is past the lighting's {frames} frames in flight"),
            });
        }
        let groups = held
            .lighting
            .step_timings(slot)?
            .map(|b| b.groups)
            .unwrap_or_default();
        if times.is_null() {
            *count = groups.len() as u32;
            return Ok(());
        }
        held.step_names = (groups.iter())
            .map(|(g, _)| std::ffi::CString::new(g.replace('\0', " ")).expect("no NUL left"))
            .collect();
        let written = groups.len().min(*count as usize);
        for (i, ((_, ms), name)) in groups
            .iter()
            .zip(&held.step_names)
            .take(written)
            .enumerate()
        {
            // SAFETY: this fn's # Safety: `*count` writable entries, `i` below it.
            unsafe {
                times.add(i).write(HistencilStepTime {
                    group: name.as_ptr(),
                    ms: *ms,
                })
            };
        }
        *count = written as u32;
        Ok(())
    })
}

/// Writes 1 to `in_flight` while a slot is recorded and not declared finished, else 0.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle or a null `in_flight`.
///
/// Thread safety: not at the same time as another call on `lighting`.
///
/// # Safety
/// `in_flight` is null or writable.
#[no_mangle]
pub unsafe extern "C" fn histencil_lighting_in_flight(
    lighting: *mut HistencilLighting,
    in_flight: *mut u32,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        let held = unsafe { handles::get(lighting, Kind::Lighting, "lighting") }?;
        if in_flight.is_null() {
            return Err(Failure::invalid("in_flight is null"));
        }
        // SAFETY: checked non-null; writable by this fn's # Safety.
        unsafe { in_flight.write(u32::from(held.lighting.in_flight())) };
        Ok(())
    })
}

/// Makes the lighting fit targets of `width` x `height`, all or nothing.
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle; `BAD_SETUP` for a zero extent;
/// `DEVICE_LIMIT` past the device's image or buffer limits; `IN_FLIGHT` while a slot is not
/// declared finished (the lighting is unchanged).
///
/// Thread safety: not at the same time as another call on `lighting`.
///
/// # Safety
/// `lighting` is null or a handle from `histencil_lighting_create` (a freed one is refused).
#[no_mangle]
pub unsafe extern "C" fn histencil_lighting_resize(
    lighting: *mut HistencilLighting,
    width: u32,
    height: u32,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        let held = unsafe { handles::get(lighting, Kind::Lighting, "lighting") }?;
        held.lighting.resize(vk::Extent2D { width, height })?;
        Ok(())
    })
}

/// Frees the lighting. Refused with `IN_FLIGHT` while a slot is not declared finished: the
/// lighting stays whole and usable (wait for those frames, declare them, destroy again).
///
/// Errors: `INVALID_ARGUMENT` for a null or freed handle; `IN_FLIGHT` as above.
///
/// Thread safety: not at the same time as another call on `lighting`.
///
/// # Safety
/// `lighting` is null or a handle from `histencil_lighting_create` (a freed one is refused).
#[no_mangle]
pub unsafe extern "C" fn histencil_lighting_destroy(
    lighting: *mut HistencilLighting,
) -> HistencilResult {
    call(|| {
        // SAFETY: the header's thread-safety rule.
        let held = unsafe { handles::get(lighting, Kind::Lighting, "lighting") }?;
        // Refused before the handle is taken, so the lighting stays whole.
        crate::refuse_destroy_in_flight(
            held.lighting.in_flight(),
            "histencil_lighting_slot_finished",
        )?;
        // SAFETY: as above.
        let held = unsafe { handles::take(lighting, Kind::Lighting, "lighting") }?;
        held.lighting
            .destroy()
            .map_err(|refused| Failure::from(refused.error))?;
        Ok(())
    })
}
