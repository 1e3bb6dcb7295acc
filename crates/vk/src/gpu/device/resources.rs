//! Buffers and images with their gpu-allocator memory, both named after the resource. They are
//! destroyed explicitly with the context (`destroy`), never by `Drop` (see `teardown`); their
//! empty values (`Default`) hold null handles, which `destroy` accepts.

use crate::gpu::access::{subresource_range, ImageRef, ImageState};
use crate::gpu::device::context::Context;
use crate::gpu::device::error::{Error, Result, VkCall};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;

fn allocate(
    ctx: &Context,
    name: &str,
    requirements: vk::MemoryRequirements,
    location: MemoryLocation,
    linear: bool,
) -> Result<Allocation> {
    ctx.memory
        .reserve(requirements.size)
        .map_err(|message| Error::Allocation {
            name: name.to_owned(),
            message,
        })?;
    let made = ctx
        .allocator
        .lock()
        .unwrap()
        .allocate(&AllocationCreateDesc {
            name,
            requirements,
            location,
            linear,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        })
        .map_err(|e| Error::Allocation {
            name: name.to_owned(),
            message: e.to_string(),
        });
    if made.is_err() {
        ctx.memory.release(requirements.size);
    }
    made
}

fn free(ctx: &Context, allocation: Allocation) {
    ctx.memory.release(allocation.size());
    // Freeing only fails for allocations this allocator did not make: a bug, not a runtime state.
    ctx.allocator
        .lock()
        .unwrap()
        .free(allocation)
        .expect("freeing a gpu-allocator allocation");
}

/// A buffer and its memory.
#[derive(Default)]
pub struct Buffer {
    pub handle: vk::Buffer,
    pub size: vk::DeviceSize,
    allocation: Option<Allocation>,
}

impl Buffer {
    /// Creates a named buffer. `location` decides host visibility: uploads use `CpuToGpu`
    /// (written once, read by the GPU), readbacks `GpuToCpu`.
    pub fn new(
        ctx: &Context,
        name: &str,
        size: vk::DeviceSize,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Self> {
        // histencil binds its storage buffers whole, so one past the device's
        // maxStorageBufferRange could never be bound: refused here, for every buffer, before
        // anything is made (Vulkan would make it and leave the bind to the validation layer).
        let range = u64::from(ctx.max_storage_buffer_range);
        if usage.contains(vk::BufferUsageFlags::STORAGE_BUFFER) && size > range {
            return Err(Error::DeviceLimit(format!(
                "buffer `{name}` needs {size} bytes, past this device's maxStorageBufferRange \
                 ({range})"
            )));
        }
        let info = vk::BufferCreateInfo::default()
            .size(size.max(4))
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: `info` lives until the call returns; its size is non-zero (`max(4)`) and
        // its sharing mode exclusive, so it names no queue families.
        let handle = unsafe { ctx.device.create_buffer(&info, None) }.call("vkCreateBuffer")?;
        ctx.buffer_uses
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .remove(&handle);
        if let Some(hazards) = ctx.hazards.get() {
            // A handle a destroyed buffer had: nothing of that one's accesses is this one's.
            hazards.forget_buffer(handle);
        }
        ctx.name(handle, name);
        // SAFETY: `handle` was just created from `ctx.device`.
        let requirements = unsafe { ctx.device.get_buffer_memory_requirements(handle) };
        let allocation = match allocate(ctx, name, requirements, location, true) {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: `handle` is unbound and unused: nothing has seen it but the name.
                unsafe { ctx.device.destroy_buffer(handle, None) };
                return Err(e);
            }
        };
        // SAFETY: the memory goes to `bind_buffer_memory` with its offset, as gpu-allocator's
        // # Safety allows; `destroy` frees the allocation only after destroying the buffer.
        let (memory, offset) = (unsafe { allocation.memory() }, allocation.offset());
        let mut made = Self {
            handle,
            size,
            allocation: Some(allocation),
        };
        // SAFETY: `handle` is not yet bound; the allocation was made from its requirements
        // (size, alignment, memory type), so `offset` is aligned and the range fits.
        let bound = unsafe { ctx.device.bind_buffer_memory(handle, memory, offset) };
        if let Err(e) = bound.call("vkBindBufferMemory") {
            made.destroy(ctx);
            return Err(e);
        }
        Ok(made)
    }

