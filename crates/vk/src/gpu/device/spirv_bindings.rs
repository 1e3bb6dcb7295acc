//! The descriptor bindings a SPIR-V module declares, read from its words.
//!
//! Why a reader of its own and not naga at run time: the check it serves
//! ([`crate::EngineHooks::new`]) must read the very modules the light pipelines are made from,
//! whichever way an engine built them, and an engine should not link a shader compiler's front
//! end for it. Only the instructions that say what a resource is are read (about a dozen
//! opcodes); `crates/vk/tests/reflection.rs` holds it to naga on every histencil module.

use ash::vk;

/// What a binding holds, as the shader declares it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ResourceKind {
    /// A `uniform` block.
    UniformBuffer,
    /// A `buffer` block.
    StorageBuffer,
    /// A `texture2D` (or other dimension), without a sampler.
    SampledImage,
    /// An `image2D` (or other dimension), read and written with image load/store.
    StorageImage,
    /// A `sampler`.
    Sampler,
    /// A `sampler2D`: image and sampler in one binding.
    CombinedImageSampler,
    /// A `textureBuffer`.
    UniformTexelBuffer,
    /// An `imageBuffer`.
    StorageTexelBuffer,
    /// A `subpassInput`.
    InputAttachment,
    /// An `accelerationStructureEXT`.
    AccelerationStructure,
}

impl ResourceKind {
    /// The descriptor types a layout may declare for it (Vulkan's interface matching rules:
    /// a combined image sampler also serves a separate image or sampler).
    pub fn accepts(self, ty: vk::DescriptorType) -> bool {
        use vk::DescriptorType as T;
        match self {
            ResourceKind::UniformBuffer => {
                matches!(ty, T::UNIFORM_BUFFER | T::UNIFORM_BUFFER_DYNAMIC)
            }
            ResourceKind::StorageBuffer => {
                matches!(ty, T::STORAGE_BUFFER | T::STORAGE_BUFFER_DYNAMIC)
            }
            ResourceKind::SampledImage => {
                matches!(ty, T::SAMPLED_IMAGE | T::COMBINED_IMAGE_SAMPLER)
            }
            ResourceKind::Sampler => matches!(ty, T::SAMPLER | T::COMBINED_IMAGE_SAMPLER),
            ResourceKind::StorageImage => ty == T::STORAGE_IMAGE,
            ResourceKind::CombinedImageSampler => ty == T::COMBINED_IMAGE_SAMPLER,
            ResourceKind::UniformTexelBuffer => ty == T::UNIFORM_TEXEL_BUFFER,
            ResourceKind::StorageTexelBuffer => ty == T::STORAGE_TEXEL_BUFFER,
            ResourceKind::InputAttachment => ty == T::INPUT_ATTACHMENT,
            ResourceKind::AccelerationStructure => ty == T::ACCELERATION_STRUCTURE_KHR,
        }
    }

    /// Its name in messages, as GLSL declares it.
    pub fn describe(self) -> &'static str {
        match self {
            ResourceKind::UniformBuffer => "a uniform buffer",
            ResourceKind::StorageBuffer => "a storage buffer",
            ResourceKind::SampledImage => "a sampled image (texture2D)",
            ResourceKind::StorageImage => "a storage image (image2D)",
            ResourceKind::Sampler => "a sampler",
            ResourceKind::CombinedImageSampler => "a combined image sampler (sampler2D)",
            ResourceKind::UniformTexelBuffer => "a uniform texel buffer",
            ResourceKind::StorageTexelBuffer => "a storage texel buffer",
            ResourceKind::InputAttachment => "an input attachment",
            ResourceKind::AccelerationStructure => "an acceleration structure",
        }
    }
}

/// One descriptor binding a module declares.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Resource {
    /// Its `set =` decoration.
    pub set: u32,
    /// Its `binding =` decoration.
    pub binding: u32,
    /// What it holds.
    pub kind: ResourceKind,
    /// Array length; 0 for a runtime-sized array, 1 for a single resource.
    pub count: u32,
    /// The variable's name (empty for an anonymous block).
    pub name: String,
    /// Whether the shader may write it: a storage buffer not `readonly` (NonWritable on the
    /// variable or on every member of its block), a storage image or texel buffer not
    /// `readonly`. What the hazard check holds a pass's buffers to.
    pub writes: bool,
    /// Whether the shader may read it: all but a `writeonly` storage resource (NonReadable).
    pub reads: bool,
}

