//! The light shaders' two hooks, for engines whose G-buffer or shadows are their own.
//!
//! histencil's deferred light shaders get each pixel's surface from a *decode hook*
//! (`surface_decode.glsl`) and scale each light by a *visibility hook*
//! (`light_visibility.glsl`). Built in, the decode reads histencil's G-buffer
//! ([`crate::GBUFFER_FORMATS`]) and every light is unshadowed. An engine writes either hook in
//! GLSL, compiles the light shaders with them at its build (`histencil_build`), and makes its
//! [`crate::DeferredLighting`] with [`LightHooks::Engine`]: its decode's resources in set 1 and
//! its visibility's in set 4, each in a descriptor set layout of its own, and the sets bound per
//! frame from [`HookSets`]. Why build time: see `histencil_build`.

use crate::gpu::device::context::Context;
use crate::gpu::device::descriptors::{layout_bindings, GBUFFER_SET, GRAPHICS_STAGES};
use crate::gpu::device::error::{Error, Result};
use crate::gpu::device::spirv_bindings::{reflect_bindings, Resource};
pub use crate::passes::light_modules::LightModules;
use ash::vk;
use histencil_brdf::BrdfId;
use std::io::Cursor;

/// Where a lighting's shaders get surfaces and visibility from (fixed for its life).
#[derive(Clone, Debug, Default)]
pub enum LightHooks {
    /// histencil's G-buffer ([`crate::GBUFFER_FORMATS`], written through `gbuffer_write.glsl`),
    /// every light unshadowed.
    #[default]
    Builtin,
    /// histencil's G-buffer and no shadows, as [`LightHooks::Builtin`], with the light shaders
    /// compiled for a BRDF set of the engine's (`BrdfModules::light`, from
    /// [`crate::compile_brdf_set`] or histencil-build).
    BuiltinWithBrdfs(LightModules),
    /// The engine's hooks (their modules compiled with its BRDF set, if it has one).
    Engine(EngineHooks),
}

/// A descriptor set layout of the engine's and the bindings it was created from: Vulkan cannot
/// be asked what a layout holds, so the engine says, and histencil holds its hooks' SPIR-V to it.
#[derive(Clone, Copy, Debug)]
pub struct HookSetLayout<'a> {
    /// The layout, created by the engine from `bindings`.
    pub layout: vk::DescriptorSetLayout,
    /// The `pBindings` the layout was created with.
    pub bindings: &'a [vk::DescriptorSetLayoutBinding<'a>],
}

/// An engine's compiled hooks, the descriptor set layouts their resources are bound with, and
/// the images its decode hook reads.
#[derive(Clone, Debug)]
pub struct EngineHooks {
    pub(crate) modules: LightModules,
    pub(crate) decode_layout: vk::DescriptorSetLayout,
    pub(crate) visibility_layout: Option<vk::DescriptorSetLayout>,
    /// The formats of the images the decode hook reads, in [`crate::LightingTargets::gbuffer`]
    /// order.
    pub(crate) surface_formats: Box<[vk::Format]>,
    /// Why the tiled technique's kernels cannot bind these layouts, if they cannot (a binding
    /// the kernels read is not visible to the compute stage).
    pub(crate) tiled_refusal: Option<String>,
    /// What the decode and visibility layouts hold, from their bindings: what the pipeline
    /// layouts made with them are checked against the device's limits with.
    /// (Shared: the hooks are cloned into every lighting, and kept small.)
    pub(crate) layout_counts: LayoutCounts,
    /// How the decode hook reads each BRDF's parameters ([`EngineHooks::with_brdf_params`]).
    pub(crate) brdf_params: Option<BrdfParams>,
}

