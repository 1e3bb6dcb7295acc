//! What a C engine needs to write histencil's G-buffer and make its device: the images' formats,
//! each BRDF's values as the G-buffer stores them, and the device features histencil needs.

use crate::shaders::utf8;
use crate::Outcome;
use crate::{call, slice, Failure, HistencilResult};
use ash::vk;
use histencil::brdf::Brdf;
use std::ffi::c_char;

/// The Vulkan version an engine's instance must be created for: `VK_API_VERSION_1_3`, spelt
/// out for the header (`api_version_is_vulkans` holds the two equal).
pub const HISTENCIL_API_VERSION: u32 = (1 << 22) | (3 << 12);
/// How many images histencil's G-buffer has (`histencil_gbuffer_formats`).
pub const HISTENCIL_GBUFFER_IMAGES: u32 = 3;

/// One named parameter of a BRDF (`ggx`'s `perceptual_roughness`, ...).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct HistencilBrdfParam {
    /// The parameter's name, NUL-terminated.
    pub name: *const c_char,
    /// Its value.
    pub value: f64,
}

/// Writes histencil's G-buffer formats, in binding order (albedo, normal-depth, material:
/// `share/histencil/shaders/include/gbuffer_write.glsl` says what each channel holds), into
/// `formats`, which holds `HISTENCIL_GBUFFER_IMAGES`.
///
/// Errors: `INVALID_ARGUMENT` for a null `formats`.
///
/// Thread safety: any thread.
///
/// # Safety
/// `formats` is null or points at `HISTENCIL_GBUFFER_IMAGES` writable formats.
#[no_mangle]
pub unsafe extern "C" fn histencil_gbuffer_formats(formats: *mut vk::Format) -> HistencilResult {
    call(|| {
        if formats.is_null() {
            return Err(Failure::invalid("formats is null"));
        }
        for (i, f) in histencil::GBUFFER_FORMATS.iter().enumerate() {
            // SAFETY: this fn's # Safety: room for every G-buffer format.
            unsafe { formats.add(i).write(*f) };
        }
        Ok(())
    })
}

/// The G-buffer's values for a surface of BRDF `name` with `params` (each parameter the BRDF
/// takes, by name; an engine BRDF's left out take their defaults): its packed parameters
/// (`gbuffer_encode`'s `brdf_params`, the first three; `packed` holds 4) and its id
/// (`brdf_model`, the BRDF's `BrdfId::index`). `shaders` are those compiled for the engine's BRDF
/// set that holds `name` (`histencil_shaders_compile` or `_load`), or null for histencil's own BRDFs. Every parameter is held to
/// its range, as the Rust API holds it.
///
/// Errors: `INVALID_ARGUMENT` for a null pointer, freed `shaders` or a name that is not UTF-8;
/// `BAD_SETUP` for a BRDF neither histencil nor `shaders`' set holds, a parameter it does not take, one
/// left out that has no default, or one out of its range (the message names it).
///
/// Thread safety: any thread.
///
/// # Safety
/// `name` is null or NUL-terminated; `params` is null or points at `param_count` parameters
/// whose names are NUL-terminated; `packed` is null or holds 4 writable floats; `brdf_id` is
/// null or writable; `shaders` is null or a live handle.
#[no_mangle]
pub unsafe extern "C" fn histencil_brdf_encode(
    shaders: *const crate::HistencilShaders,
    name: *const c_char,
    params: *const HistencilBrdfParam,
    param_count: u32,
    packed: *mut f32,
    brdf_id: *mut u32,
) -> HistencilResult {
    call(|| {
        if packed.is_null() || brdf_id.is_null() {
            return Err(Failure::invalid("packed or brdf_id is null"));
        }
        // SAFETY: this fn's # Safety.
        let modules = unsafe { crate::shaders::modules_of(shaders) }?;
        // SAFETY: this fn's # Safety: null or NUL-terminated.
        let name = unsafe { utf8(name, "name") }?;
        // SAFETY: this fn's # Safety: `param_count` parameters at `params`.
        let params = unsafe { slice(params, param_count, "params") }?;
        let brdf = brdf_of(modules, name, params)?;
        for (i, v) in brdf.packed_params().iter().enumerate() {
            // SAFETY: this fn's # Safety: 4 writable floats.
            unsafe { packed.add(i).write(*v as f32) };
        }
        // SAFETY: checked non-null; writable by this fn's # Safety.
        unsafe { brdf_id.write(brdf.id().index()) };
        Ok(())
    })
}

