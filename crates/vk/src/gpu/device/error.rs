use ash::vk;

/// What can go wrong in histencil, sorted by who can prevent it ([`Error::cause`]): the caller
/// (a frame or description that does not fit, a slot still in flight: fix the call), the device
/// (no loader, no suitable device, a format or limit it lacks, a Vulkan call or allocation that
/// failed: choose another configuration or device), the data (a scene, layout or plan the
/// renderer cannot take: fix the content), or the output (a file that could not be written).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The Vulkan loader, or the validation layer that was asked for, is not installed.
    #[error("cannot load the Vulkan library: {0}")]
    Loading(String),
    /// No device (or, for a lent device, not that one or its queue family) meets
    /// [`crate::REQUIREMENTS`]; the message lists what was seen or what is missing.
    #[error("no suitable Vulkan 1.3 device: {0}")]
    NoDevice(String),
    /// The device lacks a format that was asked for (a caller can skip that configuration).
    #[error("missing format: {0}")]
    MissingFormat(String),
    /// The device offers less of a limit than the work asked of it needs (a device below
    /// [`crate::NEEDS`], or an engine's hooks adding descriptors): the message names the limit,
    /// the need and the device's value.
    #[error("device limit: {0}")]
    DeviceLimit(String),
    /// A Vulkan call returned an error code (out of memory, device lost, ...).
    #[error("Vulkan call `{call}` failed: {result}")]
    Vulkan {
        /// The Vulkan entry point, as `vkCreateImage`.
        call: &'static str,
        /// What it returned.
        result: vk::Result,
    },
    /// Waiting for a frame failed: the GPU did not finish it within the fence timeout, or the
    /// device was lost while it ran. `progress` says how far the GPU got, from the frame's own
    /// timestamps (each written once every command before it has finished): the last pass
    /// the GPU finished and the one it had not.
    #[error("Vulkan call `{call}` failed: {result}; {progress}")]
    GpuStalled {
        /// The wait, as `vkWaitForFences`.
        call: &'static str,
        /// What it returned: `VK_TIMEOUT` or `VK_ERROR_DEVICE_LOST`.
        result: vk::Result,
        /// `the GPU has finished gbuffer, not lighting`, or why it cannot be read.
        progress: String,
    },
    /// The memory budget or gpu-allocator refused an allocation.
    #[error("GPU memory allocation `{name}` failed: {message}")]
    Allocation {
        /// The allocation's name, as it would have appeared in a leak report.
        name: String,
        /// Why: over the budget, or the allocator's own error.
        message: String,
    },
    /// A frame size of zero, or larger than the device's largest image.
    #[error("bad resolution {width}x{height}: {reason}")]
    BadResolution {
        /// The requested width in pixels.
        width: u32,
        /// The requested height in pixels.
        height: u32,
        /// Which limit it broke.
        reason: String,
    },
    /// A scene the renderer cannot take.
    #[error(transparent)]
    Scene(#[from] histencil_scene::SceneError),
    /// The stencil bit layout cannot hold the scene's BRDFs and the engine's reserved bits.
    #[error(transparent)]
    Layout(#[from] histencil_model::LayoutError),
    /// The model refused to plan the frame: a request that does not fit the stencil layout.
    #[error(transparent)]
    Plan(#[from] histencil_model::PlanError),
    /// histencil-brdf refused to build a BRDF table (its resolution, or a BRDF it cannot hold).
    #[error(transparent)]
    Lut(#[from] histencil_brdf::lut::LutError),
    /// The LUT technique's tables would not fit in one storage buffer on this device.
    #[error(
        "the BRDF tables need {bytes} bytes, more than this device's storage-buffer range of \
         {limit} bytes: lower the LUT resolution"
    )]
    LutTooLarge {
        /// The size of all the tables together.
        bytes: u64,
        /// The device's `maxStorageBufferRange`.
        limit: u64,
    },
    /// The LUT technique on a scene whose BRDF parameters vary per texel.
    #[error(
        "the LUT technique tabulates each material's own BRDF parameters, and object `{object}`'s \
         metallic-roughness map changes its {brdf} parameters per texel, which no table per \
         material follows: light this scene with stencil, branching or adaptive"
    )]
    LutTexturedParameters {
        /// The scene object's name.
        object: String,
        /// The name of its BRDF.
        brdf: &'static str,
    },
    /// The LUT technique on a BRDF that no table can hold
    /// ([`crate::lut_refusal`]: an engine BRDF whose function takes the tint, that reads the
    /// tangent, or that lights where `N.L <= 0`).
    #[error(
        "the LUT technique cannot light object `{object}`: {why}; light this scene with \
         stencil, branching, adaptive, tiled or depth-id"
    )]
    LutUntabulable {
        /// The scene object's name.
        object: String,
        /// The name of its BRDF.
        brdf: &'static str,
        /// Why not.
        why: histencil_brdf::lut::LutError,
    },
    /// The alpha entities could not be laid out in the lightmap atlas.
    #[error(transparent)]
    Lightmap(#[from] histencil_alpha::LayoutError),
    /// More materials than the G-buffer's material index can name.
    #[error("{count} distinct materials; the G-buffer indexes at most {max}")]
    TooManyMaterials {
        /// Distinct materials in the scene.
        count: usize,
        /// What the G-buffer indexes.
        max: usize,
    },
    /// A frame that does not fit its lighting or lightmaps (an engine's input at record time).
    #[error("bad lighting frame: {0}")]
    BadFrame(String),
    /// A call that rewrites or frees what a recorded frame uses, while that frame is not known
    /// finished: a slot recorded again, a resize or a destroy before the engine said the GPU
    /// finished (`DeferredLighting::slot_finished`). Nothing was changed.
    #[error("frames in flight: {0}")]
    InFlight(String),
    /// A description or hooks refused at creation (an engine's input when it makes a
    /// [`crate::DeferredLighting`], [`crate::AlphaLightmaps`] or [`crate::EngineHooks`]): said
    /// as such, not as a frame's fault.
    #[error("bad lighting setup: {0}")]
    BadSetup(String),
    /// A combination histencil does not implement (statistics without hi-stencil, ...): the
    /// message names it.
    #[error("not supported yet: {0}")]
    Unsupported(&'static str),
    /// A BRDF set that cannot be compiled (the engine's GLSL, with its file and line), or a
    /// material whose BRDF the lighting's set does not hold.
    #[error("BRDF set: {0}")]
    BrdfSet(String),
    /// A tool's output file could not be written (nothing half-written is left behind).
    #[error("cannot write `{path}`: {message}")]
    Output {
        /// The file that was to be written.
        path: String,
        /// The I/O or encoder error.
        message: String,
    },
}

/// Who can prevent an [`Error`], and so what a caller does about it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cause {
    /// The caller broke the API's rules (a frame, description or slot that does not fit): a
    /// bug in the calling code, never worth retrying as it is.
    Usage,
    /// The device, driver or loader cannot do it (or failed doing it): another device, format
    /// or configuration may; a test skips it, a CI job names it.
    Device,
    /// The content (scene, layout, plan, tables) cannot be rendered as asked.
    Data,
    /// A file could not be written.
    Output,
}