/// How an engine's decode hook reads each pixel's BRDF parameters (`Surface::params`), which a
/// lighting holds against the BRDF ids it shades: a hook with rows for ids 0 to 7 reads nothing
/// for an engine BRDF's id 8, and its surfaces come out unlit with no error anywhere.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BrdfParams {
    /// From the pixel itself (the G-buffer carries them, as `examples/engine`'s compact
    /// G-buffer does): every id.
    PerPixel,
    /// From rows indexed by the BRDF id (`BrdfId::index`), each a `Brdf::packed_params`: ids 0
    /// to `rows - 1`. Size them from the set: `BRDF_ID_COUNT` in `brdf_set/ids.glsl`. Every
    /// surface of a BRDF then shares its parameters.
    Rows(u32),
    /// From rows indexed by a material index the G-buffer carries, each a BRDF id and its
    /// parameters ([`histencil_brdf::MaterialRows`]): materials of one BRDF keep their own
    /// parameters. The rows are the engine's data, so they are held to a lighting by
    /// [`crate::DeferredLighting::check_materials`], not here.
    Materials,
}

/// What each of an engine's layouts holds ([`EngineHooks::register_layouts`]).
pub(crate) type LayoutCounts = std::sync::Arc<
    Vec<(
        vk::DescriptorSetLayout,
        Vec<crate::gpu::device::limits::SetCounts>,
    )>,
>;

impl EngineHooks {
    /// Tells `ctx` what the engine's layouts hold, so the pipeline layouts made with them are
    /// checked against the device's limits like histencil's own.
    pub(crate) fn register_layouts(&self, ctx: &crate::Context) {
        let mut known = ctx.set_counts.lock().unwrap_or_else(|e| e.into_inner());
        for (layout, counts) in self.layout_counts.iter() {
            known.insert(*layout, counts.clone());
        }
    }
}

impl EngineHooks {
    /// The engine's light shaders (from `histencil_build`), its decode hook's set layout (set 1)
    /// and, when its visibility hook reads resources, that hook's set layout (set 4), and the
    /// formats of the images the decode reads (which the engine then passes, in that order, as
    /// [`crate::LightingTargets::gbuffer`], so that each frame barriers them for the light
    /// shaders' reads).
    ///
    /// Every resource each module declares in sets 1 and 4 is held to the layout's bindings:
    /// the binding exists, its descriptor type serves the shader's resource, its count covers
    /// the shader's array, and it is visible to the module's stage (to the compute stage only
    /// where the tiled technique is recorded: without it [`crate::DeferredLighting::record_tiled`]
    /// is refused, not crashed). Sets 0, 2 and 3 are histencil's: a module must declare there what
    /// histencil's own declares.
    ///
    /// # Errors
    /// [`Error::BadSetup`] naming the module, set, binding and types when a module is not SPIR-V,
    /// reads a binding its layout lacks or declares differently, or reads set 4 without a
    /// visibility layout.
    ///
    /// # Safety
    /// The layouts are live, created from exactly the bindings given, on the device of every
    /// context a lighting is made on with these hooks, and outlive those lightings; the modules
    /// were compiled by `histencil_build` from this version of histencil-vk's shaders.
    pub unsafe fn new(
        modules: LightModules,
        decode: HookSetLayout,
        visibility: Option<HookSetLayout>,
        surface_formats: &[vk::Format],
    ) -> Result<Self> {
        let layouts = HookLayouts {
            decode: decode.bindings,
            visibility: visibility.map(|v| v.bindings),
        };
        let tiled_refusal = check_modules(&modules, &layouts)?;
        let mut layout_counts = vec![(
            decode.layout,
            crate::gpu::device::limits::SetCounts::of_bindings(decode.bindings),
        )];
        layout_counts.extend(visibility.map(|v| {
            (
                v.layout,
                crate::gpu::device::limits::SetCounts::of_bindings(v.bindings),
            )
        }));
        Ok(Self {
            modules,
            decode_layout: decode.layout,
            visibility_layout: visibility.map(|v| v.layout),
            surface_formats: surface_formats.into(),
            tiled_refusal,
            layout_counts: std::sync::Arc::new(layout_counts),
            brdf_params: None,
        })
    }

