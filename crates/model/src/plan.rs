//! Light pass plans: the ordered passes that light one volume, each with its full state.
//!
//! Written here for standard depth (near 0, far 1); with reversed depth every depth compare is
//! mirrored ([`DepthConvention::orient`]) and full-screen passes sit at depth 0. A surface at
//! depth `d` lies inside a light volume whose front face is at `f` and back face at `b` along the
//! pixel's ray when `f < d < b` (nearer than, in the reversed case). Sky pixels lie at the far
//! depth and are never lit. Volume pipelines clamp depth, so a back face beyond the far plane
//! sits at the far depth and a volume crossing the far plane needs no special case.
//!
//! ```text
//! Outside (the talk):  setup    back faces, depth b <= d  -> culling bit := 1
//!                      mask b   front faces, hi-stencil write, ref = b << shift    (hi-stencil)
//!                      shade b  front faces, depth f < d, stencil == b << shift
//!                      cleanup  back faces, no depth      -> culling bit := 0
//! Crosses near plane:  setup    front faces, depth f >= d -> culling bit := 1
//!                      mask b / shade b on back faces, depth b > d
//!                      cleanup  front faces, no depth     -> culling bit := 0
//! Viewer inside:       mask b / shade b on a full-screen triangle at the far depth, far > d
//! Full screen:         the same
//! ```
//! 360-like with zeroing: setup and cleanup write `!brdf_mask` (preserved bits := 0) and every
//! case not starting with a back-face setup first draws a `zero-preserved` pass over the whole
//! footprint, so the hi-stencil sees zeros wherever it must pass. A single affected BRDF (or a
//! single-BRDF layout) needs no mask pass: the last stencil-writing pass before shading writes
//! the hi-stencil itself.

use crate::backend::PlatformCaps;
use crate::layout::StencilLayout;
use crate::state::{
    CompareOp, CullMode, DepthState, FaceStencil, HiStencilState, PassState, StencilOp,
};
use crate::view::DepthConvention;

/// How the light volume relates to the camera.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LightCase {
    /// The whole volume lies beyond the near plane (far crossing is fine: depth clamp).
    Outside,
    /// The near plane cuts the volume: some pixels see its front face, others only its back.
    CrossesNear,
    /// The viewer is inside the volume: no front face is visible anywhere.
    ViewerInside,
    /// A light without a volume (directional): a full-screen triangle at the far plane.
    FullScreen,
}

/// How the BRDFs of one light are separated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LightTechnique {
    /// One BRDF affected (or one in use): the plain depth-culled light, no per-BRDF passes.
    SingleBrdf,
    /// The talk's technique: a mask and a shade pass per affected BRDF.
    Stencil,
    /// One shade pass whose shader branches on the BRDF id.
    Branching,
}

/// What one light needs.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LightRequest {
    /// How its volume meets the camera, which decides the faces and depth tests of its passes.
    pub case: LightCase,
    /// BRDF slots whose objects the light can reach. Empty: the light draws nothing.
    pub affected: Vec<u32>,
    /// How its BRDFs are separated.
    pub technique: LightTechnique,
}

/// What a pass rasterises.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Geometry {
    /// The light's convex volume; [`PassState::cull`] says which faces remain.
    Volume,
    /// A full-screen triangle at the far depth ([`DepthConvention::far`]).
    FullScreen,
}

/// Which light shader runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Shader {
    /// The shader of one BRDF slot.
    Brdf(u32),
    /// One shader branching on the BRDF id read from the G-buffer.
    Branching,
}

/// The role of a pass in the plan.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PassKind {
    /// 360-like only: zeroes the culling and preserved bits over the whole footprint, where no
    /// back-face setup does it.
    ZeroPreserved,
    /// Marks the culling bit where the surface lies outside the volume (and, outside case on
    /// 360-like, zeroes the preserved bits).
    Setup,
    /// Writes the hi-stencil for the shade pass of this shader; no colour.
    Mask(Shader),
    /// Runs the light shader.
    Shade(Shader),
    /// Clears the culling bit (and preserved bits on 360-like with zeroing).
    Cleanup,
}

