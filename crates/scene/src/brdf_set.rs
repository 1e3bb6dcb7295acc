//! A scene made for histencil's BRDFs, shaded with an engine's: what `--brdfs` does to an
//! embedded scene, so the check and the lab run an engine's own functions over histencil's
//! scenes (the talk's question, asked of the engine's shading models).

use crate::Scene;
use histencil_brdf::{BrdfId, BrdfSet};

/// Gives the scene's opaque objects `set`'s engine BRDFs: each distinct BRDF they use, in id
/// order (the stencil slots' order), becomes the set's next engine BRDF, from the first again
/// after the last, with the manifest's default parameters; tints, maps and emission stay.
/// Returns what became what. A scene that already names one of the set's engine BRDFs (a glTF
/// file made for them) and a set without engine BRDFs leave the scene as it is (no pairs).
///
/// Alpha entities keep theirs: their lightmaps are approximate, held to a bound measured on
/// histencil's BRDFs, and the parameters chosen for them come from a CPU estimate that an
/// engine BRDF has no spelling for; an entity a glTF file gives an engine BRDF is still lit by
/// it (through the lightmaps compiled for the set).
pub fn retarget_brdfs(scene: &mut Scene, set: &BrdfSet) -> Vec<(BrdfId, BrdfId)> {
    let engine: Vec<BrdfId> = set.engine().map(|(id, _)| id).collect();
    let named = scene
        .alpha_objects
        .iter()
        .map(|o| &o.material)
        .chain(scene.particle_systems.iter().map(|p| &p.material))
        .any(|m| !m.brdf.id().is_builtin());
    let mut materials: Vec<&mut crate::Material> =
        scene.objects.iter_mut().map(|o| &mut o.material).collect();
    if engine.is_empty() || named || materials.iter().any(|m| !m.brdf.id().is_builtin()) {
        return Vec::new();
    }
    let mut used: Vec<BrdfId> = materials.iter().map(|m| m.brdf.id()).collect();
    used.sort();
    used.dedup();
    let pairs: Vec<(BrdfId, BrdfId)> = used
        .iter()
        .enumerate()
        .map(|(k, from)| (*from, engine[k % engine.len()]))
        .collect();
    for material in &mut materials {
        let (_, to) = pairs
            .iter()
            .find(|(from, _)| *from == material.brdf.id())
            .expect("every BRDF in use is paired");
        material.brdf = set
            .engine_brdf(to.name(), &[])
            .expect("an engine BRDF of the set with its defaults");
    }
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;
    use histencil_brdf::{EngineBrdfSpec, EngineParam, Range};

    fn spec(name: &str) -> EngineBrdfSpec {
        EngineBrdfSpec {
            name: name.into(),
            glsl: "x.glsl".into(),
            function: name.into(),
            white: None,
            params: vec![EngineParam {
                name: "rho".into(),
                range: Range::new(0.0, 1.0),
                default: 0.5,
            }],
            tangent: false,
            tint: false,
        }
    }

    #[test]
    fn each_brdf_in_use_becomes_the_next_engine_brdf() {
        let set = BrdfSet::new(&[], vec![spec("toon"), spec("sheen")]).unwrap();
        let mut scene = crate::embedded("brdfs-3").unwrap();
        let before = scene.brdfs_in_use();
        assert_eq!(before.len(), 3);
        let pairs = retarget_brdfs(&mut scene, &set);
        let names: Vec<&str> = pairs.iter().map(|(_, to)| to.name()).collect();
        assert_eq!(names, ["toon", "sheen", "toon"]);
        assert_eq!(scene.brdfs_in_use().len(), 2);
        for o in &scene.objects {
            set.check(&o.material.brdf).unwrap();
            assert_eq!(o.material.brdf.packed_params()[0], 0.5);
        }
        // Already the engine's: left alone.
        assert!(retarget_brdfs(&mut scene, &set).is_empty());
        // Alpha entities keep theirs.
        let mut alpha = crate::embedded("alpha").unwrap();
        let kept: Vec<_> = alpha
            .alpha_objects
            .iter()
            .map(|o| o.material.brdf)
            .collect();
        assert!(!retarget_brdfs(&mut alpha, &set).is_empty());
        let after: Vec<_> = alpha
            .alpha_objects
            .iter()
            .map(|o| o.material.brdf)
            .collect();
        assert_eq!(kept, after);
        // No engine BRDF in the set: left alone.
        let mut plain = crate::embedded("brdfs-3").unwrap();
        assert!(retarget_brdfs(&mut plain, &BrdfSet::default()).is_empty());
        assert_eq!(plain.brdfs_in_use(), before);
    }
}
