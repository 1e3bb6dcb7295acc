//! Vertex attributes as f32, in the component types glTF allows them: the core types, and with
//! `KHR_mesh_quantization` (as `gltfpack` writes it) the integer ones, normalised or not.
//!
//! | attribute | core | with KHR_mesh_quantization, also |
//! |---|---|---|
//! | `POSITION` (vec3) | f32 | i8, u8, i16, u16, normalised or not |
//! | `NORMAL` (vec3), `TANGENT` (vec4) | f32 | i8, i16 normalised |
//! | `TEXCOORD_n` (vec2) | f32; u8, u16 normalised | i8, i16 normalised; i8, u8, i16, u16 not |
//!
//! Normalised integers decode as the specification says: `c / 255`, `c / 65535` unsigned,
//! `max(c / 127, -1)`, `max(c / 32767, -1)` signed. A quantized mesh's dequantizing scale and
//! offset are its node's transform, which the importer applies as for any mesh.

use gltf::accessor::{DataType, Dimensions, Item};

/// The glTF name of the extension that widens the types.
pub const MESH_QUANTIZATION: &str = "KHR_mesh_quantization";

/// The attributes read here.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Attribute {
    Position,
    Normal,
    Tangent,
    TexCoord(u32),
}

impl Attribute {
    fn name(self) -> String {
        match self {
            Attribute::Position => "POSITION".into(),
            Attribute::Normal => "NORMAL".into(),
            Attribute::Tangent => "TANGENT".into(),
            Attribute::TexCoord(set) => format!("TEXCOORD_{set}"),
        }
    }

    fn dimensions(self) -> Dimensions {
        match self {
            Attribute::Position | Attribute::Normal => Dimensions::Vec3,
            Attribute::Tangent => Dimensions::Vec4,
            Attribute::TexCoord(_) => Dimensions::Vec2,
        }
    }

    /// The `(component type, normalised)` pairs the attribute may have.
    fn allowed(self, quantized: bool) -> Vec<(DataType, bool)> {
        use DataType::{F32, I16, I8, U16, U8};
        let mut out = vec![(F32, false)];
        let integers = [I8, U8, I16, U16];
        match (self, quantized) {
            (Attribute::TexCoord(_), false) => out.extend([(U8, true), (U16, true)]),
            (Attribute::Position | Attribute::TexCoord(_), true) => {
                out.extend(integers.iter().flat_map(|&t| [(t, true), (t, false)]));
            }
            (Attribute::Normal | Attribute::Tangent, true) => {
                out.extend([(I8, true), (I16, true)]);
            }
            (Attribute::Position | Attribute::Normal | Attribute::Tangent, false) => {}
        }
        out
    }
}

/// Refuses an accessor whose type or normalisation `attribute` may not have, naming both.
pub fn check_type(
    attribute: Attribute,
    accessor: &gltf::Accessor,
    quantized: bool,
) -> Result<(), String> {
    let found = (accessor.data_type(), accessor.normalized());
    let allowed = attribute.allowed(quantized);
    if accessor.dimensions() == attribute.dimensions() && allowed.contains(&found) {
        return Ok(());
    }
    let spell = |(t, normalised): (DataType, bool)| {
        format!("{t:?}{}", if normalised { " normalized" } else { "" })
    };
    let names: Vec<String> = allowed.into_iter().map(spell).collect();
    Err(format!(
        "{} (accessor {}) is {:?} {}; glTF allows {:?} of {}{}",
        attribute.name(),
        accessor.index(),
        accessor.dimensions(),
        spell(found),
        attribute.dimensions(),
        names.join(", "),
        if quantized {
            ""
        } else {
            " (KHR_mesh_quantization allows more)"
        }
    ))
}

/// The accessor's elements as f32, decoded from its component type ([`check_type`] first).
pub fn read<const N: usize>(
    accessor: &gltf::Accessor,
    buffers: &[Vec<u8>],
) -> Result<Vec<[f32; N]>, String>
where
    [f32; N]: Item,
    [i8; N]: Item,
    [u8; N]: Item,
    [i16; N]: Item,
    [u16; N]: Item,
{
    let get = |b: gltf::Buffer| buffers.get(b.index()).map(Vec::as_slice);
    let norm = accessor.normalized();
    let unreadable = || format!("accessor {} cannot be read", accessor.index());
    macro_rules! decode {
        ($t:ty, $scale:expr) => {{
            let items = gltf::accessor::Iter::<[$t; N]>::new(accessor.clone(), get)
                .ok_or_else(unreadable)?;
            items
                .map(|c| {
                    c.map(|x| {
                        let x = f32::from(x);
                        if norm {
                            (x / $scale).max(-1.0)
                        } else {
                            x
                        }
                    })
                })
                .collect()
        }};
    }
    Ok(match accessor.data_type() {
        DataType::F32 => gltf::accessor::Iter::<[f32; N]>::new(accessor.clone(), get)
            .ok_or_else(unreadable)?
            .collect(),
        DataType::I8 => decode!(i8, 127.0),
        DataType::U8 => decode!(u8, 255.0),
        DataType::I16 => decode!(i16, 32767.0),
        DataType::U16 => decode!(u16, 65535.0),
        other => {
            return Err(format!(
                "accessor {}: {other:?} is no vertex attribute type",
                accessor.index()
            ))
        }
    })
}
