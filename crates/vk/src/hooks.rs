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

use crate::context::Context;
use crate::error::{Error, Result};
use crate::shaders;
use ash::vk;
use std::io::Cursor;

/// The SPIR-V of the light shaders that call the hooks: `deferred_light.frag` (the talk's
/// per-BRDF and branching shaders, by specialisation), `lut_light.frag` (the LUT technique) and
/// the tiled technique's classification and shade kernels for 16x16 and 8x8 tiles.
/// `histencil_build::compile_light_shaders` writes this as an expression for `include!`.
#[derive(Clone, Copy, Debug)]
pub struct LightModules {
    pub deferred_light: &'static [u8],
    pub lut_light: &'static [u8],
    pub tile_classify: &'static [u8],
    pub tile_shade: &'static [u8],
    pub tile_classify_8: &'static [u8],
    pub tile_shade_8: &'static [u8],
}

impl LightModules {
    /// histencil's own: its G-buffer, no shadows.
    pub const BUILTIN: LightModules = LightModules {
        deferred_light: shaders::DEFERRED_LIGHT_FRAG,
        lut_light: shaders::LUT_LIGHT_FRAG,
        tile_classify: shaders::TILE_CLASSIFY_COMP,
        tile_shade: shaders::TILE_SHADE_COMP,
        tile_classify_8: shaders::TILE_CLASSIFY_8_COMP,
        tile_shade_8: shaders::TILE_SHADE_8_COMP,
    };

    /// Each module with its name, for checks and messages.
    fn named(&self) -> [(&'static str, &'static [u8]); 6] {
        [
            ("deferred_light", self.deferred_light),
            ("lut_light", self.lut_light),
            ("tile_classify", self.tile_classify),
            ("tile_shade", self.tile_shade),
            ("tile_classify_8", self.tile_classify_8),
            ("tile_shade_8", self.tile_shade_8),
        ]
    }
}

/// Where a lighting's shaders get surfaces and visibility from (fixed for its life).
#[derive(Clone, Copy, Debug, Default)]
pub enum LightHooks {
    /// histencil's G-buffer ([`crate::GBUFFER_FORMATS`], written through `gbuffer_write.glsl`),
    /// every light unshadowed.
    #[default]
    Builtin,
    /// The engine's hooks.
    Engine(EngineHooks),
}

/// An engine's compiled hooks and the descriptor set layouts their resources are bound with.
#[derive(Clone, Copy, Debug)]
pub struct EngineHooks {
    pub(crate) modules: LightModules,
    pub(crate) decode_layout: vk::DescriptorSetLayout,
    pub(crate) visibility_layout: Option<vk::DescriptorSetLayout>,
}

impl EngineHooks {
    /// The engine's light shaders (from `histencil_build`), its decode hook's set layout (set 1)
    /// and, when its visibility hook reads resources, that hook's set layout (set 4). Every
    /// module is checked to be SPIR-V.
    ///
    /// # Errors
    /// [`Error::BadSetup`] when a module is not SPIR-V (wrong length or magic number).
    ///
    /// # Safety
    /// The layouts are live, from the device of every context a lighting is made on with these
    /// hooks, and outlive those lightings; they declare the bindings the hooks' GLSL reads, for
    /// the fragment stage, and for the compute stage too where the lighting records the tiled
    /// technique ([`crate::DeferredLighting::record_tiled`]); the modules were compiled by `histencil_build` from this version of
    /// histencil-vk's shaders.
    pub unsafe fn new(
        modules: LightModules,
        decode_layout: vk::DescriptorSetLayout,
        visibility_layout: Option<vk::DescriptorSetLayout>,
    ) -> Result<Self> {
        for (name, spirv) in modules.named() {
            spirv_words(spirv).map_err(|e| Error::BadSetup(format!("{name}: {e}")))?;
        }
        Ok(Self {
            modules,
            decode_layout,
            visibility_layout,
        })
    }
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
    /// The modules the light pipelines are made from.
    pub(crate) fn modules(&self) -> LightModules {
        match self {
            LightHooks::Builtin => LightModules::BUILTIN,
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
            LightHooks::Builtin => None,
            LightHooks::Engine(e) => e.visibility_layout,
        }
    }

    /// Refuses hooks the device cannot bind: a visibility set is the fifth set of the light
    /// pipelines' layout, and Vulkan only guarantees four.
    pub(crate) fn check(&self, ctx: &Context) -> Result<()> {
        let sets = if self.visibility_layout().is_some() {
            5
        } else {
            4
        };
        if sets > ctx.max_bound_descriptor_sets {
            return Err(Error::BadSetup(format!(
                "a visibility hook binds set 4, and this device binds at most {} sets",
                ctx.max_bound_descriptor_sets
            )));
        }
        Ok(())
    }

    /// Checks a frame's sets against the hooks.
    pub(crate) fn check_sets(&self, sets: &HookSets) -> Result<()> {
        let bad = |m: &str| Err(Error::BadFrame(m.to_owned()));
        match self {
            LightHooks::Builtin if sets.decode.is_some() || sets.visibility.is_some() => {
                bad("hook sets for a lighting with histencil's built-in hooks")
            }
            LightHooks::Builtin => Ok(()),
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