/// A module's stages (from its entry points) and descriptor bindings, ordered by set and
/// binding.
#[derive(Clone, Debug, Default)]
pub struct ModuleBindings {
    /// Every stage with an entry point in the module.
    pub stages: vk::ShaderStageFlags,
    /// Its bindings, ordered by set and binding.
    pub resources: Vec<Resource>,
}

mod op {
    pub const NAME: u32 = 5;
    pub const ENTRY_POINT: u32 = 15;
    pub const TYPE_IMAGE: u32 = 25;
    pub const TYPE_SAMPLER: u32 = 26;
    pub const TYPE_SAMPLED_IMAGE: u32 = 27;
    pub const TYPE_ARRAY: u32 = 28;
    pub const TYPE_RUNTIME_ARRAY: u32 = 29;
    pub const TYPE_STRUCT: u32 = 30;
    pub const TYPE_POINTER: u32 = 32;
    pub const CONSTANT: u32 = 43;
    pub const VARIABLE: u32 = 59;
    pub const DECORATE: u32 = 71;
    pub const MEMBER_DECORATE: u32 = 72;
    pub const TYPE_ACCELERATION_STRUCTURE: u32 = 5341;
}

/// What the reader keeps of a type.
#[derive(Clone, Copy)]
enum Type {
    /// `OpTypeImage`: its Dim and Sampled operands.
    Image {
        dim: u32,
        sampled: u32,
    },
    Sampler,
    SampledImage,
    Array {
        element: u32,
        length_id: u32,
    },
    RuntimeArray {
        element: u32,
    },
    Struct,
    Pointer {
        pointee: u32,
    },
    AccelerationStructure,
}

const CLASS_UNIFORM_CONSTANT: u32 = 0;
const CLASS_UNIFORM: u32 = 2;
const CLASS_STORAGE_BUFFER: u32 = 12;
const DECORATION_BUFFER_BLOCK: u32 = 3;
const DECORATION_BINDING: u32 = 33;
const DECORATION_DESCRIPTOR_SET: u32 = 34;
const DECORATION_NON_WRITABLE: u32 = 24;
const DECORATION_NON_READABLE: u32 = 25;
const DIM_BUFFER: u32 = 5;
const DIM_SUBPASS_DATA: u32 = 6;