    /// Says how the decode hook reads each BRDF's parameters, so that a lighting shading an id
    /// the hook has no row for is refused at creation, naming the ids and the rows. Hooks that do
    /// not say are taken to have a row for each built-in id (0 to 7, the book's first hooks)
    /// and are refused for an engine BRDF's.
    pub fn with_brdf_params(mut self, params: BrdfParams) -> Self {
        self.brdf_params = Some(params);
        self
    }
}

/// The bindings of sets 1 and 4, as the layouts were made.
pub(crate) struct HookLayouts<'a> {
    pub decode: &'a [vk::DescriptorSetLayoutBinding<'a>],
    pub visibility: Option<&'a [vk::DescriptorSetLayoutBinding<'a>]>,
}

/// The set an engine's decode hook binds its resources in.
pub const DECODE_SET: u32 = 1;
/// The set an engine's visibility hook binds its resources in.
pub const VISIBILITY_SET: u32 = 4;

/// Holds every module's declared resources to the layouts (histencil's own modules for sets 0,
/// 2 and 3). Returns why the tiled kernels cannot be used with them, if they cannot.
pub(crate) fn check_modules(
    modules: &LightModules,
    layouts: &HookLayouts,
) -> Result<Option<String>> {
    let mut tiled_refusal = None;
    for ((name, spirv), (_, own)) in modules
        .named()
        .into_iter()
        .zip(LightModules::BUILTIN.named())
    {
        let setup = |e: String| Error::BadSetup(format!("{name}: {e}"));
        let reflected = spirv_words(spirv)
            .and_then(|w| reflect_bindings(&w))
            .map_err(setup)?;
        let histencils = spirv_words(own)
            .and_then(|w| reflect_bindings(&w))
            .expect("histencil's own modules are SPIR-V");
        // The pipeline takes the module as its stage: a module of another stage, or none,
        // would reach pipeline creation with no entry point for it.
        if reflected.stages != histencils.stages {
            return Err(setup(format!(
                "a module of stage {:?}, where histencil's {name} is {:?} (from                  histencil_build's modules of this version?)",
                reflected.stages, histencils.stages
            )));
        }
        for resource in &reflected.resources {
            let declared = match resource.set {
                DECODE_SET => Some(("the decode layout (set 1)", layouts.decode)),
                VISIBILITY_SET => layouts
                    .visibility
                    .map(|b| ("the visibility layout (set 4)", b)),
                _ => None,
            };
            let problem = match declared {
                Some((layout, bindings)) => {
                    match check_binding(resource, bindings, reflected.stages) {
                        Ok(()) => continue,
                        Err(Mismatch::Stage(stages))
                            if reflected.stages == vk::ShaderStageFlags::COMPUTE =>
                        {
                            let why = format!(
                                "{name} (the tiled technique) reads {} and {layout} makes it \
                             visible to {stages:?} only, not COMPUTE",
                                resource_words(resource)
                            );
                            tiled_refusal.get_or_insert(why);
                            continue;
                        }
                        Err(m) => {
                            format!("{}, and {layout} {}", resource_words(resource), m.words())
                        }
                    }
                }
                None if resource.set == VISIBILITY_SET => format!(
                    "{}, and the hooks have no visibility layout",
                    resource_words(resource)
                ),
                None if histencils
                    .resources
                    .iter()
                    .any(|r| same_slot(r, resource) && r.kind == resource.kind) =>
                {
                    continue
                }
                None => format!(
                    "{}, and set {} is histencil's: a decode hook binds set {DECODE_SET}, a \
                     visibility hook set {VISIBILITY_SET}",
                    resource_words(resource),
                    resource.set
                ),
            };
            return Err(setup(format!("reads {problem}")));
        }
    }
    Ok(tiled_refusal)
}

fn same_slot(a: &Resource, b: &Resource) -> bool {
    (a.set, a.binding) == (b.set, b.binding)
}

