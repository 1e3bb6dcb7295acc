//! Materials on the GPU: the scene's images as textures (sRGB where a base colour reads them,
//! linear for the other maps; every mip level made on the CPU and uploaded through staging into
//! device-local memory), their samplers, and one descriptor set per distinct set of maps, set 1
//! of the mesh pipelines (`crates/vk/shaders/include/material.glsl`). Objects without maps share a set
//! whose maps are a white texel, which changes nothing.

use crate::gpu::device::context::Context;
use crate::gpu::device::error::{Error, Result, VkCall};
use crate::gpu::device::resources::{Buffer, Image};
use crate::gpu::device::teardown::build;
use crate::gpu::encoder::upload::{upload, BufferUpload, ImageUpload};
use ash::vk;
use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use gpu_allocator::MemoryLocation;
use histencil_scene::{Filter, MaterialMaps, Sampler, Scene, TextureImage, Wrap, MAP_COUNT};

/// `MaterialMaps` in include/material.glsl (std140).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct MaterialRecord {
    /// Per map two rows of its uv transform; the first row's w is its texture coordinate set.
    pub transform: [[f32; 4]; 2 * MAP_COUNT],
    /// x: 1 where the normal map is read; y: its scale.
    pub normal_map: [f32; 4],
    /// rgb: the radiance the surface emits (times the emissive map).
    pub emissive: [f32; 4],
    /// x: 1 where fragments are masked (glTF MASK); y: the threshold on texel alpha times
    /// vertex alpha ([`MaterialMaps::alpha_cutoff`]).
    pub alpha_mask: [f32; 4],
}

impl MaterialRecord {
    /// The record of one map set: an absent map reads texture set 0 through the identity
    /// transform (its slot binds the white texel).
    pub fn new(maps: &MaterialMaps, emissive: Vec3) -> Self {
        let mut transform = [[0.0; 4]; 2 * MAP_COUNT];
        for (i, map) in maps.refs().iter().enumerate() {
            let (m, set) = map.map_or((histencil_scene::UV_IDENTITY, 0), |m| {
                (m.transform, m.texcoord)
            });
            transform[2 * i] = [m[0][0], m[0][1], m[0][2], set as f32];
            transform[2 * i + 1] = [m[1][0], m[1][1], m[1][2], 0.0];
        }
        let normal_map = match maps.normal {
            Some(_) => [1.0, maps.normal_scale, 0.0, 0.0],
            None => [0.0; 4],
        };
        let alpha_mask = match maps.alpha_cutoff {
            Some(threshold) => [1.0, threshold, 0.0, 0.0],
            None => [0.0; 4],
        };
        Self {
            transform,
            normal_map,
            emissive: emissive.extend(0.0).to_array(),
            alpha_mask,
        }
    }
}

/// Records sit this far apart in their buffer: the largest `minUniformBufferOffsetAlignment`
/// Vulkan allows.
const RECORD_STRIDE: u64 = 256;

/// A texture to make: a scene image, and whether it holds sRGB colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TextureKey {
    /// Index into the scene's images.
    pub image: u32,
    /// Decoded as sRGB (a base colour or emissive map): the same image read as another map
    /// is a second, linear texture.
    pub srgb: bool,
}

/// One descriptor set: its record (maps and emitted radiance) and, per map, the texture and
/// sampler slots it binds (slot 0 is the white texel and the default sampler).
#[derive(Clone, Debug, PartialEq)]
pub struct SetPlan {
    /// The maps its objects share.
    pub maps: MaterialMaps,
    /// The radiance its objects emit (times the emissive map).
    pub emissive: Vec3,
    /// Per map, its texture slot in [`MaterialPlan::textures`] (0: the white texel).
    pub textures: [usize; MAP_COUNT],
    /// Per map, its sampler slot in [`MaterialPlan::samplers`] (0: the default sampler).
    pub samplers: [usize; MAP_COUNT],
}

/// What the scene's materials need on the GPU, computed without it.
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialPlan {
    /// Textures from slot 1 on (slot 0 is the white texel).
    pub textures: Vec<TextureKey>,
    /// Samplers from slot 1 on (slot 0 is the default sampler).
    pub samplers: Vec<Sampler>,
    /// Set 0 is the untextured one, always present.
    pub sets: Vec<SetPlan>,
    /// Each object's set.
    pub object_sets: Vec<u32>,
}