/// BRDF `name` of `modules`' set with `params` (by name; an engine BRDF's left out take their
/// defaults), each held to its range.
pub(crate) fn brdf_of(
    modules: &histencil::BrdfModules,
    name: &str,
    params: &[HistencilBrdfParam],
) -> Outcome<histencil::brdf::Brdf> {
    let mut given = Vec::with_capacity(params.len());
    for (i, p) in params.iter().enumerate() {
        // SAFETY: the caller's contract: each name null or NUL-terminated.
        let key = unsafe { utf8(p.name, &format!("params[{i}].name")) }?;
        if !p.value.is_finite() {
            return Err(setup(format!(
                "params[{i}] (`{key}`) is {}, not finite",
                p.value
            )));
        }
        given.push((key, p.value));
    }
    let engine = modules.set.engine().any(|(_, spec)| spec.name == name);
    let brdf = if engine {
        modules.set.engine_brdf(name, &given)
    } else {
        let map: serde_json::Map<String, serde_json::Value> = (given.iter())
            .filter_map(|(k, v)| Some(((*k).to_owned(), serde_json::Number::from_f64(*v)?.into())))
            .collect();
        Brdf::parse(name, &map)
    }
    .map_err(|e| setup(format!("BRDF `{name}`: {e}")))?;
    if !modules.set.ids().contains(&brdf.id()) {
        return Err(setup(format!(
            "BRDF `{name}` is not in the set (its manifest's builtins leave it out)"
        )));
    }
    Ok(brdf)
}

fn setup(message: String) -> Failure {
    Failure {
        result: HistencilResult::BadSetup,
        message,
    }
}

/// Adds the features histencil needs to an engine's own, before it creates its device: sets
/// them in `features` (chained as `VkDeviceCreateInfo::pEnabledFeatures` or in
/// `VkPhysicalDeviceFeatures2`) and `features13` (chained into `pNext`), leaving every other
/// member, `sType` and `pNext` as they are.
///
/// Errors: `INVALID_ARGUMENT` for a null pointer.
///
/// Thread safety: any thread.
///
/// # Safety
/// Each pointer is null or points at a live, writable struct.
#[no_mangle]
pub unsafe extern "C" fn histencil_device_features(
    features: *mut vk::PhysicalDeviceFeatures,
    features13: *mut vk::PhysicalDeviceVulkan13Features,
) -> HistencilResult {
    call(|| {
        // SAFETY: this fn's # Safety: null or live and writable.
        let (Some(features), Some(features13)) =
            (unsafe { features.as_mut() }, unsafe { features13.as_mut() })
        else {
            return Err(Failure::invalid("features or features13 is null"));
        };
        let needed = histencil::REQUIREMENTS.features();
        features.depth_clamp |= needed.depth_clamp;
        features.fragment_stores_and_atomics |= needed.fragment_stores_and_atomics;
        let needed13 = histencil::REQUIREMENTS.features13();
        features13.dynamic_rendering |= needed13.dynamic_rendering;
        features13.synchronization2 |= needed13.synchronization2;
        Ok(())
    })
}

/// The bytes of histencil's frame block (`frame.glsl`'s `Frame`, set 0 binding 0, std140).
pub const HISTENCIL_FRAME_UNIFORMS_BYTES: u32 = 336;
/// The bytes of one light in histencil's light buffer (`frame.glsl`'s `Light`, set 0 binding 1,
/// std430).
pub const HISTENCIL_GPU_LIGHT_BYTES: u32 = 64;

