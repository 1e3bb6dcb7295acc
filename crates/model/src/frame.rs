//! A frame's lighting as one ordered list of steps: every light's passes, the hi-stencil flushes
//! the flush policy inserts, and the save / restore of preserved bits where a platform needs it.

use crate::backend::PlatformCaps;
use crate::layout::StencilLayout;
use crate::plan::{plan_light, LightCase, LightRequest, LightTechnique, Pass, PlanError};
use crate::view::{DepthConvention, NdcRect};

/// When pending hi-stencil state is made visible to later tests.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum FlushPolicy {
    /// Exactly one flush before each test that reads state written since the last flush.
    #[default]
    Auto,
    /// A flush after every pass that writes stencil or hi-stencil: correct, and wasteful.
    Always,
    /// No flushes: tests read stale state on purpose, to show what breaks.
    Never,
}

/// One thing the frame's lighting does, in order: what the recorder replays and the simulator
/// runs.
#[derive(Clone, Debug, PartialEq)]
pub enum Step {
    /// A pass of light `light` (its index in [`FramePlan::lights`]).
    Pass {
        /// The light's index in [`FramePlan::lights`].
        light: usize,
        /// The draw and its full state.
        pass: Pass,
    },
    /// Pending hi-stencil state becomes active.
    FlushHiStencil,
    /// Copies the bits of `mask` aside before lighting.
    SavePreserved {
        /// The engine's bits ([`StencilLayout::engine_mask`]).
        mask: u8,
    },
    /// Writes the saved bits back; costs one full-screen pass per bit of `mask`.
    RestorePreserved {
        /// The bits saved by the matching [`Step::SavePreserved`].
        mask: u8,
    },
}

impl Step {
    fn pass(&self) -> Option<&Pass> {
        match self {
            Step::Pass { pass, .. } => Some(pass),
            _ => None,
        }
    }
}

/// One light the frame draws, and why it is drawn as it is.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedLight {
    /// The light's index in the caller's light list.
    pub input: usize,
    /// The estimated fraction of the screen its volume covers (1 for lights reaching the near
    /// plane and for full-screen lights); `None` for plans built from bare requests.
    pub coverage: Option<f64>,
    /// A rectangle holding every pixel its volume mesh can rasterise: the screen rectangle of
    /// the sphere that bounds the mesh. `None` where nothing smaller than the screen is known
    /// (plans from bare requests, full-screen lights, a bound reaching the eye plane). The GPU
    /// hi-stencil emulation looks for the tiles a write touched only inside it.
    pub screen_rect: Option<NdcRect>,
    /// The depth-buffer values its volume can reach, where its shade passes are confined to
    /// them by the depth bounds test ([`FramePlan::with_depth_bounds`]); `None` otherwise.
    pub depth_range: Option<crate::view::DepthRange>,
    /// Its case, the BRDF slots it touches and the technique chosen for it.
    pub request: LightRequest,
}

impl PlannedLight {
    /// Bare requests, numbered in order, without coverage.
    pub fn numbered(requests: impl IntoIterator<Item = LightRequest>) -> Vec<Self> {
        requests
            .into_iter()
            .enumerate()
            .map(|(input, request)| Self {
                input,
                coverage: None,
                screen_rect: None,
                depth_range: None,
                request,
            })
            .collect()
    }
}

/// The lighting of a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct FramePlan {
    /// The depth convention the passes' depth tests are written for.
    pub depth: DepthConvention,
    /// The lights drawn, in drawing order; lights that touch nothing or that the view cannot
    /// see are not here.
    pub lights: Vec<PlannedLight>,
    /// Every pass, flush and save / restore, in the order they run.
    pub steps: Vec<Step>,
    /// The view, lights and layout [`crate::plan_frame`] made this plan for, which the lighting
    /// holds every frame against; `None` for a plan built by hand from requests, which names no
    /// view.
    pub made_for: Option<Box<crate::light_shape::PlannedFor>>,
}

impl FramePlan {
    /// Plans every light in order, then inserts flushes and the save / restore steps.
    pub fn build(
        layout: &StencilLayout,
        caps: &PlatformCaps,
        depth: DepthConvention,
        lights: Vec<PlannedLight>,
        policy: FlushPolicy,
    ) -> Result<Self, PlanError> {
        let mut steps = Vec::new();
        for (light, planned) in lights.iter().enumerate() {
            for pass in plan_light(layout, caps, depth, &planned.request)? {
                steps.push(Step::Pass { light, pass });
            }
        }
        let mut steps = insert_flushes(steps, policy);
        // Only the engine's declared bits come back; free bits may stay zeroed.
        let engine = layout.engine_mask();
        if caps.save_restore_preserved && caps.zero_preserved_as_we_go && engine != 0 {
            steps.insert(0, Step::SavePreserved { mask: engine });
            steps.push(Step::RestorePreserved { mask: engine });
        }
        Ok(Self {
            depth,
            lights,
            steps,
            made_for: None,
        })
    }

