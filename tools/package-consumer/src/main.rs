//! Uses each packaged crate through the front door `histencil`: a plan (histencil-model), a BRDF
//! (histencil-brdf), an embedded scene (histencil-scene), histencil-vk's compiled shaders and
//! requirements, and the light shaders compiled with this consumer's hook by histencil-build.

use histencil::LightModules;

/// The light shaders with `hooks/light_visibility.glsl` (build.rs).
const HOOKED: LightModules = include!(concat!(env!("OUT_DIR"), "/histencil_light_modules.rs"));

fn main() {
    let layout = histencil::StencilLayout::new(3, 0).expect("a layout for 3 BRDFs");
    let scene = histencil::scene::embedded("pbr-mixed").expect("an embedded scene");
    let shaders = histencil::vk::shaders::ALL.len();
    let requirements = histencil::REQUIREMENTS.api_version;
    println!(
        "histencil from its packages: {} BRDFs known, {} in a scene, {} BRDF slots in a layout, \
         {shaders} shader modules, light shaders with a hook of {} bytes, Vulkan {}.{} required",
        histencil::BrdfId::ALL.len(),
        scene.brdfs_in_use().len(),
        layout.brdfs_in_use(),
        HOOKED.deferred_light.len(),
        requirements >> 22 & 0x7f,
        requirements >> 12 & 0x3ff,
    );
    assert!(shaders > 10, "the package's shaders were compiled");
    assert_ne!(
        HOOKED.deferred_light,
        LightModules::BUILTIN.deferred_light,
        "the hook changed the light shader"
    );
}
