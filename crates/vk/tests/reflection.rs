//! Every descriptor binding reflected from the SPIR-V (by naga) matches the Rust-side layout the
//! module is used with: same set, binding, kind, and GLSL name.

use histencil_vk::descriptors::BindingKind;
use histencil_vk::shader_layouts::SHADER_LAYOUTS;
use histencil_vk::shaders;

fn reflected_bindings(name: &str, spirv: &[u8]) -> Vec<(u32, u32, BindingKind, String)> {
    let module = naga::front::spv::parse_u8_slice(spirv, &naga::front::spv::Options::default())
        .unwrap_or_else(|e| panic!("{name}: {e:?}"));
    module
        .global_variables
        .iter()
        .filter_map(|(_, var)| {
            let binding = var.binding.as_ref()?;
            let kind = match var.space {
                naga::AddressSpace::Uniform => BindingKind::UniformBuffer,
                naga::AddressSpace::Storage { .. } => BindingKind::StorageBuffer,
                naga::AddressSpace::Handle => match module.types[var.ty].inner {
                    naga::TypeInner::Image {
                        class: naga::ImageClass::Storage { .. },
                        ..
                    } => BindingKind::StorageImage,
                    naga::TypeInner::Image { .. } => BindingKind::SampledImage,
                    naga::TypeInner::Sampler { .. } => BindingKind::Sampler,
                    ref other => panic!("{name}: unexpected handle type {other:?}"),
                },
                other => panic!("{name}: unexpected address space {other:?}"),
            };
            Some((
                binding.group,
                binding.binding,
                kind,
                var.name.clone().unwrap_or_default(),
            ))
        })
        .collect()
}

/// naga validates every module (a second reader beside the driver's and the validation layer's).
/// Here and not in the build script: an engine building histencil compiles no shader
/// translator for it.
#[test]
fn naga_validates_every_module() {
    for (name, spirv) in shaders::ALL {
        let module = naga::front::spv::parse_u8_slice(spirv, &naga::front::spv::Options::default())
            .unwrap_or_else(|e| panic!("naga cannot parse {name}: {e:?}"));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::all(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("naga rejects {name}: {e:?}"));
    }
}

#[test]
fn every_module_has_a_layout_and_every_layout_a_module() {
    for (name, _) in shaders::ALL {
        assert!(
            SHADER_LAYOUTS.iter().any(|(n, _)| n == name),
            "{name} has no declared layout"
        );
    }
    for (name, _) in SHADER_LAYOUTS {
        assert!(
            shaders::ALL.iter().any(|(n, _)| n == name),
            "{name} is declared but not built"
        );
    }
}

#[test]
fn reflected_bindings_match_rust_layouts() {
    let mut checked = 0;
    for (name, spirv) in shaders::ALL {
        let layout = SHADER_LAYOUTS.iter().find(|(n, _)| n == name).unwrap().1;
        for (set, binding, kind, glsl_name) in reflected_bindings(name, spirv) {
            let declared = layout
                .get(set as usize)
                .and_then(|s| s.iter().find(|b| b.binding == binding))
                .unwrap_or_else(|| {
                    panic!("{name}: set {set} binding {binding} is not in the Rust layout")
                });
            assert_eq!(declared.kind, kind, "{name}: set {set} binding {binding}");
            // Anonymous blocks (`buffer Lights { ... };`) have no variable name in SPIR-V.
            if !glsl_name.is_empty() {
                assert_eq!(
                    declared.glsl_name, glsl_name,
                    "{name}: set {set} binding {binding}"
                );
            }
            checked += 1;
        }
    }
    assert!(
        checked >= 10,
        "only {checked} bindings reflected: is reflection working?"
    );
}

/// histencil-vk's own SPIR-V reader (which `EngineHooks::new` holds an engine's hooks with)
/// agrees with naga on every module: the same set, binding, kind and name, nothing more.
#[test]
fn the_run_time_reader_agrees_with_naga() {
    use histencil_vk::ResourceKind;
    let mut compared = 0;
    for (name, spirv) in shaders::ALL {
        let words = ash::util::read_spv(&mut std::io::Cursor::new(spirv)).unwrap();
        let ours = histencil_vk::reflect_bindings(&words).unwrap_or_else(|e| panic!("{name}: {e}"));
        let mut theirs = reflected_bindings(name, spirv);
        theirs.sort_by_key(|(set, binding, ..)| (*set, *binding));
        let ours: Vec<_> = ours
            .resources
            .iter()
            .map(|r| {
                let kind = match r.kind {
                    ResourceKind::UniformBuffer => BindingKind::UniformBuffer,
                    ResourceKind::StorageBuffer => BindingKind::StorageBuffer,
                    ResourceKind::SampledImage => BindingKind::SampledImage,
                    ResourceKind::StorageImage => BindingKind::StorageImage,
                    ResourceKind::Sampler => BindingKind::Sampler,
                    other => panic!("{name}: histencil declares no {other:?}"),
                };
                (r.set, r.binding, kind, r.name.clone())
            })
            .collect();
        assert_eq!(ours, theirs, "{name}");
        compared += ours.len();
    }
    assert!(compared >= 50, "only {compared} bindings compared");
}