    /// Plans bare requests (numbered in order, standard depth) for the platform `backend`: what
    /// tests and what-if studies build by hand.
    pub fn from_requests(
        layout: &StencilLayout,
        backend: &dyn crate::backend::PlatformBackend,
        requests: &[LightRequest],
        policy: FlushPolicy,
    ) -> Result<Self, PlanError> {
        Self::build(
            layout,
            &backend.caps(),
            DepthConvention::Standard,
            PlannedLight::numbered(requests.iter().cloned()),
            policy,
        )
    }

    /// Whether drawn light `light` is drawn full-screen (no volume to rasterise).
    pub fn is_full_screen(&self, light: usize) -> bool {
        matches!(
            self.lights[light].request.case,
            LightCase::FullScreen | LightCase::ViewerInside
        )
    }

    /// The passes alone, in order, without flushes or save / restore.
    pub fn passes(&self) -> impl Iterator<Item = &Pass> {
        self.steps.iter().filter_map(Step::pass)
    }

    /// How many hi-stencil flushes the flush policy inserted.
    pub fn flushes(&self) -> usize {
        self.steps
            .iter()
            .filter(|s| matches!(s, Step::FlushHiStencil))
            .count()
    }

    /// Full-screen or volume draws the plan costs, flushes excluded; a restore counts one
    /// full-screen pass per preserved bit.
    pub fn draw_count(&self) -> usize {
        self.steps
            .iter()
            .map(|s| match s {
                Step::Pass { .. } => 1,
                Step::FlushHiStencil | Step::SavePreserved { .. } => 0,
                Step::RestorePreserved { mask } => mask.count_ones() as usize,
            })
            .sum()
    }

    /// A printable description: one line per drawn light (its case, coverage, BRDF slots and
    /// technique), then one line per step.
    pub fn describe(&self) -> String {
        let mut out = format!("depth {:?}\n", self.depth);
        for (index, light) in self.lights.iter().enumerate() {
            let request = &light.request;
            let coverage = light.coverage.map_or(String::new(), |c| {
                format!(", {:.2} % of the screen", 100.0 * c)
            });
            let technique = match (request.affected.len(), request.technique) {
                (..=1, _) | (_, LightTechnique::SingleBrdf) => "single BRDF",
                (_, LightTechnique::Stencil) => "stencil",
                (_, LightTechnique::Branching) => "branching",
            };
            out.push_str(&format!(
                "light {index} (input {}): {:?}{coverage}, BRDF slots {:?}, {technique}\n",
                light.input, request.case, request.affected
            ));
        }
        for step in &self.steps {
            let line = match step {
                Step::Pass { light, pass } => format!("light {light}: {}", pass.label()),
                Step::FlushHiStencil => "flush hi-stencil".into(),
                Step::SavePreserved { mask } => format!("save preserved bits {mask:#04x}"),
                Step::RestorePreserved { mask } => format!("restore preserved bits {mask:#04x}"),
            };
            out.push_str(&line);
            out.push('\n');
        }
        out
    }
}

/// Inserts [`Step::FlushHiStencil`] according to `policy`. Pure.
pub fn insert_flushes(steps: Vec<Step>, policy: FlushPolicy) -> Vec<Step> {
    let mut out = Vec::with_capacity(steps.len() * 2);
    let mut unflushed_write = false;
    for step in steps {
        let (writes, writes_any, tests) = step.pass().map_or((false, false, false), |p| {
            (
                p.state.writes_hi_stencil(),
                p.state.writes_hi_stencil() || p.state.writes_stencil(),
                p.state.tests_hi_stencil(),
            )
        });
        if policy == FlushPolicy::Auto && tests && unflushed_write {
            out.push(Step::FlushHiStencil);
            unflushed_write = false;
        }
        out.push(step);
        unflushed_write |= writes;
        if policy == FlushPolicy::Always && writes_any {
            out.push(Step::FlushHiStencil);
        }
    }
    out
}

/// Hi-stencil tests that read state some earlier pass wrote after the previous test: each needs
/// one flush in between. Counted independently of [`insert_flushes`] for its tests.
pub fn write_test_dependencies(steps: &[Step]) -> usize {
    let passes: Vec<&Pass> = steps.iter().filter_map(Step::pass).collect();
    passes
        .iter()
        .enumerate()
        .filter(|(i, p)| {
            p.state.tests_hi_stencil() && {
                let since_last_test = passes[..*i]
                    .iter()
                    .rposition(|q| q.state.tests_hi_stencil())
                    .map_or(0, |j| j + 1);
                passes[since_last_test..*i]
                    .iter()
                    .any(|q| q.state.writes_hi_stencil())
            }
        })
        .count()
}