/// One draw of a light: its role, what it rasterises and the whole pipeline and stencil state
/// it runs with, so a recorder translates it without deciding anything.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Pass {
    /// The pass's role: setup, mask, shade, cleanup.
    pub kind: PassKind,
    /// The light's volume or the full-screen triangle.
    pub geometry: Geometry,
    /// Culling, depth, stencil and hi-stencil state.
    pub state: PassState,
}

impl Pass {
    /// Which faces the pass rasterises: front faces (`Some(true)`: a full-screen pass, or a
    /// volume culling back faces), back faces (`Some(false)`: a volume culling front faces), or
    /// both (`None`: a volume culling neither, which no plan makes: each pixel would run the
    /// pass's stencil ops twice).
    pub fn front_facing(&self) -> Option<bool> {
        match (self.geometry, self.state.cull) {
            (Geometry::FullScreen, _) | (Geometry::Volume, CullMode::Back) => Some(true),
            (Geometry::Volume, CullMode::Front) => Some(false),
            (Geometry::Volume, CullMode::None) => None,
        }
    }

    /// A kebab-case label for debug markers and reports.
    pub fn label(&self) -> String {
        match self.kind {
            PassKind::ZeroPreserved => "zero-preserved".into(),
            PassKind::Setup => "setup".into(),
            PassKind::Mask(Shader::Brdf(slot)) => format!("mask-brdf-{slot}"),
            PassKind::Mask(Shader::Branching) => "mask-branching".into(),
            PassKind::Shade(Shader::Brdf(slot)) => format!("shade-brdf-{slot}"),
            PassKind::Shade(Shader::Branching) => "shade-branching".into(),
            PassKind::Cleanup => "cleanup".into(),
        }
    }
}

/// A request that cannot be planned: a caller bug that is reported, not a panic.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum PlanError {
    /// A light names a BRDF slot the layout does not have.
    #[error("BRDF slot {slot} is not in the layout ({brdfs} BRDFs in use)")]
    SlotOutOfRange {
        /// The slot named.
        slot: u32,
        /// BRDFs in the layout.
        brdfs: u32,
    },
    /// `PlanInputs::brdf_bounds` must hold one list (possibly empty) per BRDF slot of the
    /// layout: fewer would light the missing BRDFs' surfaces with nothing and say nothing.
    #[error(
        "brdf_bounds has {bounds} entries, but the stencil layout has {brdfs} BRDFs: give one \
         list of world boxes per BRDF slot, empty for a BRDF with no surfaces"
    )]
    BoundsCount {
        /// Lists given.
        bounds: usize,
        /// BRDFs in the layout.
        brdfs: u32,
    },
    /// [`LightTechnique::SingleBrdf`] was asked for a light that reaches several BRDFs.
    #[error("single-BRDF technique asked for a light affecting {count} BRDFs")]
    SingleWithManyBrdfs {
        /// BRDFs the light reaches.
        count: usize,
    },
    /// A light's shape cannot be planned with (not finite, a zero direction, a range not above
    /// 0, ...).
    #[error("light {index}: {problem}")]
    BadLight {
        /// The light's index in [`PlanInputs::lights`](crate::PlanInputs::lights).
        index: usize,
        /// What is wrong with it.
        problem: &'static str,
    },
    /// A world box is not finite or has a min corner above its max.
    #[error("bounds {index} of BRDF slot {slot}: {problem}")]
    BadBounds {
        /// The BRDF slot whose list holds the box.
        slot: u32,
        /// The box's index in that list.
        index: usize,
        /// What is wrong with it.
        problem: &'static str,
    },
    /// The view's matrices or description were refused.
    #[error("view: {0}")]
    View(#[from] crate::view::ViewError),
}