/// Reads `words` (a whole module, header first).
///
/// # Errors
/// Why the words are not a module this reader understands: a bad header, an instruction running
/// past the end, a resource of a type it does not know.
pub fn reflect_bindings(words: &[u32]) -> Result<ModuleBindings, String> {
    if words.len() < 5 || words[0] != 0x0723_0203 {
        return Err("not SPIR-V (no magic number)".into());
    }
    let mut types = std::collections::HashMap::new();
    let mut constants = std::collections::HashMap::new();
    let mut names = std::collections::HashMap::new();
    let mut sets = std::collections::HashMap::new();
    let mut bindings = std::collections::HashMap::new();
    let mut buffer_blocks = std::collections::HashSet::new();
    // NonWritable / NonReadable on variables, and per block the members so decorated.
    let mut non_writable = std::collections::HashSet::new();
    let mut non_readable = std::collections::HashSet::new();
    let mut members = std::collections::HashMap::new();
    let mut member_marks: std::collections::HashMap<(u32, u32), std::collections::HashSet<u32>> =
        std::collections::HashMap::new();
    let mut variables = Vec::new();
    let mut stages = vk::ShaderStageFlags::empty();
    let mut at = 5;
    while at < words.len() {
        let count = (words[at] >> 16) as usize;
        let opcode = words[at] & 0xffff;
        if count == 0 || at + count > words.len() {
            return Err(format!(
                "instruction at word {at} runs past the module's end"
            ));
        }
        let w = &words[at + 1..at + count];
        let arg = |i: usize| {
            w.get(i)
                .copied()
                .ok_or(format!("opcode {opcode} too short"))
        };
        match opcode {
            op::NAME => {
                names.insert(arg(0)?, literal_string(&w[1..]));
            }
            op::ENTRY_POINT => {
                stages |= match arg(0)? {
                    0 => vk::ShaderStageFlags::VERTEX,
                    4 => vk::ShaderStageFlags::FRAGMENT,
                    5 => vk::ShaderStageFlags::COMPUTE,
                    1 => vk::ShaderStageFlags::TESSELLATION_CONTROL,
                    2 => vk::ShaderStageFlags::TESSELLATION_EVALUATION,
                    3 => vk::ShaderStageFlags::GEOMETRY,
                    model => return Err(format!("entry point of execution model {model}")),
                };
            }
            op::TYPE_IMAGE => {
                let (dim, sampled) = (arg(2)?, arg(6)?);
                types.insert(arg(0)?, Type::Image { dim, sampled });
            }
            op::TYPE_SAMPLER => {
                types.insert(arg(0)?, Type::Sampler);
            }
            op::TYPE_SAMPLED_IMAGE => {
                types.insert(arg(0)?, Type::SampledImage);
            }
            op::TYPE_ARRAY => {
                let t = Type::Array {
                    element: arg(1)?,
                    length_id: arg(2)?,
                };
                types.insert(arg(0)?, t);
            }
            op::TYPE_RUNTIME_ARRAY => {
                types.insert(arg(0)?, Type::RuntimeArray { element: arg(1)? });
            }
            op::TYPE_STRUCT => {
                types.insert(arg(0)?, Type::Struct);
                members.insert(arg(0)?, w.len() as u32 - 1);
            }
            op::TYPE_POINTER => {
                types.insert(arg(0)?, Type::Pointer { pointee: arg(2)? });
            }
            op::TYPE_ACCELERATION_STRUCTURE => {
                types.insert(arg(0)?, Type::AccelerationStructure);
            }
            // A 32-bit integer constant: array lengths. Wider constants keep their low word,
            // which no array length needs.
            op::CONSTANT => {
                constants.insert(arg(1)?, arg(2)?);
            }
            op::VARIABLE => variables.push((arg(0)?, arg(1)?, arg(2)?)),
            op::DECORATE => match arg(1)? {
                DECORATION_DESCRIPTOR_SET => {
                    sets.insert(arg(0)?, arg(2)?);
                }
                DECORATION_BINDING => {
                    bindings.insert(arg(0)?, arg(2)?);
                }
                DECORATION_BUFFER_BLOCK => {
                    buffer_blocks.insert(arg(0)?);
                }
                DECORATION_NON_WRITABLE => {
                    non_writable.insert(arg(0)?);
                }
                DECORATION_NON_READABLE => {
                    non_readable.insert(arg(0)?);
                }
                _ => {}
            },
            op::MEMBER_DECORATE => {
                let decoration = arg(2)?;
                if decoration == DECORATION_NON_WRITABLE || decoration == DECORATION_NON_READABLE {
                    let marks = member_marks.entry((arg(0)?, decoration)).or_default();
                    marks.insert(arg(1)?);
                }
            }
            _ => {}
        }
        at += count;
    }
    let mut resources = Vec::new();
    for (pointer, id, class) in variables {
        let (Some(&set), Some(&binding)) = (sets.get(&id), bindings.get(&id)) else {
            continue;
        };
        let name = names.get(&id).cloned().unwrap_or_default();
        let what = || format!("set {set} binding {binding} ({name})");
        let Some(Type::Pointer { pointee, .. }) = types.get(&pointer).copied() else {
            return Err(format!("{}: its type is not a pointer", what()));
        };
        // Arrays of resources (of arrays): the innermost element says what, the lengths' product
        // how many; 0 for a runtime-sized array.
        let (mut element, mut count) = (pointee, 1u32);
        loop {
            match types.get(&element).copied() {
                Some(Type::Array {
                    element: e,
                    length_id,
                }) => {
                    let length = constants.get(&length_id).copied().ok_or_else(|| {
                        format!(
                            "{}: an array whose length is not a plain constant (a \
                             specialization constant?)",
                            what()
                        )
                    })?;
                    count = count.saturating_mul(length);
                    element = e;
                }
                Some(Type::RuntimeArray { element: e }) => {
                    count = 0;
                    element = e;
                }
                _ => break,
            }
        }
        let kind = match (class, types.get(&element).copied()) {
            (CLASS_STORAGE_BUFFER, Some(Type::Struct)) => ResourceKind::StorageBuffer,
            (CLASS_UNIFORM, Some(Type::Struct)) if buffer_blocks.contains(&element) => {
                ResourceKind::StorageBuffer
            }
            (CLASS_UNIFORM, Some(Type::Struct)) => ResourceKind::UniformBuffer,
            (CLASS_UNIFORM_CONSTANT, Some(Type::Sampler)) => ResourceKind::Sampler,
            (CLASS_UNIFORM_CONSTANT, Some(Type::SampledImage)) => {
                ResourceKind::CombinedImageSampler
            }
            (CLASS_UNIFORM_CONSTANT, Some(Type::AccelerationStructure)) => {
                ResourceKind::AccelerationStructure
            }
            (CLASS_UNIFORM_CONSTANT, Some(Type::Image { dim, sampled })) => match (dim, sampled) {
                (DIM_SUBPASS_DATA, _) => ResourceKind::InputAttachment,
                (DIM_BUFFER, 2) => ResourceKind::StorageTexelBuffer,
                (DIM_BUFFER, _) => ResourceKind::UniformTexelBuffer,
                (_, 2) => ResourceKind::StorageImage,
                _ => ResourceKind::SampledImage,
            },
            (class, _) => {
                return Err(format!(
                    "{}: a resource of storage class {class} this reader does not know",
                    what()
                ))
            }
        };
        // A block is read-only (write-only) when every member is, or the variable.
        let marked = |decoration: u32, on_variable: &std::collections::HashSet<u32>| {
            let whole_block = members.get(&element).is_some_and(|&n| {
                member_marks
                    .get(&(element, decoration))
                    .is_some_and(|m| n > 0 && m.len() as u32 == n)
            });
            on_variable.contains(&id) || whole_block
        };
        let storage = matches!(
            kind,
            ResourceKind::StorageBuffer
                | ResourceKind::StorageImage
                | ResourceKind::StorageTexelBuffer
        );
        let writes = storage && !marked(DECORATION_NON_WRITABLE, &non_writable);
        let reads = !(storage && marked(DECORATION_NON_READABLE, &non_readable));
        resources.push(Resource {
            set,
            binding,
            kind,
            count,
            name,
            writes,
            reads,
        });
    }
    resources.sort_by_key(|r| (r.set, r.binding));
    Ok(ModuleBindings { stages, resources })
}