impl Error {
    /// Who can prevent this error ([`Cause`]), as wgpu-hal tells a device error from a usage
    /// error: what an engine logs as its own bug, and what it reports as the player's GPU.
    pub fn cause(&self) -> Cause {
        match self {
            Error::BadFrame(_)
            | Error::BadSetup(_)
            | Error::InFlight(_)
            | Error::Unsupported(_) => Cause::Usage,
            // A zero size is the caller's (a minimised window, say); one past the device's
            // largest image is the device's.
            Error::BadResolution { width: 0, .. } | Error::BadResolution { height: 0, .. } => {
                Cause::Usage
            }
            // A table or atlas resolution is a setting the caller chose.
            Error::Lut(histencil_brdf::lut::LutError::Resolution(_))
            | Error::Lightmap(histencil_alpha::LayoutError::BadResolution(_)) => Cause::Usage,
            Error::Loading(_)
            | Error::NoDevice(_)
            | Error::MissingFormat(_)
            | Error::DeviceLimit(_)
            | Error::Vulkan { .. }
            | Error::GpuStalled { .. }
            | Error::Allocation { .. }
            | Error::BadResolution { .. }
            | Error::LutTooLarge { .. } => Cause::Device,
            Error::Scene(_)
            | Error::Layout(_)
            | Error::Plan(_)
            | Error::Lut(_)
            | Error::Lightmap(_)
            | Error::TooManyMaterials { .. }
            | Error::LutTexturedParameters { .. }
            | Error::LutUntabulable { .. }
            | Error::BrdfSet(_) => Cause::Data,
            Error::Output { .. } => Cause::Output,
        }
    }
}

/// The crate's result, with [`Error`] unless said otherwise.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Attaches the call name to a raw `vk::Result`.
pub(crate) trait VkCall<T> {
    fn call(self, call: &'static str) -> Result<T>;
}

impl<T> VkCall<T> for Result<T, vk::Result> {
    fn call(self, call: &'static str) -> Result<T> {
        self.map_err(|result| Error::Vulkan { call, result })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The variants whose cause depends on what they hold are sorted by it: a size or a
    /// resolution the caller chose is the caller's, one past the device's limit the device's.
    #[test]
    fn causes_follow_who_can_prevent_the_error() {
        let resolution = |width, height| Error::BadResolution {
            width,
            height,
            reason: String::new(),
        };
        assert_eq!(resolution(0, 720).cause(), Cause::Usage);
        assert_eq!(resolution(1280, 0).cause(), Cause::Usage);
        assert_eq!(resolution(100_000, 720).cause(), Cause::Device);
        let lut = histencil_brdf::lut::LutError::Resolution(1);
        assert_eq!(Error::Lut(lut).cause(), Cause::Usage);
        let lightmap = histencil_alpha::LayoutError::BadResolution(0);
        assert_eq!(Error::Lightmap(lightmap).cause(), Cause::Usage);
        let lost = Error::Vulkan {
            call: "vkWaitForFences",
            result: vk::Result::ERROR_DEVICE_LOST,
        };
        assert_eq!(lost.cause(), Cause::Device);
        assert_eq!(Error::InFlight(String::new()).cause(), Cause::Usage);
        assert_eq!(Error::DeviceLimit(String::new()).cause(), Cause::Device);
    }
}
