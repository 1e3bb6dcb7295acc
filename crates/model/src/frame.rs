//! A frame's lighting as one ordered list of steps: every light's passes, the hi-stencil flushes
//! the flush policy inserts, and the save / restore of preserved bits where a platform needs it.

use crate::backend::PlatformBackend;
use crate::layout::StencilLayout;
use crate::plan::{plan_light, LightRequest, Pass, PlanError};

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

#[derive(Clone, Debug, PartialEq)]
pub enum Step {
    /// A pass of light `light` (its index in the request list).
    Pass { light: usize, pass: Pass },
    /// Pending hi-stencil state becomes active.
    FlushHiStencil,
    /// Copies the bits of `mask` aside before lighting.
    SavePreserved { mask: u8 },
    /// Writes the saved bits back; costs one full-screen pass per bit of `mask`.
    RestorePreserved { mask: u8 },
}

impl Step {
    fn pass(&self) -> Option<&Pass> {
        match self {
            Step::Pass { pass, .. } => Some(pass),
            _ => None,
        }
    }
}

/// The lighting of a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct FramePlan {
    pub steps: Vec<Step>,
}

impl FramePlan {
    /// Plans every light in order, then inserts flushes and the save / restore steps.
    pub fn build(
        layout: &StencilLayout,
        backend: &dyn PlatformBackend,
        lights: &[LightRequest],
        policy: FlushPolicy,
    ) -> Result<Self, PlanError> {
        let caps = backend.caps();
        let mut steps = Vec::new();
        for (light, request) in lights.iter().enumerate() {
            for pass in plan_light(layout, &caps, request)? {
                steps.push(Step::Pass { light, pass });
            }
        }
        let mut steps = insert_flushes(steps, policy);
        let preserved = layout.preserved_mask();
        if caps.save_restore_preserved && caps.zero_preserved_as_we_go && preserved != 0 {
            steps.insert(0, Step::SavePreserved { mask: preserved });
            steps.push(Step::RestorePreserved { mask: preserved });
        }
        Ok(Self { steps })
    }

    pub fn passes(&self) -> impl Iterator<Item = &Pass> {
        self.steps.iter().filter_map(Step::pass)
    }

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

    /// A printable description, one step per line.
    pub fn describe(&self) -> String {
        let mut out = String::new();
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