/// "set 1 binding 3 (`shadow_atlas`), a sampled image (texture2D)".
fn resource_words(r: &Resource) -> String {
    let name = if r.name.is_empty() {
        String::new()
    } else {
        format!(" (`{}`)", r.name)
    };
    let array = match r.count {
        1 => String::new(),
        0 => " in a runtime-sized array".to_owned(),
        n => format!(" in an array of {n}"),
    };
    format!(
        "set {} binding {}{name}, {}{array}",
        r.set,
        r.binding,
        r.kind.describe()
    )
}

/// How a layout's binding fails a module's resource.
enum Mismatch {
    Missing,
    Type(vk::DescriptorType),
    Count(u32),
    Stage(vk::ShaderStageFlags),
}

impl Mismatch {
    fn words(&self) -> String {
        match self {
            Mismatch::Missing => "has no such binding".into(),
            Mismatch::Type(ty) => format!("declares it {ty:?}"),
            Mismatch::Count(n) => format!("declares {n} descriptors there"),
            Mismatch::Stage(s) => format!("makes it visible to {s:?} only"),
        }
    }
}

fn check_binding(
    resource: &Resource,
    bindings: &[vk::DescriptorSetLayoutBinding],
    stages: vk::ShaderStageFlags,
) -> std::result::Result<(), Mismatch> {
    let b = bindings
        .iter()
        .find(|b| b.binding == resource.binding)
        .ok_or(Mismatch::Missing)?;
    if !resource.kind.accepts(b.descriptor_type) {
        return Err(Mismatch::Type(b.descriptor_type));
    }
    if b.descriptor_count < resource.count.max(1) {
        return Err(Mismatch::Count(b.descriptor_count));
    }
    if !b.stage_flags.contains(stages) {
        return Err(Mismatch::Stage(b.stage_flags));
    }
    Ok(())
}

/// The SPIR-V words of `bytes`, or why they are not SPIR-V.
pub(crate) fn spirv_words(bytes: &[u8]) -> std::result::Result<Vec<u32>, String> {
    ash::util::read_spv(&mut Cursor::new(bytes)).map_err(|e| format!("not SPIR-V ({e})"))
}

/// The engine's descriptor sets for one frame's hooks.
#[derive(Clone, Copy, Debug, Default)]
pub struct HookSets {
    /// Bound at set 1 for the decode hook: required with [`LightHooks::Engine`], absent with
    /// [`LightHooks::Builtin`] (histencil writes its own G-buffer set).
    pub decode: Option<vk::DescriptorSet>,
    /// Bound at set 4 for the visibility hook: required exactly when the hooks have a
    /// visibility layout.
    pub visibility: Option<vk::DescriptorSet>,
}

impl LightHooks {
    /// Whether surfaces come from histencil's own G-buffer (no engine hooks).
    pub(crate) fn is_builtin_decode(&self) -> bool {
        !matches!(self, LightHooks::Engine(_))
    }

    /// The modules the light pipelines are made from.
    pub(crate) fn modules(&self) -> LightModules {
        match self {
            LightHooks::Builtin => LightModules::BUILTIN,
            LightHooks::BuiltinWithBrdfs(modules) => *modules,
            LightHooks::Engine(e) => e.modules,
        }
    }

    /// Whether the decode may sample the depth aspect of the depth-stencil attachment, which the
    /// lighting pass then holds in `DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL`.
    pub(crate) fn samples_depth(&self) -> bool {
        matches!(self, LightHooks::Engine(_))
    }

    /// The visibility set layout, if any.
    pub(crate) fn visibility_layout(&self) -> Option<vk::DescriptorSetLayout> {
        match self {
            LightHooks::Builtin | LightHooks::BuiltinWithBrdfs(_) => None,
            LightHooks::Engine(e) => e.visibility_layout,
        }
    }

