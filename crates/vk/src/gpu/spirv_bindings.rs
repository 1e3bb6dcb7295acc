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
                _ => {}
            },
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
        resources.push(Resource {
            set,
            binding,
            kind,
            count,
            name,
        });
    }
    resources.sort_by_key(|r| (r.set, r.binding));
    Ok(ModuleBindings { stages, resources })
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
}
