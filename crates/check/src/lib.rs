//! histencil-check: the validation-CI matrix.
//!
//! One of histencil's three uses is Vulkan validation-layer CI: a driver, layer or engine team
//! runs a known workload on its device under the Khronos validation layer and wants its CI to
//! show what passed. This crate is that workload: for each scene, every configuration it needs
//! ([`matrix`]: technique x platform backend x flush policy x preserved stencil pattern x alpha
//! mode x depth-stencil format x resolution), each rendered under validation with
//! synchronisation validation and judged ([`judge`]) against the forward reference rendered in
//! the same process, plus its stencil after lighting against the backend's promise. The talk's
//! known-wrong configurations are cases too, expected to fail. [`report`] writes JUnit XML, JSON
//! and a summary. `histencil check` is a thin wrapper over [`run_check`].

pub mod baseline_update;
pub mod bound;
pub mod gtest;
pub mod judge;
pub mod lists;
pub mod matrix;
pub mod report;
mod run;
pub mod runner;

pub use run::{
    planned_cases, run_check, CaseResult, CheckError, CheckOptions, CheckReport, CheckScene, Event,
    InjectedFault, Outcome, ACCEPTED_BEST_PRACTICES,
};
