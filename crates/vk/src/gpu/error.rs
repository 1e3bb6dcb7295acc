use ash::vk;

/// What can go wrong in the renderer that a caller cannot prevent by calling it correctly.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error("cannot load the Vulkan library: {0}")]
    Loading(String),
    #[error("no suitable Vulkan 1.3 device: {0}")]
    NoDevice(String),
    /// The device lacks a format that was asked for (a caller can skip that configuration).
    #[error("missing format: {0}")]
    MissingFormat(String),
    #[error("Vulkan call `{call}` failed: {result}")]
    Vulkan {
        call: &'static str,
        result: vk::Result,
    },
    #[error("GPU memory allocation `{name}` failed: {message}")]
    Allocation { name: String, message: String },
    #[error("bad resolution {width}x{height}: {reason}")]
    BadResolution {
        width: u32,
        height: u32,
        reason: String,
    },
    #[error(transparent)]
    Scene(#[from] histencil_scene::SceneError),
    #[error(transparent)]
    Layout(#[from] histencil_model::LayoutError),
    #[error(transparent)]
    Plan(#[from] histencil_model::PlanError),
    #[error(transparent)]
    Lut(#[from] histencil_brdf::lut::LutError),
    #[error(
        "the BRDF tables need {bytes} bytes, more than this device's storage-buffer range of \
         {limit} bytes: lower the LUT resolution"
    )]
    LutTooLarge { bytes: u64, limit: u64 },
    /// The LUT technique on a scene whose BRDF parameters vary per texel.
    #[error(
        "the LUT technique tabulates each material's own BRDF parameters, and object `{object}`'s \
         metallic-roughness map changes its {brdf} parameters per texel, which no table per \
         material follows: light this scene with stencil, branching or adaptive"
    )]
    LutTexturedParameters { object: String, brdf: &'static str },
    #[error(
        "the LUT technique tabulates each material's BRDF divided by its tint, and object \
         `{object}`'s {brdf} is not its tint times a function of the angles (its dielectric \
         specular is white): light this scene with stencil, branching or adaptive"
    )]
    LutUntabulable { object: String, brdf: &'static str },
    #[error(transparent)]
    Lightmap(#[from] histencil_alpha::LayoutError),
    #[error("{count} distinct materials; the G-buffer indexes at most {max}")]
    TooManyMaterials { count: usize, max: usize },
    /// A frame that does not fit its lighting or lightmaps (an engine's input at record time).
    #[error("bad lighting frame: {0}")]
    BadFrame(String),
    /// A description or hooks refused at creation (an engine's input when it makes a
    /// [`crate::DeferredLighting`], [`crate::AlphaLightmaps`] or [`crate::EngineHooks`]): said
    /// as such, not as a frame's fault.
    #[error("bad lighting setup: {0}")]
    BadSetup(String),
    #[error("not supported yet: {0}")]
    Unsupported(&'static str),
    #[error("cannot write `{path}`: {message}")]
    Output { path: String, message: String },
}

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