    /// Refuses hooks the device cannot bind: a visibility set is the fifth set of the light
    /// pipelines' layout, and Vulkan only guarantees four.
    /// With histencil's built-in decode, also holds histencil's own light modules to its
    /// G-buffer layout by the check engines' hooks get ([`EngineHooks::new`]).
    pub(crate) fn check(&self, ctx: &Context) -> Result<()> {
        if self.is_builtin_decode() {
            let stages = GRAPHICS_STAGES | vk::ShaderStageFlags::COMPUTE;
            let gbuffer = layout_bindings(GBUFFER_SET, stages);
            let layouts = HookLayouts {
                decode: &gbuffer,
                visibility: None,
            };
            if let Some(why) = check_modules(&self.modules(), &layouts)? {
                return Err(Error::BadSetup(why));
            }
        }
        let sets = if self.visibility_layout().is_some() {
            5
        } else {
            4
        };
        // How many sets a pipeline layout may hold (an engine's visibility hook needs 5).
        let bindable = ctx
            .device_limits()
            .get(crate::gpu::device::limits::Limit::BoundDescriptorSets);
        if sets > bindable {
            return Err(Error::DeviceLimit(format!(
                "a visibility hook binds set 4, and this device binds at most {} sets (the \
                 spec's minimum is 4): declare the visibility hook's resources in the decode \
                 hook's set 1 instead (its layout, its sets), and give the hooks no visibility \
                 layout",
                bindable
            )));
        }
        Ok(())
    }

    /// Refuses BRDF ids the decode hook reads no parameters for ([`BrdfParams`]).
    pub(crate) fn check_ids(&self, brdfs: &[BrdfId]) -> Result<()> {
        let LightHooks::Engine(e) = self else {
            return Ok(());
        };
        let builtins = BrdfId::ALL.len() as u32;
        let (rows, said) = match e.brdf_params {
            Some(BrdfParams::PerPixel | BrdfParams::Materials) => return Ok(()),
            Some(BrdfParams::Rows(rows)) => (rows, true),
            None => (builtins, false),
        };
        let past: Vec<String> = (brdfs.iter())
            .filter(|b| b.index() >= rows)
            .map(|b| format!("`{b}` (id {})", b.index()))
            .collect();
        if past.is_empty() {
            return Ok(());
        }
        let declared = if said {
            format!("the decode hook reads {rows} BRDF rows (EngineHooks::with_brdf_params)")
        } else {
            format!(
                "the decode hook did not say how it reads BRDF parameters, so it is taken to \
                 have the built-ins' {builtins} rows (EngineHooks::with_brdf_params)"
            )
        };
        Err(Error::BadSetup(format!(
            "{declared}, and the lighting shades {}: those pixels would read no parameters \
             and come out unlit. Size the hook's rows from the set (BRDF_ID_COUNT in \
             brdf_set/ids.glsl) and say BrdfParams::Rows(BRDF_ID_COUNT), BrdfParams::Materials \
             for rows per material, or BrdfParams::PerPixel \
             when the G-buffer carries them",
            past.join(", ")
        )))
    }

    /// Why the tiled technique cannot be recorded with these hooks, if it cannot.
    pub(crate) fn tiled_refusal(&self) -> Option<&str> {
        match self {
            LightHooks::Builtin | LightHooks::BuiltinWithBrdfs(_) => None,
            LightHooks::Engine(e) => e.tiled_refusal.as_deref(),
        }
    }

    /// Checks a frame's sets against the hooks.
    pub(crate) fn check_sets(&self, sets: &HookSets) -> Result<()> {
        let bad = |m: &str| Err(Error::BadFrame(m.to_owned()));
        match self {
            _ if self.is_builtin_decode() && (sets.decode.is_some() || sets.visibility.is_some()) => {
                bad("hook sets for a lighting with histencil's built-in hooks")
            }
            LightHooks::Builtin | LightHooks::BuiltinWithBrdfs(_) => Ok(()),
            LightHooks::Engine(_) if sets.decode.is_none() => {
                bad("no decode set for a lighting with the engine's decode hook (HookSets::decode)")
            }
            LightHooks::Engine(e) if e.visibility_layout.is_some() != sets.visibility.is_some() => {
                bad("HookSets::visibility must be given exactly when the hooks have a visibility layout")
            }
            LightHooks::Engine(_) => Ok(()),
        }
    }
}
