//! The platforms by name: the one vocabulary `render --backend`, the check's case names, the
//! lab's rows and an engine's configuration share. [`Backend`] is what the renderer takes; a
//! [`Platform`] is a backend with its name, so that a name is spelled and parsed in one place.

use crate::renderer::technique::Backend;

/// A platform whose stencil and hi-stencil behaviour the lighting plan follows, by name: each
/// names one [`Backend`], the 360-like one in its three ways with its preserved bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Platform {
    /// 360-like, zeroing the engine's bits as lights draw (the talk's fix).
    X360,
    /// 360-like without zeroing: the talk's failure.
    X360NoZeroing,
    /// 360-like, zeroing, the engine's bits saved before lighting and restored after.
    X360SaveRestore,
    /// PS3-like: a hi-stencil read mask.
    Ps3,
    /// Plain Vulkan: no hi-stencil.
    Native,
    /// AMD GFX9-11 with pretests (modelled from AMD's driver sources).
    AmdPretest,
    /// AMD GFX12's AND/OR tiles (modelled from AMD's driver sources).
    AmdAndOr,
    /// GFX12's tiles ignoring a test's read mask: only as a known-wrong case.
    AmdAndOrUnmasked,
}

impl Platform {
    /// Every platform, in the order `render --help` lists them.
    pub const ALL: [Platform; 8] = [
        Platform::X360,
        Platform::X360NoZeroing,
        Platform::X360SaveRestore,
        Platform::Ps3,
        Platform::Native,
        Platform::AmdPretest,
        Platform::AmdAndOr,
        Platform::AmdAndOrUnmasked,
    ];

    /// The name commands, case names and reports use (`x360-save-restore`).
    pub fn name(self) -> &'static str {
        match self {
            Platform::X360 => "x360",
            Platform::X360NoZeroing => "x360-no-zeroing",
            Platform::X360SaveRestore => "x360-save-restore",
            Platform::Ps3 => "ps3",
            Platform::Native => "native",
            Platform::AmdPretest => "amd-pretest",
            Platform::AmdAndOr => "amd-andor",
            Platform::AmdAndOrUnmasked => "amd-andor-unmasked",
        }
    }

    /// What the platform is, in one line (a command's help).
    pub fn about(self) -> &'static str {
        match self {
            Platform::X360 => {
                "360-like hi-stencil without a read mask, the engine's bits zeroed as lights \
                 draw (the talk's fix)"
            }
            Platform::X360NoZeroing => {
                "360-like without zeroing: engine bits break culling (the talk's failure)"
            }
            Platform::X360SaveRestore => {
                "360-like, zeroing, the engine's bits saved before lighting and restored after"
            }
            Platform::Ps3 => {
                "PS3-like hi-stencil with a read mask; also the model of NVIDIA's ZCull stencil \
                 criterion (its documented fields are the RSX's; what a region holds is assumed)"
            }
            Platform::Native => "plain Vulkan: no hierarchical stencil",
            Platform::AmdPretest => {
                "AMD GFX9-11 with two hierarchical-stencil pretests, modelled from AMD's driver \
                 sources (not measured on AMD hardware): the native plan, the GPU's tiles \
                 emulated"
            }
            Platform::AmdAndOr => "AMD GFX12's per-tile AND/OR of the stencil, modelled likewise",
            Platform::AmdAndOrUnmasked => {
                "GFX12's tiles ignoring a test's read mask: engine bits break culling \
                 (known-wrong)"
            }
        }
    }

    /// The backend the renderer takes.
    pub fn backend(self) -> Backend {
        let x360 = |zero_preserved, save_restore| Backend::X360 {
            zero_preserved,
            save_restore,
        };
        match self {
            Platform::X360 => x360(true, false),
            Platform::X360NoZeroing => x360(false, false),
            Platform::X360SaveRestore => x360(true, true),
            Platform::Ps3 => Backend::Ps3,
            Platform::Native => Backend::Native,
            Platform::AmdPretest => Backend::AmdPretest,
            Platform::AmdAndOr => Backend::AmdAndOr,
            Platform::AmdAndOrUnmasked => Backend::AmdAndOrUnmasked,
        }
    }

    /// The platform of `backend`; `None` for a 360-like backend saving and restoring without
    /// zeroing, which the plan never makes (saving is only needed because zeroing destroys).
    pub fn of(backend: Backend) -> Option<Platform> {
        Platform::ALL.into_iter().find(|p| p.backend() == backend)
    }

    /// Whether the backend emulates a console's hi-stencil (and so has flushes to vary; AMD's
    /// hierarchies follow stencil writes by themselves).
    pub fn has_hi_stencil(self) -> bool {
        matches!(
            self,
            Platform::X360 | Platform::X360NoZeroing | Platform::X360SaveRestore | Platform::Ps3
        )
    }
}

impl std::fmt::Display for Platform {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Platform {
    type Err = String;

    /// A platform by its [`Platform::name`]; the error lists the names.
    fn from_str(s: &str) -> Result<Self, String> {
        Platform::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| {
                let names: Vec<&str> = Platform::ALL.iter().map(|p| p.name()).collect();
                format!("unknown platform `{s}`: one of {}", names.join(", "))
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_platform_has_one_name_and_one_backend() {
        for p in Platform::ALL {
            assert_eq!(p.name().parse::<Platform>(), Ok(p));
            assert_eq!(Platform::of(p.backend()), Some(p));
        }
        let odd = Backend::X360 {
            zero_preserved: false,
            save_restore: true,
        };
        assert_eq!(Platform::of(odd), None);
        let err = "x361".parse::<Platform>().unwrap_err();
        assert!(err.contains("one of x360, x360-no-zeroing"), "{err}");
    }
}