    /// A host-readable buffer that copies write into.
    pub fn readback(ctx: &Context, name: &str, size: vk::DeviceSize) -> Result<Self> {
        Self::new(
            ctx,
            name,
            size,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )
    }

    /// A host-visible buffer filled with `bytes`.
    pub fn with_data(
        ctx: &Context,
        name: &str,
        usage: vk::BufferUsageFlags,
        bytes: &[u8],
    ) -> Result<Self> {
        let mut b = Self::new(
            ctx,
            name,
            bytes.len() as u64,
            usage,
            MemoryLocation::CpuToGpu,
        )?;
        b.write(bytes);
        Ok(b)
    }

    /// Copies `bytes` to the start of a host-visible buffer.
    ///
    /// # Panics
    /// If the buffer is not host visible or `bytes` is longer than it: caller bugs.
    pub fn write(&mut self, bytes: &[u8]) {
        self.write_at(0, bytes);
    }

    /// Copies `bytes` into a host-visible buffer from byte `offset`.
    ///
    /// # Panics
    /// If the buffer is not host visible or `bytes` runs past its end: caller bugs.
    pub fn write_at(&mut self, offset: usize, bytes: &[u8]) {
        let slice = self
            .allocation
            .as_mut()
            .and_then(|a| a.mapped_slice_mut())
            .expect("buffer is host visible");
        slice[offset..offset + bytes.len()].copy_from_slice(bytes);
    }

    /// The contents of a host-visible buffer.
    pub fn read(&self) -> &[u8] {
        let slice = self
            .allocation
            .as_ref()
            .and_then(|a| a.mapped_slice())
            .expect("buffer is host visible");
        &slice[..self.size as usize]
    }

    /// Frees the buffer and its memory; a second call does nothing.
    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the buffer is this value's own, from `ctx.device`; a null one (empty, or
        // destroyed before) is a no-op. Owners call `destroy` only once the GPU is done with
        // it (teardown.rs: after their fence wait or device idle, or on a creation that failed
        // before any submission), and the memory is freed only after the buffer is gone.
        unsafe { ctx.device.destroy_buffer(self.handle, None) };
        ctx.buffer_uses
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .remove(&self.handle);
        if let (Some(hazards), false) = (ctx.hazards.get(), self.handle == vk::Buffer::null()) {
            hazards.forget_buffer(self.handle);
        }
        self.handle = vk::Buffer::null();
        if let Some(a) = self.allocation.take() {
            free(ctx, a);
        }
    }
}

/// A 2D image histencil owns: its memory, and an [`ImageRef`] (handles, one view over all its
/// aspects, current state) that the passes record against, as they do an engine's images.
pub struct Image {
    target: ImageRef,
    allocation: Option<Allocation>,
}

impl std::ops::Deref for Image {
    type Target = ImageRef;
    fn deref(&self) -> &ImageRef {
        &self.target
    }
}

impl std::ops::DerefMut for Image {
    fn deref_mut(&mut self) -> &mut ImageRef {
        &mut self.target
    }
}

impl Image {
    pub fn new(
        ctx: &Context,
        name: &str,
        format: vk::Format,
        extent: vk::Extent2D,
        usage: vk::ImageUsageFlags,
    ) -> Result<Self> {
        Self::with_mips(ctx, name, format, extent, usage, 1)
    }