/// The distinct textures, samplers and map sets of the scene's objects, each once, in
/// first-use order.
pub fn plan_materials(scene: &Scene) -> MaterialPlan {
    fn slot<T: PartialEq>(list: &mut Vec<T>, item: T) -> usize {
        1 + list.iter().position(|x| *x == item).unwrap_or_else(|| {
            list.push(item);
            list.len() - 1
        })
    }
    let mut plan = MaterialPlan {
        textures: vec![],
        samplers: vec![],
        sets: vec![SetPlan {
            maps: MaterialMaps::default(),
            emissive: Vec3::ZERO,
            textures: [0; MAP_COUNT],
            samplers: [0; MAP_COUNT],
        }],
        object_sets: vec![],
    };
    for object in &scene.objects {
        let (maps, emissive) = (object.material.maps, object.material.emissive);
        let set = match plan
            .sets
            .iter()
            .position(|s| s.maps == maps && s.emissive == emissive)
        {
            Some(set) => set,
            None => {
                let mut set = SetPlan {
                    maps,
                    emissive,
                    textures: [0; MAP_COUNT],
                    samplers: [0; MAP_COUNT],
                };
                for (i, map) in maps.refs().iter().enumerate() {
                    if let Some(map) = map {
                        let key = TextureKey {
                            image: map.image,
                            srgb: MaterialMaps::is_srgb(i),
                        };
                        set.textures[i] = slot(&mut plan.textures, key);
                        set.samplers[i] = slot(&mut plan.samplers, map.sampler);
                    }
                }
                plan.sets.push(set);
                plan.sets.len() - 1
            }
        };
        plan.object_sets.push(set as u32);
    }
    plan
}

/// sRGB-encoded byte to linear, exactly as the sRGB transfer function defines it (what an
/// `R8G8B8A8_SRGB` texture read returns, to within the device's conversion precision).
pub fn srgb_to_linear(c: u8) -> f32 {
    let c = f32::from(c) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn linear_to_srgb(x: f32) -> u8 {
    let x = x.clamp(0.0, 1.0);
    let c = if x <= 0.003_130_8 {
        x * 12.92
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    };
    (c * 255.0).round() as u8
}

/// Every mip level of `image`, level 0 first, down to 1x1: each texel of a level is the mean of
/// the 2x2 (at an odd edge, 1x2 or 2x1) texels it covers in the level above, averaged in linear
/// light when `srgb` (colour channels; alpha is linear in both). Deterministic, on the CPU.
pub fn mip_chain(image: &TextureImage, srgb: bool) -> Vec<(vk::Extent2D, Vec<u8>)> {
    let decode: Vec<f32> = (0..=255u8)
        .map(|c| {
            if srgb {
                srgb_to_linear(c)
            } else {
                f32::from(c) / 255.0
            }
        })
        .collect();
    let encode = |x: f32, channel: usize| {
        if srgb && channel < 3 {
            linear_to_srgb(x)
        } else {
            (x.clamp(0.0, 1.0) * 255.0).round() as u8
        }
    };
    let mut levels = vec![(
        vk::Extent2D {
            width: image.width,
            height: image.height,
        },
        image.rgba8.clone(),
    )];
    loop {
        let (extent, above) = levels.last().expect("level 0");
        let (w, h) = (extent.width, extent.height);
        if w == 1 && h == 1 {
            return levels;
        }
        let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
        let mut next = vec![0u8; (nw * nh * 4) as usize];
        for y in 0..nh {
            for x in 0..nw {
                let xs: &[u32] = if w > 1 { &[2 * x, 2 * x + 1] } else { &[0] };
                let ys: &[u32] = if h > 1 { &[2 * y, 2 * y + 1] } else { &[0] };
                let count = (xs.len() * ys.len()) as f32;
                for channel in 0..4 {
                    let mut sum = 0.0f32;
                    for &sy in ys {
                        for &sx in xs {
                            let byte = above[((sy * w + sx) * 4) as usize + channel];
                            sum += if channel < 3 {
                                decode[byte as usize]
                            } else {
                                f32::from(byte) / 255.0
                            };
                        }
                    }
                    next[((y * nw + x) * 4) as usize + channel] = encode(sum / count, channel);
                }
            }
        }
        levels.push((
            vk::Extent2D {
                width: nw,
                height: nh,
            },
            next,
        ));
    }
}

/// Refuses an image larger than the device can hold, naming it: the one property of a
/// scene's images that depends on the device ([`histencil_scene::Scene::validate`] checks the
/// rest).
pub fn check_images(ctx: &Context, scene: &Scene) -> Result<()> {
    let max = ctx.max_image_dimension;
    match scene
        .images
        .iter()
        .find(|i| i.width > max || i.height > max)
    {
        Some(image) => Err(Error::DeviceLimit(format!(
            "image `{}` is {}x{}; this device allows at most {max} texels per side",
            image.name, image.width, image.height
        ))),
        None => Ok(()),
    }
}

fn sampler_info(s: &Sampler) -> vk::SamplerCreateInfo<'static> {
    let filter = |f: Filter| match f {
        Filter::Nearest => vk::Filter::NEAREST,
        Filter::Linear => vk::Filter::LINEAR,
    };
    let wrap = |w: Wrap| match w {
        Wrap::Repeat => vk::SamplerAddressMode::REPEAT,
        Wrap::MirroredRepeat => vk::SamplerAddressMode::MIRRORED_REPEAT,
        Wrap::ClampToEdge => vk::SamplerAddressMode::CLAMP_TO_EDGE,
    };
    let (mipmap_mode, max_lod) = match s.mip {
        Some(Filter::Nearest) => (vk::SamplerMipmapMode::NEAREST, vk::LOD_CLAMP_NONE),
        Some(Filter::Linear) => (vk::SamplerMipmapMode::LINEAR, vk::LOD_CLAMP_NONE),
        // No mip filter: level 0 only.
        None => (vk::SamplerMipmapMode::NEAREST, 0.0),
    };
    vk::SamplerCreateInfo::default()
        .mag_filter(filter(s.mag))
        .min_filter(filter(s.min))
        .mipmap_mode(mipmap_mode)
        .address_mode_u(wrap(s.wrap_u))
        .address_mode_v(wrap(s.wrap_v))
        .address_mode_w(vk::SamplerAddressMode::REPEAT)
        .max_lod(max_lod)
}