/// Writes histencil's frame block for `view` at `width` x `height` with `light_count` lights,
/// `HISTENCIL_FRAME_UNIFORMS_BYTES` bytes, and each of `lights` as histencil's light buffer
/// holds it, `HISTENCIL_GPU_LIGHT_BYTES` bytes each: what an engine's own shaders that include
/// histencil's `light.glsl` (a forward reference shading as histencil shades, say) read in set 0.
///
/// Errors: `INVALID_ARGUMENT` for a null pointer, an unknown light kind or falloff;
/// `BAD_FRAME` for a zero width or height, and for a view or a light
/// `histencil_lighting_record` would refuse (not finite, a projection that cannot be inverted
/// per pixel, a light's radius or angles out of range).
///
/// Thread safety: any thread.
///
/// # Safety
/// `view` is null or live; `lights` is null or points at `light_count` lights; `frame_block` is
/// null or holds `HISTENCIL_FRAME_UNIFORMS_BYTES` writable bytes, `gpu_lights` null or
/// `light_count * HISTENCIL_GPU_LIGHT_BYTES`.
#[no_mangle]
pub unsafe extern "C" fn histencil_shading_inputs(
    view: *const crate::HistencilView,
    width: u32,
    height: u32,
    lights: *const crate::HistencilLight,
    light_count: u32,
    frame_block: *mut u8,
    gpu_lights: *mut u8,
) -> HistencilResult {
    use histencil::vk::gpu_types::{FrameUniforms, GpuLight};
    call(|| {
        // SAFETY: this fn's # Safety.
        let view = unsafe { crate::required(view, "view") }?.to_view();
        // SAFETY: this fn's # Safety.
        let lights = unsafe { slice(lights, light_count, "lights") }?;
        if frame_block.is_null() || (light_count > 0 && gpu_lights.is_null()) {
            return Err(Failure::invalid("frame_block or gpu_lights is null"));
        }
        // What `histencil_lighting_record` refuses is refused here too: a forward reference
        // fed NaN shades NaN, and the engine compares it with a frame histencil never lit.
        let bad_frame = |message: String| Failure {
            result: HistencilResult::BadFrame,
            message,
        };
        if width == 0 || height == 0 {
            return Err(bad_frame(format!("a {width}x{height} viewport")));
        }
        let converted = (lights.iter().enumerate())
            .map(|(i, l)| l.to_light(i))
            .collect::<crate::Outcome<Vec<_>>>()?;
        if let Some(problem) = histencil::vk::frame_inputs_problem(&view, &converted) {
            return Err(bad_frame(problem));
        }
        let uniforms =
            FrameUniforms::from_view(&view, width, height, light_count).map_err(|e| Failure {
                result: HistencilResult::BadFrame,
                message: format!("the view: {e}"),
            })?;
        let gpu: Vec<GpuLight> = converted.iter().map(GpuLight::new).collect();
        let block = bytemuck::bytes_of(&uniforms);
        let light_bytes: &[u8] = bytemuck::cast_slice(&gpu);
        // SAFETY: this fn's # Safety: room for the block and every light; the sources are
        // this function's own values, so nothing overlaps.
        unsafe {
            std::ptr::copy_nonoverlapping(block.as_ptr(), frame_block, block.len());
            if !light_bytes.is_empty() {
                std::ptr::copy_nonoverlapping(light_bytes.as_ptr(), gpu_lights, light_bytes.len());
            }
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn shading_input_sizes_are_histencils() {
        use histencil::vk::gpu_types::{FrameUniforms, GpuLight};
        assert_eq!(
            super::HISTENCIL_FRAME_UNIFORMS_BYTES as usize,
            size_of::<FrameUniforms>()
        );
        assert_eq!(
            super::HISTENCIL_GPU_LIGHT_BYTES as usize,
            size_of::<GpuLight>()
        );
    }

    /// What `histencil_lighting_record` refuses, the shading inputs refuse too: a zero
    /// viewport, a view that is not finite, a light out of range (an outside trial's forward
    /// reference was fed NaN where the lighting refused the frame).
    #[test]
    fn shading_inputs_refuse_what_recording_refuses() {
        use crate::{HistencilLight, HistencilResult as R, HistencilView};
        // An embedded scene's camera, its matrices flattened column by column.
        let camera = histencil::scene::embedded("default").unwrap().camera;
        let desc = camera.view_desc(1.0);
        let flat = |m: [[f32; 4]; 4]| -> [f32; 16] { bytemuck::cast(m) };
        let view = HistencilView {
            world_to_view: flat(desc.world_to_view),
            view_to_clip: flat(desc.view_to_clip),
            reversed_depth: 0,
        };
        let light = HistencilLight {
            kind: crate::HISTENCIL_LIGHT_POINT,
            falloff: crate::HISTENCIL_FALLOFF_SQUARED_WINDOW,
            position: [0.0, 1.0, 0.0],
            radius: 2.0,
            color: [1.0; 3],
            inner_angle: 0.0,
            direction: [0.0; 3],
            outer_angle: 0.0,
        };
        let mut block = [0u8; super::HISTENCIL_FRAME_UNIFORMS_BYTES as usize];
        let mut gpu = [0u8; super::HISTENCIL_GPU_LIGHT_BYTES as usize];
        let mut inputs = |view: &HistencilView, size: u32, light: &HistencilLight| {
            // SAFETY: live structs and buffers of the sizes the header asks for.
            let r = unsafe {
                super::histencil_shading_inputs(
                    view,
                    size,
                    size,
                    light,
                    1,
                    block.as_mut_ptr(),
                    gpu.as_mut_ptr(),
                )
            };
            // SAFETY: the header's: never null, valid until the next call on this thread.
            let said = unsafe { std::ffi::CStr::from_ptr(crate::histencil_last_error()) };
            (r, said.to_string_lossy().into_owned())
        };
        assert_eq!(inputs(&view, 64, &light).0, R::Success);
        let (r, said) = inputs(&view, 0, &light);
        assert_eq!((r, said.as_str()), (R::BadFrame, "a 0x0 viewport"));
        let mut nan_view = view;
        nan_view.world_to_view[12] = f32::NAN;
        let (r, said) = inputs(&nan_view, 64, &light);
        assert!(r == R::BadFrame && said.starts_with("the view: "), "{said}");
        let nan_radius = HistencilLight {
            radius: f32::NAN,
            ..light
        };
        let (r, said) = inputs(&view, 64, &nan_radius);
        assert!(r == R::BadFrame && said.starts_with("light 0: "), "{said}");
    }

    #[test]
    fn api_version_is_vulkans() {
        assert_eq!(
            super::HISTENCIL_API_VERSION,
            histencil::REQUIREMENTS.api_version
        );
    }
}