/// How a module's code reaches a binding's memory: whether it loads, stores or uses atomics
/// on it (all false: declared, by an include, but not used).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Reach {
    pub loads: bool,
    pub stores: bool,
    pub atomics: bool,
}

/// How the module reaches each (set, binding) it declares, through the variable or any access
/// chain of it. What the hazard check needs: a binding the code never touches is no access,
/// and atomics of two draws are no data race where plain accesses are. A module it cannot
/// read has no entries (the check then takes the declarations' word).
pub(crate) fn binding_reach(words: &[u32]) -> std::collections::HashMap<(u32, u32), Reach> {
    use std::collections::{HashMap, HashSet};
    const FUNCTION_CALL: u32 = 57;
    const LOAD: u32 = 61;
    const STORE: u32 = 62;
    const COPY_MEMORY: u32 = 63;
    const ACCESS_CHAIN: std::ops::RangeInclusive<u32> = 65..=67;
    const COPY_OBJECT: u32 = 83;
    const ATOMIC_STORE: u32 = 228;
    const ATOMICS: std::ops::RangeInclusive<u32> = 227..=242;
    let (mut sets, mut bindings) = (HashMap::new(), HashMap::new());
    let mut chains = Vec::new();
    let (mut loads, mut stores, mut atomic) = (HashSet::new(), HashSet::new(), HashSet::new());
    let mut at = 5;
    while words.len() >= 5 && at < words.len() {
        let count = (words[at] >> 16) as usize;
        let opcode = words[at] & 0xffff;
        if count == 0 || at + count > words.len() {
            return HashMap::new();
        }
        let w = &words[at + 1..at + count];
        let get = |i: usize| w.get(i).copied().unwrap_or(0);
        match opcode {
            op::DECORATE if get(1) == DECORATION_DESCRIPTOR_SET => {
                sets.insert(get(0), get(2));
            }
            op::DECORATE if get(1) == DECORATION_BINDING => {
                bindings.insert(get(0), get(2));
            }
            o if ACCESS_CHAIN.contains(&o) || o == COPY_OBJECT => chains.push((get(1), get(2))),
            LOAD => {
                loads.insert(get(2));
            }
            STORE => {
                stores.insert(get(0));
            }
            COPY_MEMORY => {
                stores.insert(get(0));
                loads.insert(get(1));
            }
            FUNCTION_CALL => {
                loads.extend(w.iter().skip(3).copied());
                stores.extend(w.iter().skip(3).copied());
            }
            ATOMIC_STORE => {
                atomic.insert(get(0));
            }
            o if ATOMICS.contains(&o) => {
                atomic.insert(get(2));
            }
            _ => {}
        }
        at += count;
    }
    let mut out = HashMap::new();
    for (variable, set) in &sets {
        let Some(binding) = bindings.get(variable) else {
            continue;
        };
        let mut reached = HashSet::from([*variable]);
        loop {
            let before = reached.len();
            for (result, base) in &chains {
                if reached.contains(base) {
                    reached.insert(*result);
                }
            }
            if reached.len() == before {
                break;
            }
        }
        let reach = Reach {
            loads: reached.iter().any(|id| loads.contains(id)),
            stores: reached.iter().any(|id| stores.contains(id)),
            atomics: reached.iter().any(|id| atomic.contains(id)),
        };
        out.insert((*set, *binding), reach);
    }
    out
}