/// The scene's materials on the GPU. [`GpuMaterials::object_sets`] is each object's set 1.
#[derive(Default)]
pub struct GpuMaterials {
    textures: Vec<Image>,
    samplers: Vec<vk::Sampler>,
    records: Option<Buffer>,
    pool: vk::DescriptorPool,
    /// Set 1 of each object's draws, in `Scene::objects` order.
    pub object_sets: Vec<vk::DescriptorSet>,
}

impl GpuMaterials {
    /// Textures, samplers, records and sets for `scene`'s objects, with `layout` (the mesh
    /// pipelines' set 1). A failure half way frees what was made.
    ///
    /// # Errors
    /// An image larger than the device allows (`check_images`), and Vulkan or allocation
    /// failures.
    pub fn new(ctx: &Context, scene: &Scene, layout: vk::DescriptorSetLayout) -> Result<Self> {
        check_images(ctx, scene)?;
        let plan = plan_materials(scene);
        build(ctx, |made: &mut Self| made.fill(ctx, scene, &plan, layout))
    }

    fn fill(
        &mut self,
        ctx: &Context,
        scene: &Scene,
        plan: &MaterialPlan,
        layout: vk::DescriptorSetLayout,
    ) -> Result<()> {
        let white = TextureImage {
            name: "white".into(),
            width: 1,
            height: 1,
            rgba8: vec![255; 4],
        };
        let sources = std::iter::once((&white, false)).chain(
            plan.textures
                .iter()
                .map(|k| (&scene.images[k.image as usize], k.srgb)),
        );
        let mut chains = Vec::new();
        for (i, (image, srgb)) in sources.enumerate() {
            let chain = mip_chain(image, srgb);
            let format = if srgb {
                vk::Format::R8G8B8A8_SRGB
            } else {
                vk::Format::R8G8B8A8_UNORM
            };
            let name = format!(
                "texture-{i}-{}{}",
                image.name,
                if srgb { "-srgb" } else { "" }
            );
            self.textures.push(Image::with_mips(
                ctx,
                &name,
                format,
                chain[0].0,
                vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST,
                chain.len() as u32,
            )?);
            chains.push(chain);
        }
        for (i, s) in std::iter::once(&Sampler::default())
            .chain(&plan.samplers)
            .enumerate()
        {
            // SAFETY: `sampler_info` is a plain create info (no anisotropy, no compare, no
            // chained structs), valid for the call.
            let sampler = unsafe { ctx.device.create_sampler(&sampler_info(s), None) }
                .call("vkCreateSampler")?;
            ctx.name(sampler, &format!("material-sampler-{i}"));
            self.samplers.push(sampler);
        }
        let mut record_bytes = vec![0u8; plan.sets.len() * RECORD_STRIDE as usize];
        for (set, chunk) in plan
            .sets
            .iter()
            .zip(record_bytes.chunks_exact_mut(RECORD_STRIDE as usize))
        {
            let record = MaterialRecord::new(&set.maps, set.emissive);
            chunk[..size_of::<MaterialRecord>()].copy_from_slice(bytemuck::bytes_of(&record));
        }
        let records = self.records.insert(Buffer::new(
            ctx,
            "material-records",
            record_bytes.len() as u64,
            vk::BufferUsageFlags::UNIFORM_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?);
        let image_uploads: Vec<ImageUpload> = self
            .textures
            .iter()
            .zip(&chains)
            .map(|(t, chain)| ImageUpload {
                dst: t.image,
                levels: chain,
            })
            .collect();
        let buffer_uploads = [BufferUpload {
            dst: records.handle,
            bytes: &record_bytes,
        }];
        upload(ctx, "material-upload", &buffer_uploads, &image_uploads)?;
        for t in &mut self.textures {
            t.state = crate::gpu::access::ImageState::after(
                crate::gpu::access::ImageAccess::FragmentSampled,
            );
        }
        self.create_sets(ctx, plan, layout)
    }

    fn create_sets(
        &mut self,
        ctx: &Context,
        plan: &MaterialPlan,
        layout: vk::DescriptorSetLayout,
    ) -> Result<()> {
        let count = plan.sets.len() as u32;
        let table = crate::passes::geometry::MATERIAL_SET;
        let sizes = crate::gpu::device::descriptors::pool_sizes(&[(table, count)]);
        let pool_info = vk::DescriptorPoolCreateInfo::default()
            .max_sets(count)
            .pool_sizes(&sizes);
        // SAFETY: `pool_info` and `sizes` outlive the call; `plan_materials` always plans the
        // default set first, so `max_sets` and every size's count are non-zero.
        self.pool = unsafe { ctx.device.create_descriptor_pool(&pool_info, None) }
            .call("vkCreateDescriptorPool")?;
        ctx.name(self.pool, "material-descriptor-pool");
        let layouts = vec![layout; plan.sets.len()];
        let alloc = vk::DescriptorSetAllocateInfo::default()
            .descriptor_pool(self.pool)
            .set_layouts(&layouts);
        // SAFETY: the pool was made above from this device with room for exactly these sets
        // and their descriptors; `layout` is the mesh passes' live set 1 layout (`new`).
        let sets = unsafe { ctx.device.allocate_descriptor_sets(&alloc) }
            .call("vkAllocateDescriptorSets")?;
        let records = self.records.as_ref().expect("made before the sets").handle;
        for (i, (set, p)) in sets.iter().zip(&plan.sets).enumerate() {
            ctx.name(*set, &format!("material-set-{i}"));
            let record = [vk::DescriptorBufferInfo::default()
                .buffer(records)
                .offset(i as u64 * RECORD_STRIDE)
                .range(size_of::<MaterialRecord>() as u64)];
            let images = p.textures.map(|t| {
                [vk::DescriptorImageInfo::default()
                    .image_view(self.textures[t].view)
                    .image_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL)]
            });
            let samplers = p
                .samplers
                .map(|s| [vk::DescriptorImageInfo::default().sampler(self.samplers[s])]);
            let mut writes = vec![vk::WriteDescriptorSet::default()
                .dst_set(*set)
                .dst_binding(0)
                .descriptor_type(vk::DescriptorType::UNIFORM_BUFFER)
                .buffer_info(&record)];
            for (k, info) in images.iter().enumerate() {
                writes.push(
                    vk::WriteDescriptorSet::default()
                        .dst_set(*set)
                        .dst_binding(1 + k as u32)
                        .descriptor_type(vk::DescriptorType::SAMPLED_IMAGE)
                        .image_info(info),
                );
            }
            for (k, info) in samplers.iter().enumerate() {
                writes.push(
                    vk::WriteDescriptorSet::default()
                        .dst_set(*set)
                        .dst_binding(1 + (MAP_COUNT + k) as u32)
                        .descriptor_type(vk::DescriptorType::SAMPLER)
                        .image_info(info),
                );
            }
            // SAFETY: `set` was just allocated and no command buffer uses it yet; each write
            // matches a binding of `MATERIAL_SET` (material.glsl); the record's offset is a
            // multiple of 256 (every device's largest uniform alignment); the textures and
            // samplers were made above, the textures uploaded and left shader-read-only.
            unsafe { crate::gpu::device::descriptors::update_sets(ctx, &writes) };
        }
        self.object_sets = plan.object_sets.iter().map(|&s| sets[s as usize]).collect();
        Ok(())
    }