/// Where the shading passes of a case rasterise, and their depth test.
///
/// A viewer inside a closed volume sees one back face through every pixel, so the volume covers
/// the screen: it is drawn as the full-screen triangle, which rasterises each pixel exactly once
/// (the light's window is exactly 0 beyond its range, so the extra surfaces get nothing). Its
/// back faces did the same work but are not watertight there: the triangles that straddle the
/// eye plane are clipped one by one, and two of them can both cover a pixel, which then gets the
/// light twice (`histencil check` found one such pixel on the glTF test scene at 257x129 on
/// lavapipe).
fn shade_raster(case: LightCase, depth: DepthConvention) -> (Geometry, CullMode, DepthState) {
    let test = |op| DepthState::test(depth.orient(op));
    match case {
        LightCase::Outside => (Geometry::Volume, CullMode::Back, test(CompareOp::Less)),
        LightCase::CrossesNear => (Geometry::Volume, CullMode::Front, test(CompareOp::Greater)),
        LightCase::ViewerInside | LightCase::FullScreen => (
            Geometry::FullScreen,
            CullMode::None,
            test(CompareOp::Greater),
        ),
    }
}

/// The faces that mark (and later clear) the culling bit, and the depth test that marks it:
/// surfaces behind the back face (outside) or in front of the front face (near crossing).
fn culling_raster(case: LightCase, depth: DepthConvention) -> Option<(CullMode, CompareOp)> {
    match case {
        LightCase::Outside => Some((CullMode::Front, depth.orient(CompareOp::LessOrEqual))),
        LightCase::CrossesNear => Some((CullMode::Back, depth.orient(CompareOp::GreaterOrEqual))),
        LightCase::ViewerInside | LightCase::FullScreen => None,
    }
}

fn with_faces(state: PassState, face: FaceStencil) -> PassState {
    PassState {
        front: Some(face),
        back: Some(face),
        ..state
    }
}

/// A pass without colour or hi-stencil that writes stencil with `face`.
fn stencil_pass(
    kind: PassKind,
    geometry: Geometry,
    cull: CullMode,
    depth: DepthState,
    face: FaceStencil,
) -> Pass {
    let state = PassState {
        cull,
        depth,
        front: None,
        back: None,
        color_write: false,
        hi_stencil: None,
        depth_bounds: false,
    };
    Pass {
        kind,
        geometry,
        state: with_faces(state, face),
    }
}

/// Checks the request and returns its sorted slots and the technique it really needs.
fn normalise(
    layout: &StencilLayout,
    request: &LightRequest,
) -> Result<(Vec<u32>, LightTechnique), PlanError> {
    let mut slots = request.affected.clone();
    slots.sort_unstable();
    slots.dedup();
    if let Some(&slot) = slots.iter().find(|&&s| s >= layout.brdfs_in_use()) {
        return Err(PlanError::SlotOutOfRange {
            slot,
            brdfs: layout.brdfs_in_use(),
        });
    }
    if request.technique == LightTechnique::SingleBrdf && slots.len() > 1 {
        return Err(PlanError::SingleWithManyBrdfs { count: slots.len() });
    }
    let technique = if slots.len() == 1 {
        LightTechnique::SingleBrdf
    } else {
        request.technique
    };
    Ok((slots, technique))
}