/// A SPIR-V literal string: UTF-8 bytes, little-endian in words, nul-terminated.
fn literal_string(words: &[u32]) -> String {
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
    String::from_utf8_lossy(&bytes[..end]).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_truncated_module_is_refused_not_read_past_its_end() {
        let mut words = vec![0x0723_0203, 0x0001_0300, 0, 10, 0];
        words.push((4 << 16) | op::DECORATE);
        words.push(7);
        assert!(reflect_bindings(&words)
            .unwrap_err()
            .contains("past the module's end"));
        assert!(reflect_bindings(&[1, 2, 3])
            .unwrap_err()
            .contains("not SPIR-V"));
        // An instruction of zero words would loop for ever.
        let zero = [0x0723_0203, 0x0001_0300, 0, 10, 0, 0];
        assert!(reflect_bindings(&zero).is_err());
    }

    fn words(spirv: &[u8]) -> Vec<u32> {
        ash::util::read_spv(&mut std::io::Cursor::new(spirv)).expect("SPIR-V")
    }

    /// What the hazard check reads of histencil's own modules: the statistics draw reaches
    /// its touched marks and counters by atomics alone, the depth-id shade only loads the
    /// tile lists it declares writable (tiled.glsl's blocks are not `readonly`), and the
    /// classification stores them.
    #[test]
    fn binding_reach_tells_atomics_loads_and_stores_apart() {
        let count = binding_reach(&words(crate::shaders::HI_STENCIL_COUNT_FRAG));
        let atomics = Reach {
            loads: false,
            stores: false,
            atomics: true,
        };
        assert_eq!(count[&(2, 1)], atomics, "touched");
        assert_eq!(count[&(2, 2)], atomics, "statistics");
        let shade = binding_reach(&words(crate::shaders::DEPTH_ID_SHADE_FRAG));
        let lists = shade[&(2, 2)];
        assert!(lists.loads && !lists.stores && !lists.atomics, "{lists:?}");
        let reflected = reflect_bindings(&words(crate::shaders::DEPTH_ID_SHADE_FRAG)).unwrap();
        let declared = reflected
            .resources
            .iter()
            .find(|r| (r.set, r.binding) == (2, 2));
        assert!(declared.is_some_and(|r| r.writes && r.reads));
        // frame.glsl's lights are `readonly` (NonWritable on the block's members).
        let lights = reflected
            .resources
            .iter()
            .find(|r| (r.set, r.binding) == (0, 1));
        assert!(lights.is_some_and(|r| !r.writes && r.reads), "{lights:?}");
        let classify = binding_reach(&words(crate::shaders::TILE_CLASSIFY_COMP));
        assert!(classify[&(2, 1)].stores, "{:?}", classify[&(2, 1)]);
        // A module it cannot read reaches nothing it can name.
        assert!(binding_reach(&[1, 2, 3]).is_empty());
    }
}