    /// An image of `mip_levels` levels, its view over all of them (a texture). Its
    /// [`ImageRef`] state describes every level.
    pub fn with_mips(
        ctx: &Context,
        name: &str,
        format: vk::Format,
        extent: vk::Extent2D,
        usage: vk::ImageUsageFlags,
        mip_levels: u32,
    ) -> Result<Self> {
        // Refused here for every image, before anything is made: Vulkan leaves an image past
        // maxImageDimension2D to the validation layer.
        let max = ctx.max_image_dimension;
        if extent.width > max || extent.height > max {
            return Err(Error::DeviceLimit(format!(
                "image `{name}` of {}x{} is past this device's maxImageDimension2D ({max})",
                extent.width, extent.height
            )));
        }
        let aspect = crate::gpu::access::aspect_of(format);
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(format)
            .extent(vk::Extent3D {
                width: extent.width,
                height: extent.height,
                depth: 1,
            })
            .mip_levels(mip_levels)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        // SAFETY: `info` lives until the call returns: a 2D, single-sample, exclusive image of
        // an extent the callers checked (`check_extent` and the like: non-zero, within
        // `max_image_dimension`) and a format they chose for its usage.
        let handle = unsafe { ctx.device.create_image(&info, None) }.call("vkCreateImage")?;
        ctx.name(handle, name);
        // SAFETY: `handle` was just created from `ctx.device`.
        let requirements = unsafe { ctx.device.get_image_memory_requirements(handle) };
        let allocation = match allocate(ctx, name, requirements, MemoryLocation::GpuOnly, false) {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: `handle` is unbound and unused: nothing has seen it but the name.
                unsafe { ctx.device.destroy_image(handle, None) };
                return Err(e);
            }
        };
        // Binding and the view: on failure the image and its memory go too.
        let view_info = vk::ImageViewCreateInfo::default()
            .image(handle)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(format)
            .subresource_range(subresource_range(aspect).level_count(mip_levels));
        // SAFETY: the image is not yet bound, and the allocation was made from its requirements
        // and is passed with its offset (gpu-allocator's `memory` # Safety); the view's info
        // names that image, once bound, with its own format and mip levels.
        let view = unsafe {
            ctx.device
                .bind_image_memory(handle, allocation.memory(), allocation.offset())
                .call("vkBindImageMemory")
                .and_then(|()| {
                    ctx.device
                        .create_image_view(&view_info, None)
                        .call("vkCreateImageView")
                })
        };
        let view = match view {
            Ok(v) => v,
            Err(e) => {
                // SAFETY: the image has no view and no use yet; it goes before its memory.
                unsafe { ctx.device.destroy_image(handle, None) };
                free(ctx, allocation);
                return Err(e);
            }
        };
        ctx.name(view, &format!("{name}-view"));
        Ok(Self {
            target: ImageRef {
                image: handle,
                view,
                format,
                extent,
                usage,
                state: ImageState::UNDEFINED,
            },
            allocation: Some(allocation),
        })
    }

    /// Frees the image, its view and its memory; a second call does nothing.
    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the view and image are this value's own, from `ctx.device`; null ones (empty,
        // or destroyed before) are no-ops. Owners call `destroy` only once the GPU is done with
        // them (see `Buffer::destroy`); the view goes before its image, the image before its
        // memory.
        unsafe {
            ctx.device.destroy_image_view(self.target.view, None);
            ctx.device.destroy_image(self.target.image, None);
        }
        self.target.view = vk::ImageView::null();
        self.target.image = vk::Image::null();
        if let Some(a) = self.allocation.take() {
            free(ctx, a);
        }
    }
}

/// No image yet: null handles.
impl Default for Image {
    fn default() -> Self {
        Self {
            target: ImageRef {
                image: vk::Image::null(),
                view: vk::ImageView::null(),
                format: vk::Format::UNDEFINED,
                extent: vk::Extent2D::default(),
                usage: vk::ImageUsageFlags::empty(),
                state: ImageState::UNDEFINED,
            },
            allocation: None,
        }
    }
}

crate::gpu::device::teardown::destroy_by_method!(Buffer, Image);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::device::context::ContextDesc;

    /// The leak check the end-to-end tests rely on can fail: a buffer left alive at teardown is
    /// reported by the validation layer's object tracker.
    #[test]
    fn leaked_buffer_is_reported_at_teardown() {
        let ctx = Context::new(ContextDesc::validated()).unwrap();
        let log = ctx.validation_log();
        let buffer = Buffer::new(
            &ctx,
            "deliberately-leaked",
            64,
            vk::BufferUsageFlags::UNIFORM_BUFFER,
            MemoryLocation::CpuToGpu,
        )
        .unwrap();
        std::mem::forget(buffer);
        drop(ctx);
        let problems = log.problems();
        assert!(
            problems
                .iter()
                .any(|p| p.contains("deliberately-leaked") || p.contains("VkBuffer")),
            "no leak report: {problems:?}"
        );
    }
}