    /// Frees the textures, samplers, records and sets; a second call does nothing.
    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the pool and samplers are null or were made by `fill` from this device, and
        // the GPU is done with them: the renderer's Drop destroys these after its device wait,
        // `build` and `Owned` before any frame used them. A second call finds null and none.
        unsafe {
            ctx.device.destroy_descriptor_pool(self.pool, None);
            for s in self.samplers.drain(..) {
                ctx.device.destroy_sampler(s, None);
            }
        }
        self.pool = vk::DescriptorPool::null();
        for mut t in self.textures.drain(..) {
            t.destroy(ctx);
        }
        if let Some(mut r) = self.records.take() {
            r.destroy(ctx);
        }
        self.object_sets.clear();
    }
}

crate::gpu::device::teardown::destroy_by_method!(GpuMaterials);

#[cfg(test)]
mod tests {
    use super::*;
    use histencil_scene::TextureRef;

    #[test]
    fn mips_halve_to_one_texel_averaging_in_linear_light() {
        let image = TextureImage {
            name: "checker".into(),
            width: 4,
            height: 2,
            // Black and white columns, opaque.
            rgba8: (0..8)
                .flat_map(|i| {
                    let c = if i % 2 == 0 { 0 } else { 255 };
                    [c, c, c, 255]
                })
                .collect(),
        };
        let linear = mip_chain(&image, false);
        let sizes: Vec<_> = linear.iter().map(|(e, _)| (e.width, e.height)).collect();
        assert_eq!(sizes, [(4, 2), (2, 1), (1, 1)]);
        assert_eq!(&linear[1].1[..4], &[128, 128, 128, 255]);
        // Half black, half white is 0.5 in linear light: sRGB 188, not 128.
        let srgb = mip_chain(&image, true);
        assert_eq!(&srgb[2].1, &[188, 188, 188, 255]);
        for c in 0..=255u8 {
            assert_eq!(linear_to_srgb(srgb_to_linear(c)), c);
        }
    }

