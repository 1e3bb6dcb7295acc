//! Uses each packaged crate once: a plan from histencil-model, a BRDF from histencil-brdf, an
//! embedded scene from histencil-scene, and histencil-vk's compiled shaders and requirements.

fn main() {
    let layout = histencil_model::StencilLayout::new(3, 0).expect("a layout for 3 BRDFs");
    let scene = histencil_scene::embedded("pbr-mixed").expect("an embedded scene");
    let shaders = histencil_vk::shaders::ALL.len();
    println!(
        "histencil from its packages: {} BRDFs known, {} in a scene, {} BRDF slots in a layout, \
         {shaders} shader modules, Vulkan {}.{} required",
        histencil_brdf::BrdfId::ALL.len(),
        scene.brdfs_in_use().len(),
        layout.brdfs_in_use(),
        ash_major(histencil_vk::REQUIREMENTS.api_version),
        ash_minor(histencil_vk::REQUIREMENTS.api_version),
    );
    assert!(shaders > 10, "the package's shaders were compiled");
}

fn ash_major(v: u32) -> u32 {
    v >> 22 & 0x7f
}

fn ash_minor(v: u32) -> u32 {
    v >> 12 & 0x3ff
}