/// Builds the passes of one light, in order, for a depth buffer following `depth`.
pub fn plan_light(
    layout: &StencilLayout,
    caps: &PlatformCaps,
    convention: DepthConvention,
    request: &LightRequest,
) -> Result<Vec<Pass>, PlanError> {
    let (slots, technique) = normalise(layout, request)?;
    if slots.is_empty() {
        return Ok(Vec::new());
    }
    let culling = layout.culling_mask();
    let zero = caps.zero_preserved_as_we_go;
    // Bits setup and cleanup write: the culling bit, plus the preserved bits when zeroing.
    let scratch_mask = if zero { !layout.brdf_mask() } else { culling };
    // The fine test of a shade pass: culling bit clear and, unless branching, the BRDF matches.
    let select_mask = match technique {
        LightTechnique::Branching => culling,
        _ => culling | layout.brdf_mask(),
    };
    let select_ref = match technique {
        LightTechnique::SingleBrdf => layout.brdf_reference(slots[0]),
        _ => 0,
    };
    // Hi-stencil without a read mask needs one exact value; branching has none to offer.
    let hi_usable =
        caps.hi_stencil && (caps.hi_stencil_read_mask || technique != LightTechnique::Branching);
    let hi = |reference: u8, write: bool| HiStencilState {
        compare: CompareOp::Equal,
        reference,
        read_mask: caps.hi_stencil_read_mask.then_some(select_mask),
        write,
        test: !write,
    };
    let culling_faces = culling_raster(request.case, convention);
    let (geometry, cull, depth) = shade_raster(request.case, convention);

    // Stencil-writing passes before any shading.
    let mut passes = Vec::new();
    if zero && request.case != LightCase::Outside {
        passes.push(stencil_pass(
            PassKind::ZeroPreserved,
            geometry,
            cull,
            DepthState::OFF,
            FaceStencil::writing(scratch_mask, 0, StencilOp::Zero, StencilOp::Zero),
        ));
    }
    if let Some((setup_cull, marks_culled)) = culling_faces {
        // Zeroing in the outside case rides on setup; near crossing was zeroed just above.
        let write_mask = if request.case == LightCase::Outside {
            scratch_mask
        } else {
            culling
        };
        let unmarked = if write_mask == culling {
            StencilOp::Keep
        } else {
            StencilOp::Zero
        };
        passes.push(stencil_pass(
            PassKind::Setup,
            Geometry::Volume,
            setup_cull,
            DepthState::test(marks_culled),
            FaceStencil::writing(write_mask, culling, StencilOp::Replace, unmarked),
        ));
    }
    // Hi-stencil may only be written by a pass that rasterises the shade pass's pixels, or
    // tiles only the shade pass reaches keep another light's state. Without per-BRDF masks,
    // the last stencil write before shading serves, unless it sees only front faces (near
    // crossing): then a mask pass of its own writes it.
    let last_covers_shade = request.case != LightCase::CrossesNear && !passes.is_empty();
    let single_mask = hi_usable && technique != LightTechnique::Stencil;
    let prelude_writes_hi = single_mask && last_covers_shade;
    if prelude_writes_hi {
        let last = passes.last_mut().expect("prelude is not empty");
        last.state.hi_stencil = Some(hi(select_ref, true));
    }
    let mask = |shader: Shader, reference: u8| Pass {
        kind: PassKind::Mask(shader),
        geometry,
        state: PassState {
            cull,
            depth,
            front: None,
            back: None,
            color_write: false,
            hi_stencil: Some(hi(reference, true)),
            depth_bounds: false,
        },
    };
    let single_shader = match technique {
        LightTechnique::Branching => Shader::Branching,
        _ => Shader::Brdf(slots[0]),
    };
    let single_hi_test =
        prelude_writes_hi || (single_mask && request.case == LightCase::CrossesNear);
    if single_mask && request.case == LightCase::CrossesNear {
        passes.push(mask(single_shader, select_ref));
    }

    let shade = |shader: Shader, reference: u8, hi_test: bool| {
        let state = PassState {
            cull,
            depth,
            front: None,
            back: None,
            color_write: true,
            hi_stencil: hi_test.then(|| hi(reference, false)),
            depth_bounds: false,
        };
        Pass {
            kind: PassKind::Shade(shader),
            geometry,
            state: with_faces(
                state,
                FaceStencil {
                    compare: CompareOp::Equal,
                    compare_mask: select_mask,
                    reference,
                    ..FaceStencil::DISABLED
                },
            ),
        }
    };
    if technique == LightTechnique::Stencil {
        for &slot in &slots {
            let reference = layout.brdf_reference(slot);
            if hi_usable {
                passes.push(mask(Shader::Brdf(slot), reference));
            }
            passes.push(shade(Shader::Brdf(slot), reference, hi_usable));
        }
    } else {
        passes.push(shade(single_shader, select_ref, single_hi_test));
    }

    if let Some((setup_cull, _)) = culling_faces {
        passes.push(stencil_pass(
            PassKind::Cleanup,
            Geometry::Volume,
            setup_cull,
            DepthState::OFF,
            FaceStencil::writing(scratch_mask, 0, StencilOp::Zero, StencilOp::Zero),
        ));
    }
    Ok(passes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::{Native, PlatformBackend, Ps3Like, X360Like};

    fn request(case: LightCase, affected: &[u32], technique: LightTechnique) -> LightRequest {
        LightRequest {
            case,
            affected: affected.to_vec(),
            technique,
        }
    }

    fn labels(passes: &[Pass]) -> Vec<String> {
        passes.iter().map(Pass::label).collect()
    }

    #[test]
    fn talks_plan_on_360_zeroes_preserved_bits() {
        let layout = StencilLayout::new(8, 0).unwrap();
        let caps = X360Like::default().caps();
        let plan = plan_light(
            &layout,
            &caps,
            DepthConvention::Standard,
            &request(LightCase::Outside, &[0, 3], LightTechnique::Stencil),
        )
        .unwrap();
        assert_eq!(
            labels(&plan),
            [
                "setup",
                "mask-brdf-0",
                "shade-brdf-0",
                "mask-brdf-3",
                "shade-brdf-3",
                "cleanup"
            ]
        );
        let cleanup = plan.last().unwrap().state.back.unwrap();
        assert_eq!(cleanup.pass, StencilOp::Zero);
        assert_eq!(cleanup.write_mask, !0x0E);
        let mask = plan[3].state.hi_stencil.unwrap();
        assert_eq!(
            (mask.reference, mask.read_mask, mask.write),
            (0x06, None, true)
        );
        let shade = plan[4].state.front.unwrap();
        assert_eq!((shade.compare_mask, shade.reference), (0x0F, 0x06));
    }

    #[test]
    fn ps3_keeps_preserved_bits_and_uses_a_read_mask() {
        let layout = StencilLayout::new(3, 2).unwrap();
        let plan = plan_light(
            &layout,
            &Ps3Like.caps(),
            DepthConvention::Standard,
            &request(LightCase::Outside, &[1, 2], LightTechnique::Stencil),
        )
        .unwrap();
        for pass in &plan {
            if let Some(face) = pass.state.front {
                assert_eq!(face.write_mask & layout.preserved_mask(), 0);
            }
        }
        assert_eq!(plan[1].state.hi_stencil.unwrap().read_mask, Some(0x07));
    }

    #[test]
    fn native_has_no_mask_passes_and_no_hi_stencil() {
        let layout = StencilLayout::new(4, 0).unwrap();
        let plan = plan_light(
            &layout,
            &Native.caps(),
            DepthConvention::Standard,
            &request(LightCase::Outside, &[0, 1, 2], LightTechnique::Stencil),
        )
        .unwrap();
        assert_eq!(
            labels(&plan),
            [
                "setup",
                "shade-brdf-0",
                "shade-brdf-1",
                "shade-brdf-2",
                "cleanup"
            ]
        );
        assert!(plan.iter().all(|p| p.state.hi_stencil.is_none()));
    }

    #[test]
    fn one_brdf_in_use_gives_the_plain_depth_culled_light() {
        let layout = StencilLayout::new(1, 0).unwrap();
        let plan = plan_light(
            &layout,
            &Ps3Like.caps(),
            DepthConvention::Standard,
            &request(LightCase::Outside, &[0], LightTechnique::Stencil),
        )
        .unwrap();
        assert_eq!(labels(&plan), ["setup", "shade-brdf-0", "cleanup"]);
        assert!(plan[0].state.writes_hi_stencil());
        assert!(plan[1].state.tests_hi_stencil());
    }

    #[test]
    fn viewer_inside_shades_the_whole_screen_once_without_culling_bit() {
        let layout = StencilLayout::new(2, 0).unwrap();
        let plan = plan_light(
            &layout,
            &Native.caps(),
            DepthConvention::Standard,
            &request(LightCase::ViewerInside, &[0, 1], LightTechnique::Stencil),
        )
        .unwrap();
        assert_eq!(labels(&plan), ["shade-brdf-0", "shade-brdf-1"]);
        assert_eq!(plan[0].geometry, Geometry::FullScreen);
        assert_eq!(plan[0].state.cull, CullMode::None);
        assert_eq!(plan[0].state.depth.compare, Some(CompareOp::Greater));
    }

    #[test]
    fn near_crossing_marks_the_culling_bit_from_front_faces() {
        let layout = StencilLayout::new(2, 1).unwrap();
        let plan = plan_light(
            &layout,
            &X360Like::default().caps(),
            DepthConvention::Standard,
            &request(LightCase::CrossesNear, &[0, 1], LightTechnique::Stencil),
        )
        .unwrap();
        assert_eq!(
            labels(&plan),
            [
                "zero-preserved",
                "setup",
                "mask-brdf-0",
                "shade-brdf-0",
                "mask-brdf-1",
                "shade-brdf-1",
                "cleanup"
            ]
        );
        assert_eq!(plan[1].state.cull, CullMode::Back);
        assert_eq!(plan[1].state.depth.compare, Some(CompareOp::GreaterOrEqual));
        assert_eq!(plan[3].state.cull, CullMode::Front);
    }

    #[test]
    fn branching_on_360_cannot_use_hi_stencil() {
        let layout = StencilLayout::new(4, 0).unwrap();
        let plan = plan_light(
            &layout,
            &X360Like::default().caps(),
            DepthConvention::Standard,
            &request(LightCase::Outside, &[0, 1], LightTechnique::Branching),
        )
        .unwrap();
        assert_eq!(labels(&plan), ["setup", "shade-branching", "cleanup"]);
        assert!(plan.iter().all(|p| p.state.hi_stencil.is_none()));
    }

    /// Reversed depth mirrors every depth compare and nothing else.
    #[test]
    fn reversed_depth_mirrors_the_depth_tests_only() {
        let layout = StencilLayout::new(4, 2).unwrap();
        for case in [
            LightCase::Outside,
            LightCase::CrossesNear,
            LightCase::ViewerInside,
            LightCase::FullScreen,
        ] {
            for caps in [X360Like::default().caps(), Ps3Like.caps(), Native.caps()] {
                let request = request(case, &[0, 2], LightTechnique::Stencil);
                let standard =
                    plan_light(&layout, &caps, DepthConvention::Standard, &request).unwrap();
                let reversed =
                    plan_light(&layout, &caps, DepthConvention::Reversed, &request).unwrap();
                assert_eq!(standard.len(), reversed.len());
                for (s, r) in standard.iter().zip(&reversed) {
                    let mirrored = s
                        .state
                        .depth
                        .compare
                        .map(|op| DepthConvention::Reversed.orient(op));
                    assert_eq!(r.state.depth.compare, mirrored, "{case:?} {}", s.label());
                    let depth = r.state.depth;
                    assert_eq!(PassState { depth, ..s.state }, r.state);
                    assert_eq!((s.kind, s.geometry), (r.kind, r.geometry));
                }
            }
        }
    }

    #[test]
    fn bad_requests_are_errors() {
        let layout = StencilLayout::new(2, 0).unwrap();
        let caps = Native.caps();
        assert_eq!(
            plan_light(
                &layout,
                &caps,
                DepthConvention::Standard,
                &request(LightCase::Outside, &[2], LightTechnique::Stencil)
            ),
            Err(PlanError::SlotOutOfRange { slot: 2, brdfs: 2 })
        );
        assert!(matches!(
            plan_light(
                &layout,
                &caps,
                DepthConvention::Standard,
                &request(LightCase::Outside, &[0, 1], LightTechnique::SingleBrdf)
            ),
            Err(PlanError::SingleWithManyBrdfs { count: 2 })
        ));
        assert!(plan_light(
            &layout,
            &caps,
            DepthConvention::Standard,
            &request(LightCase::Outside, &[], LightTechnique::Stencil)
        )
        .unwrap()
        .is_empty());
    }
}