    #[test]
    fn the_plan_shares_textures_samplers_and_sets() {
        let mut scene = histencil_scene::embedded("default").unwrap();
        scene.images = vec![
            TextureImage {
                name: "a".into(),
                width: 1,
                height: 1,
                rgba8: vec![1; 4],
            };
            2
        ];
        let mut textured = scene.objects[0].material;
        textured.maps.base_color = Some(TextureRef::new(0));
        textured.maps.metallic_roughness = Some(TextureRef::new(0));
        scene.objects[1].material = textured;
        scene.objects[2].material = textured;
        let plan = plan_materials(&scene);
        // The untextured set, and one for the two textured objects.
        assert_eq!(plan.sets.len(), 2);
        assert_eq!(&plan.object_sets[..3], &[0, 1, 1]);
        // Image 0 as sRGB colour and as linear data are two textures; one sampler.
        assert_eq!(
            plan.textures,
            [
                TextureKey {
                    image: 0,
                    srgb: true
                },
                TextureKey {
                    image: 0,
                    srgb: false
                }
            ]
        );
        assert_eq!(plan.samplers.len(), 1);
        assert_eq!(plan.sets[1].textures, [1, 0, 2, 0]);
        assert_eq!(plan.sets[1].samplers, [1, 0, 1, 0]);
    }
}
