//! The SPIR-V modules of the light shaders that call the hooks, which the passes make their
//! pipelines from: histencil's own, or an engine's compiled with its hooks
//! (`crate::lighting::hooks`, which checks them against the engine's layouts).

use crate::shaders;

/// The SPIR-V of the light shaders that call the hooks: `deferred_light.frag` (the talk's
/// per-BRDF and branching shaders, by specialisation), `lut_light.frag` (the LUT technique) and
/// the tiled technique's classification and shade kernels for 16x16 and 8x8 tiles, and the
/// depth-id technique's id copy and shade pass (`depth_id_copy.frag`, `depth_id_shade.frag`).
/// `histencil_build::compile_light_shaders` writes this as an expression for `include!`.
#[derive(Clone, Copy, Debug)]
pub struct LightModules {
    /// `deferred_light.frag`: the per-BRDF and branching light shaders.
    pub deferred_light: &'static [u8],
    /// `lut_light.frag`: the LUT technique's light shader.
    pub lut_light: &'static [u8],
    /// `tile_classify.comp`: the tiled technique's classification, 16x16 tiles.
    pub tile_classify: &'static [u8],
    /// `tile_shade.comp`: the tiled technique's shade kernel, 16x16 tiles.
    pub tile_shade: &'static [u8],
    /// `tile_classify_8.comp`: the classification for 8x8 tiles.
    pub tile_classify_8: &'static [u8],
    /// `tile_shade_8.comp`: the shade kernel for 8x8 tiles.
    pub tile_shade_8: &'static [u8],
    /// `depth_id_copy.frag`: the depth-id technique's id copy.
    pub depth_id_copy: &'static [u8],
    /// `depth_id_shade.frag`: the depth-id technique's shade pass.
    pub depth_id_shade: &'static [u8],
    /// The BRDF ids (`BrdfId::index`) these shaders evaluate: histencil's eight, or a BRDF
    /// set's (`histencil_build::compile_light_shaders_for` writes them). A lighting whose
    /// `LightingDesc::brdfs` names another is refused, not shaded black.
    pub brdfs: &'static [u32],
    /// Their names, in the order of `brdfs`: an id names another BRDF in another set, so a
    /// lighting is held to both.
    pub brdf_names: &'static [&'static str],
}

/// histencil's own BRDFs' ids, in `BrdfId::ALL` order (as `MODEL_NAMES` names them).
const BUILTIN_IDS: [u32; 8] = {
    let mut ids = [0; 8];
    let mut i = 0;
    while i < ids.len() {
        ids[i] = histencil_brdf::BrdfId::ALL[i].index();
        i += 1;
    }
    ids
};

impl LightModules {
    /// histencil's own: its G-buffer, no shadows.
    pub const BUILTIN: LightModules = LightModules {
        deferred_light: shaders::DEFERRED_LIGHT_FRAG,
        lut_light: shaders::LUT_LIGHT_FRAG,
        tile_classify: shaders::TILE_CLASSIFY_COMP,
        tile_shade: shaders::TILE_SHADE_COMP,
        tile_classify_8: shaders::TILE_CLASSIFY_8_COMP,
        tile_shade_8: shaders::TILE_SHADE_8_COMP,
        depth_id_copy: shaders::DEPTH_ID_COPY_FRAG,
        depth_id_shade: shaders::DEPTH_ID_SHADE_FRAG,
        brdfs: &BUILTIN_IDS,
        brdf_names: &histencil_brdf::MODEL_NAMES,
    };

    /// Each module with its name, for checks and messages.
    pub(crate) fn named(&self) -> [(&'static str, &'static [u8]); 8] {
        [
            ("deferred_light", self.deferred_light),
            ("lut_light", self.lut_light),
            ("tile_classify", self.tile_classify),
            ("tile_shade", self.tile_shade),
            ("tile_classify_8", self.tile_classify_8),
            ("tile_shade_8", self.tile_shade_8),
            ("depth_id_copy", self.depth_id_copy),
            ("depth_id_shade", self.depth_id_shade),
        ]
    }

    /// Each module by its name, to be set (a run-time compile, a shader file read back).
    pub(crate) fn named_mut(&mut self) -> [(&'static str, &mut &'static [u8]); 8] {
        [
            ("deferred_light", &mut self.deferred_light),
            ("lut_light", &mut self.lut_light),
            ("tile_classify", &mut self.tile_classify),
            ("tile_shade", &mut self.tile_shade),
            ("tile_classify_8", &mut self.tile_classify_8),
            ("tile_shade_8", &mut self.tile_shade_8),
            ("depth_id_copy", &mut self.depth_id_copy),
            ("depth_id_shade", &mut self.depth_id_shade),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The modules by name are the build's table's hooked stages, in its order: the run-time
    /// compile sets them by these names, the build writes the fields by them.
    #[test]
    fn the_modules_by_name_are_the_hooked_stages_of_the_build_table() {
        let table: Vec<&str> = histencil_build::STAGES
            .iter()
            .filter(|s| s.hooked)
            .map(|s| s.field())
            .collect();
        let named: Vec<&str> = LightModules::BUILTIN.named().map(|(n, _)| n).to_vec();
        let mut builtin = LightModules::BUILTIN;
        let named_mut: Vec<&str> = builtin.named_mut().map(|(n, _)| n).to_vec();
        assert_eq!(named, table);
        assert_eq!(named_mut, table);
    }
}
