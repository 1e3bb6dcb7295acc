//! The bound an exact technique's 8-bit image is held to against forward's, derived from the
//! Vulkan specification's precision rules and the case's content rather than measured on one
//! driver. Pure functions; the derivation is below, step by step, and the tests hold each step.
//!
//! # What differs between the two images
//!
//! Per pixel and channel, both images light the same surface point with the same f32 light code
//! (assumption A1 below), so they start from the same non-negative terms: the emission `E` and
//! each light's contribution `c_k`. They differ only in where the sum is rounded:
//!
//! - **Forward** sums `E + c_1 + ... + c_n` in f32 in one invocation and stores it once into the
//!   `R16G16B16A16_SFLOAT` HDR target: one f16 rounding.
//! - **Light-volume techniques** ([`Accumulation::Blended`]: stencil, branching, adaptive,
//!   deferred; adaptive may light a frame tiled, which rounds less) store `E` from the emissive
//!   pass (one rounding), then each light's volume draw adds
//!   `c_k` by additive blending. Blending is done "with a precision and dynamic range no lower
//!   than that used to represent destination components" (spec, *Blending*), so a driver may
//!   convert the source to f16 first and must round the sum to f16: two roundings per light that
//!   touches the pixel, of which the source conversions count once in all (each errs relative to
//!   its own `c_k`, and their sum is at most the pixel's value). A light that does not reach the
//!   surface point adds an exact 0, which no rounding changes.
//! - **Tiled kernels** ([`Accumulation::Summed`]: tiled, depth-id) sum the tile's lights in f32
//!   and store `under + sum` once, `under` being the stored emission: one rounding, plus the
//!   emission's.
//! - **The tint**: the deferred paths read the surface's tint from the G-buffer's
//!   `R16G16B16A16_SFLOAT` albedo target ([`histencil_vk::GBUFFER_FORMATS`]), forward uses it
//!   unrounded: one more relative rounding of every tinted term, so of the lit sum.
//! - **f32 sums**: both sides add in f32 (`OpFAdd` is correctly rounded, the order is free, and a
//!   product may be fused into an add); `4n` f32 roundings of `2^-23` weigh no more than one f16
//!   rounding while `n <= 2048`: one rounding per 2048 lights covers them.
//! - **Alpha entities** lit forward over both frames blend `src + (1 - a) dst` in f16 on each
//!   side, with the same `src` and `a`: two roundings per side per layer.
//!
//! [`PixelPath::roundings`] counts these; call the count `m`. The scene gives the counts, from
//! above: [`lights_at_a_point`] (range spheres over one point, and every directional light),
//! whether a surface emits, and [`alpha_layers`] (alpha entities one view ray can cross).
//!
//! # Step 1: one rounding
//!
//! "Finite values falling between two representable finite values are rounded to one or the
//! other. The rounding mode is not defined" (spec, *Floating-Point Format Conversions*: a
//! fragment output or a storage-image write into an f16 attachment; conversions inside a shader
//! are "correctly rounded", which without `RoundingModeRTE`/`RTZ` is "correctly rounded with
//! implementation-defined rounding mode": either neighbour, *Precision and Operation of SPIR-V
//! Instructions*). A value `x` in f16's normal range (`x >= 2^-14`) lies
//! between neighbours `2^(e-10)` apart with `2^e <= x`, so either neighbour is within a factor
//! `(1 - u, 1 + u)` of it, `u = 2^-10` ([`F16_RELATIVE`]). Below `2^-14` neighbours are `2^-24`
//! apart ([`F16_SUBNORMAL_GAP`]), an absolute error. Beyond 65504 the result may be 65504 or
//! +inf; the tonemap clamps both to 65504, and `min(v, 65504)` shrinks ratios, so nothing below
//! changes.
//!
//! # Step 2: the HDR values' ratio
//!
//! Every term is non-negative (tints, light colours and emission are, `crates/scene`), so a
//! rounding of a partial sum errs relative to at most the pixel's value. By induction over the
//! roundings, with `m_d + m_f = m` of them on the two sides, each value is
//! `P * rho + H` with `P` the exact sum, `(1 - u)^m_side <= rho <= (1 + u)^m_side` and
//! `|H| <= 2 m_side 2^-24 (1 + u)^m_side` (the subnormal parts, at most two roundings of that
//! size per counted one). So `|ln(rho_d / rho_f)| <= m * lambda`, `lambda = -ln(1 - u)`.
//!
//! # Step 3: through the tonemap
//!
//! `tonemap.frag` computes `c = max(v * exposure, 0)`, `t = c / (1 + c)`, `D = srgb(t)` and
//! writes `255 D` to an 8-bit UNORM target. In `ln v`, `dt/d(ln v) = t (1 - t)`, so
//! `dD/d(ln v) = srgb'(t) t (1 - t)`, at most [`TONEMAP_LOG_SLOPE`] (0.18635, at
//! `t = 0.2941` on the power branch; `12.92 t (1 - t)` on the linear branch stays below 0.041).
//! In `v` itself, `dD/dv = exposure * srgb'(t) (1 - t)^2 <= 12.92 exposure`
//! ([`TONEMAP_LINEAR_SLOPE`]). The two images' display values, before quantisation, are then
//! at most `d` apart in 8-bit steps ([`display_difference`]):
//!
//! `d = 255 (m * 0.18635 * lambda + 2m * 12.92 * exposure * 2^-24 * (1 + u)^m) + 2 e_tm`
//!
//! where `e_tm` ([`TONEMAP_ARITHMETIC`]) is the tonemap shader's own error per image, which
//! matters because its inputs differ: the spec's precision table (`OpFDiv` 2.5 ULP, `pow`
//! inherited from `exp2(y * log2(x))` with `log2` 3 ULP or `2^-21` absolute and `exp2`
//! `3 + 2|x|` ULP) leaves it below `2^-9` of a step (the test
//! `the_tonemap_arithmetic_is_below_its_constant` adds it up). One rounding is worth
//! `255 * 0.18635 * lambda = 0.0464` steps.
//!
//! # Step 4: quantisation
//!
//! "`convertFloatToUint(r, b)` returns one of the two unsigned binary integer values with
//! exactly `b` bits which are closest to the floating-point value `r`. Implementations should
//! round to nearest. If `r` is equal to an integer, then that integer value must be returned"
//! (spec, *Conversion From Floating-Point to Normalized Fixed-Point*). With `q(a)` either
//! `floor(a)` or `ceil(a)`, `|q(a) - q(b)|` for `|a - b| <= d` reaches `ceil(d) + 1`
//! (`10.9 -> 10` and `11.05 -> 12`: 0.15 of a step apart, two steps apart) and no more
//! ([`quantised_max`]). Were every driver to round to nearest as the spec recommends, the bound
//! would be one less where `d` is not an integer; it is not a "must", so it is not assumed. The
//! derived max is therefore 2 for every count up to 21 roundings, where 1 held on the drivers
//! measured.
//!
//! # The mean
//!
//! The spec lets every pixel take its worst, so no mean below the max is guaranteed. But with a
//! fixed rounding rule for the UNORM conversion (nearest, or truncation) the quantisation adds
//! nothing on average over pixels whose fractions spread (`E|floor(a + d) - floor(a)| = d`), so
//! the mean is held to `d`, and never below the 1.0 it was.
//!
//! # Assumptions the spec does not give
//!
//! - **A1**: forward and the exact technique compute each light's f32 contribution and the
//!   emission to the same value, up to the one f32 rounding counted. They run the same GLSL on
//!   the same inputs on the same device, but in different shader modules, which the spec lets a
//!   compiler reassociate and approximate differently (`pow` with Blinn-Phong's exponents of
//!   10^4 may differ by far more than an f16 ulp).
//! - **A2**: every tint channel is 0 or at least `2^-14` (normal in f16), so its rounding is
//!   relative. A scene's tints are in `[0, 1e3]`; a smaller non-zero one could err more.
//! - **A3**: on one device the same conversion of the same value gives the same result (alpha
//!   entities' sources and opacities are rounded alike in both frames).

/// The relative error of one f16 rounding in f16's normal range: either neighbour of `x >=
/// 2^-14` is within a factor `(1 - 2^-10, 1 + 2^-10)` of it.
pub const F16_RELATIVE: f64 = 1.0 / 1024.0;

/// The absolute error of one f16 rounding below f16's normal range (`2^-14`): the spacing of
/// f16's subnormals, `2^-24`.
pub const F16_SUBNORMAL_GAP: f64 = 1.0 / 16_777_216.0;

/// The largest slope of the display value in `ln` of the HDR value:
/// `max over t in [0, 1] of srgb'(t) * t * (1 - t)`, with `t = c / (1 + c)` the Reinhard output.
/// On the power branch `srgb'(t) t = (1.055 / 2.4) t^(1/2.4)`, largest with `(1 - t)` at
/// `t = (1/2.4) / (1 + 1/2.4) = 0.2941`: 0.186348, rounded up.
pub const TONEMAP_LOG_SLOPE: f64 = 0.18635;

/// The largest slope of the display value in the HDR value itself, per unit of exposure:
/// `max over t of srgb'(t) * (1 - t)^2`, reached at `t = 0` on the linear branch.
pub const TONEMAP_LINEAR_SLOPE: f64 = 12.92;

/// The tonemap shader's own arithmetic error per image, in 8-bit steps: what the spec's
/// precision table allows its multiply, add, divide and `pow` before the UNORM conversion
/// (`the_tonemap_arithmetic_is_below_its_constant` adds them up).
pub const TONEMAP_ARITHMETIC: f64 = 1.0 / 512.0;

/// Lights per counted f16 rounding for the f32 sums: `4n` f32 roundings of `2^-23` (two sums,
/// each add and each product that may be fused into it) weigh one f16 rounding of `2^-10` while
/// `n <= 2048`.
pub const F32_LIGHTS_PER_ROUNDING: u32 = 2048;

/// How a technique's light reaches the HDR target.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Accumulation {
    /// One additive blend per light volume that reaches the pixel (stencil, branching,
    /// adaptive, deferred).
    Blended,
    /// The lights summed in f32 by one kernel or pass, stored once (tiled, depth-id).
    Summed,
}

/// What one pixel's value goes through in an exact technique and in forward, at most.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PixelPath {
    /// Lights that can reach one surface point (their range holds it), at most.
    pub lights: u32,
    /// Whether an emitting surface can be under the pixel.
    pub emissive: bool,
    /// Alpha entities' layers that can be blended over the pixel in both frames, at most.
    pub alpha_layers: u32,
    pub accumulation: Accumulation,
}

impl PixelPath {
    /// The relative roundings that separate the two images' HDR values, each by less than one
    /// f16 ulp of the value: the forward store (1), the exact technique's stores (per light
    /// blended, or 1 summed), the blend's source conversions (1), the emission's store (1 where
    /// a surface emits), the G-buffer's f16 tint (1), the f32 sums (1 per 2048 lights), and two
    /// per side per alpha layer.
    pub fn roundings(&self) -> u32 {
        let stores = match self.accumulation {
            Accumulation::Blended => self.lights.saturating_add(1),
            Accumulation::Summed => 1,
        };
        let f32_sums = 1 + self.lights / F32_LIGHTS_PER_ROUNDING;
        let (forward, tint) = (1, 1);
        [
            forward,
            stores,
            u32::from(self.emissive),
            tint,
            f32_sums,
            self.alpha_layers.saturating_mul(4),
        ]
        .into_iter()
        .fold(0, u32::saturating_add)
    }
}

/// `lambda = -ln(1 - u)`: the most one rounding moves `ln` of a value.
fn lambda() -> f64 {
    -(-F16_RELATIVE).ln_1p()
}

/// The most two display values can differ, in 8-bit steps before quantisation, when their HDR
/// values are `roundings` roundings apart (steps 2 and 3 of the module's derivation), at
/// [`histencil_vk::gpu_types::EXPOSURE`].
pub fn display_difference(roundings: u32) -> f64 {
    let m = f64::from(roundings);
    let exposure = f64::from(histencil_vk::gpu_types::EXPOSURE);
    let relative = m * TONEMAP_LOG_SLOPE * lambda();
    let growth = (1.0 + F16_RELATIVE).powf(m);
    let absolute = 2.0 * m * TONEMAP_LINEAR_SLOPE * exposure * F16_SUBNORMAL_GAP * growth;
    255.0 * (relative + absolute) + 2.0 * TONEMAP_ARITHMETIC
}

/// The most two UNORM conversions can differ, in 8-bit steps, for values at most `d` steps
/// apart, when each may return either neighbour: `ceil(d) + 1`, at most 255.
pub fn quantised_max(d: f64) -> u8 {
    (d.ceil() + 1.0).min(255.0) as u8
}

/// A bound on the 8-bit error per channel: the largest difference and the mean over every
/// channel of the pixels judged. Exact techniques' bounds are derived per scene and technique
/// ([`crate::matrix::SceneNeeds::exact_tolerance`]); the approximate ones'
/// are `judge`'s constants. Here, beside the derivation, so the matrix and
/// the judge both take it from below them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    pub max: u8,
    pub mean: f64,
}

/// The bound an exact case's image is held to: max `ceil(d) + 1` and mean `d`, for
/// `d = display_difference(roundings)` (the module's derivation), the mean at least 1 and at
/// most 255.
pub fn exact_bound(roundings: u32) -> Tolerance {
    let d = display_difference(roundings);
    Tolerance {
        max: quantised_max(d),
        mean: d.clamp(1.0, 255.0),
    }
}

/// The most of `items` over one point, from above: the largest weight of an item and the items
/// at least as large (`size`) that it `meet`s. Every item over a point meets the smallest of
/// them there, and is no smaller, so this counts them all.
fn most_over_a_point<T>(
    items: &[T],
    size: impl Fn(&T) -> f32,
    weight: impl Fn(&T) -> u32,
    meet: impl Fn(&T, &T) -> bool,
) -> u32 {
    (items.iter())
        .map(|a| {
            (items.iter())
                .filter(|b| size(b) >= size(a) && meet(a, b))
                .map(&weight)
                .fold(0u32, u32::saturating_add)
        })
        .max()
        .unwrap_or(0)
}

/// The most lights whose range can hold one surface point, from above: every directional
/// light, plus, over the local lights' range spheres, the most that one sphere meets among
/// those at least as large, itself included (the spheres over a point all meet the smallest of
/// them there). Spheres meet with slack for the GPU's f32 distances; lights of colour zero add
/// nothing and are left out.
pub fn lights_at_a_point(lights: &[histencil_scene::Light]) -> u32 {
    let lit = |l: &&histencil_scene::Light| l.color.max_element() > 0.0;
    let directional = lights.iter().filter(lit).filter(|l| !l.is_local()).count();
    let local: Vec<_> = lights.iter().filter(lit).filter(|l| l.is_local()).collect();
    let meet = |a: &&histencil_scene::Light, b: &&histencil_scene::Light| {
        let reach = a.radius + b.radius;
        let slack = 1e-3 * reach + 1e-4 * (1.0 + a.position.length() + b.position.length());
        a.position.distance(b.position) <= reach + slack
    };
    let local = most_over_a_point(&local, |l| l.radius, |_| 1, meet);
    u32::try_from(directional)
        .unwrap_or(u32::MAX)
        .saturating_add(local)
}

/// Something an alpha layer is blended from, seen from the eye: the cone of view rays that can
/// meet its bounding sphere, and how many times one ray can cross it.
struct Blob {
    /// Unit direction from the eye to the sphere's centre.
    direction: [f32; 3],
    /// The cone's half-angle, radians (pi with the eye inside the sphere).
    angle: f32,
    layers: u32,
}

impl Blob {
    fn new(eye: [f32; 3], centre: [f32; 3], radius: f32, layers: u32) -> Self {
        let to: Vec<f32> = (0..3).map(|i| centre[i] - eye[i]).collect();
        let distance = to.iter().map(|x| x * x).sum::<f32>().sqrt();
        // With slack for the sprite's f32 corners and the rasteriser's snapping.
        let radius = radius * 1.01 + 1e-4;
        let (direction, angle) = if distance <= radius {
            ([0.0, 0.0, 1.0], std::f32::consts::PI)
        } else {
            (
                [to[0] / distance, to[1] / distance, to[2] / distance],
                (radius / distance).asin(),
            )
        };
        Self {
            direction,
            angle,
            layers,
        }
    }

    fn meets(&self, other: &Blob) -> bool {
        let cos: f32 = (0..3).map(|i| self.direction[i] * other.direction[i]).sum();
        cos.clamp(-1.0, 1.0).acos() <= self.angle + other.angle + 1e-3
    }
}

/// The most alpha layers one pixel can blend, from above: each alpha entity's bounding sphere
/// seen from the camera is a cone of view rays, and one ray lies in at most the cones that the
/// narrowest cone holding it meets among those at least as wide, as with
/// [`lights_at_a_point`]'s spheres. A ray crosses a convex built-in shape twice, an imported
/// mesh at most once per triangle, a particle's sprite once (only its inscribed disc draws:
/// coverage is zero beyond) and a ribbon's segment (two triangles, not always in one plane) at
/// most twice.
pub fn alpha_layers(scene: &histencil_scene::Scene) -> u32 {
    let eye = scene.camera.eye.to_array();
    let mut blobs = Vec::new();
    for object in &scene.alpha_objects {
        let (lo, hi) = object.world_bounds();
        let layers = match object.shape {
            histencil_scene::Shape::Box | histencil_scene::Shape::Sphere => 2,
            histencil_scene::Shape::Mesh(i) => scene.meshes.get(i as usize).map_or(0, |m| {
                u32::try_from(m.indices.len() / 3).unwrap_or(u32::MAX)
            }),
        };
        let centre = ((lo + hi) * 0.5).to_array();
        blobs.push(Blob::new(eye, centre, (hi - lo).length() * 0.5, layers));
    }
    for system in &scene.particle_systems {
        let points = &system.particles;
        if system.layout == histencil_scene::ParticleLayout::Ribbon {
            for pair in points.windows(2) {
                let (a, b) = (pair[0], pair[1]);
                let centre = ((a.position + b.position) * 0.5).to_array();
                let radius = a.position.distance(b.position) * 0.5 + a.size.max(b.size);
                blobs.push(Blob::new(eye, centre, radius, 2));
            }
        } else {
            for p in points {
                blobs.push(Blob::new(eye, p.position.to_array(), p.size, 1));
            }
        }
    }
    most_over_a_point(&blobs, |b| b.angle, |b| b.layers, Blob::meets)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn srgb(t: f64) -> f64 {
        if t <= 0.0031308 {
            12.92 * t
        } else {
            1.055 * t.powf(1.0 / 2.4) - 0.055
        }
    }

    fn srgb_slope(t: f64) -> f64 {
        if t <= 0.0031308 {
            12.92
        } else {
            1.055 / 2.4 * t.powf(1.0 / 2.4 - 1.0)
        }
    }

    /// `tonemap.frag` in f64: the exact display value of HDR value `v`, in 8-bit steps.
    fn display(v: f64) -> f64 {
        let exposure = f64::from(histencil_vk::gpu_types::EXPOSURE);
        let c = (v.min(65504.0) * exposure).max(0.0);
        255.0 * srgb(c / (1.0 + c))
    }

    /// Dense samples of `t` in (0, 1], the two branches' meeting point included.
    fn samples() -> impl Iterator<Item = f64> {
        (1..=1_000_000)
            .map(|i| f64::from(i) / 1e6)
            .chain([0.0031308, 0.0031309])
    }

    #[test]
    fn the_tonemap_slopes_are_the_constants() {
        let log_slope = samples()
            .map(|t| srgb_slope(t) * t * (1.0 - t))
            .fold(0.0, f64::max);
        assert!(log_slope <= TONEMAP_LOG_SLOPE, "{log_slope}");
        assert!(TONEMAP_LOG_SLOPE - log_slope < 1e-5, "{log_slope}");
        let a: f64 = 1.0 / 2.4;
        let at = a / (1.0 + a);
        let closed = 1.055 * a * at.powf(a) * (1.0 - at);
        assert!((closed - log_slope).abs() < 1e-9, "{closed} {log_slope}");
        let linear_slope = samples()
            .map(|t| srgb_slope(t) * (1.0 - t) * (1.0 - t))
            .fold(0.0, f64::max);
        assert!(linear_slope <= TONEMAP_LINEAR_SLOPE, "{linear_slope}");
        assert!(TONEMAP_LINEAR_SLOPE - linear_slope < 1e-3, "{linear_slope}");
        // The linear branch's share of the log slope: small, as the module says.
        let linear_branch = samples()
            .filter(|&t| t <= 0.0031308)
            .map(|t| srgb_slope(t) * t * (1.0 - t))
            .fold(0.0, f64::max);
        assert!(linear_branch < 0.041, "{linear_branch}");
    }

    /// First-order error of `tonemap.frag` at Reinhard output `t`, in 8-bit steps, op by op
    /// from the spec's precision table: each correctly rounded f32 op errs by less than one ulp
    /// (`2^-23` relative at most), `OpFDiv` by 2.5 ulp, `log2` by 3 ulp (or `2^-21` absolute in
    /// `[0.5, 2]`), `exp2(x)` by `3 + 2|x|` ulp.
    fn tonemap_arithmetic_error(t: f64) -> f64 {
        let ulp = 2f64.powi(-23);
        // c = v * exposure, 1 + c, c / (1 + c): the relative error of t.
        let t_relative = (1.0 + 1.0 + 2.5) * ulp;
        let via_t = srgb_slope(t) * t * t_relative;
        let own = if t <= 0.0031308 {
            srgb(t) * ulp
        } else {
            let y = 1.0 / 2.4;
            let log2 = t.log2();
            let log2_error = if t >= 0.5 {
                2f64.powi(-21)
            } else {
                3.0 * ulp * 2f64.powi(log2.abs().log2().floor() as i32)
            };
            // y is a rounded constant; y * log2 is rounded; the argument's error moves exp2's
            // result by ln 2 per unit; exp2 itself errs by 3 + 2|x| ulp of its result.
            let x = y * log2;
            let x_error = y * log2_error + ulp * x.abs() + ulp * y * log2.abs();
            let p = t.powf(y);
            let p_error = p * std::f64::consts::LN_2 * x_error + (3.0 + 2.0 * x.abs()) * ulp * p;
            // 1.055 * p - 0.055: a multiply and a subtract.
            1.055 * p_error + ulp * (1.055 * p) + ulp
        };
        255.0 * (via_t + own)
    }

    #[test]
    fn the_tonemap_arithmetic_is_below_its_constant() {
        let worst = samples().map(tonemap_arithmetic_error).fold(0.0, f64::max);
        assert!(worst < TONEMAP_ARITHMETIC, "{worst}");
        // The branches meet: the exact function has no step there worth counting.
        let step = (srgb(0.0031308) - (1.055 * 0.0031308f64.powf(1.0 / 2.4) - 0.055)).abs();
        assert!(255.0 * step < 1e-4, "{step}");
    }

    /// Brute force over a fine grid: either-neighbour quantisation of values `d` apart differs
    /// by `ceil(d) + 1` at most, and reaches it.
    #[test]
    fn quantisation_adds_one_step_beyond_the_ceiling() {
        for d in [0.0, 0.05, 0.5, 0.95, 1.0, 1.3, 2.0, 2.7] {
            let mut worst = 0i64;
            for i in 0..4000 {
                let a = 10.0 + f64::from(i) / 1000.0;
                let b = a + d;
                let q = |x: f64| [x.floor() as i64, x.ceil() as i64];
                for qa in q(a) {
                    for qb in q(b) {
                        worst = worst.max((qa - qb).abs());
                    }
                }
            }
            assert_eq!(worst, i64::from(quantised_max(d)), "d = {d}");
        }
        assert_eq!(quantised_max(1e9), 255);
    }

    #[test]
    fn the_bound_grows_with_the_roundings_and_is_never_below_one() {
        let bounds: Vec<Tolerance> = (0..=2000).map(exact_bound).collect();
        for pair in bounds.windows(2) {
            assert!(pair[1].max >= pair[0].max && pair[1].mean >= pair[0].mean);
        }
        assert!(bounds.iter().all(|b| b.max >= 1 && b.mean >= 1.0));
        assert_eq!(bounds[1].max, 2);
        assert!(bounds[64].max > bounds[1].max);
        assert_eq!(exact_bound(100_000).max, 255);
        // One rounding is worth 0.046 of a step.
        let one = display_difference(1) - display_difference(0);
        assert!((one - 0.0464).abs() < 1e-3, "{one}");
    }

    #[test]
    fn the_paths_count_what_the_module_lists() {
        let path = |lights, emissive, alpha_layers, accumulation| PixelPath {
            lights,
            emissive,
            alpha_layers,
            accumulation,
        };
        // Forward 1, 8 blends and their sources 1, the tint 1, the f32 sums 1.
        assert_eq!(path(8, false, 0, Accumulation::Blended).roundings(), 12);
        assert_eq!(path(8, true, 0, Accumulation::Blended).roundings(), 13);
        assert_eq!(path(8, true, 0, Accumulation::Summed).roundings(), 5);
        assert_eq!(path(8, false, 2, Accumulation::Summed).roundings(), 12);
        assert_eq!(path(4096, false, 0, Accumulation::Summed).roundings(), 6);
        // The tint the count includes is the G-buffer albedo's f16.
        assert_eq!(
            format!("{:?}", histencil_vk::GBUFFER_FORMATS[0]),
            "R16G16B16A16_SFLOAT"
        );
    }

    /// A small LCG (Knuth's MMIX constants): seeded, no dependency.
    struct Lcg(u64);

    impl Lcg {
        fn next(&mut self) -> u64 {
            self.0 = self
                .0
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            self.0 >> 11
        }

        /// Uniform in [0, 1).
        fn unit(&mut self) -> f64 {
            self.next() as f64 / (1u64 << 53) as f64
        }
    }

    /// Which neighbour an f16 conversion picks: every rule the spec allows, and a driver that
    /// picks at random.
    #[derive(Clone, Copy, Debug, PartialEq)]
    enum Rounding {
        Down,
        Up,
        NearestEven,
        Either,
    }

    const ROUNDINGS: [Rounding; 4] = [
        Rounding::Down,
        Rounding::Up,
        Rounding::NearestEven,
        Rounding::Either,
    ];

    /// `x >= 0` converted to f16 (as the f64 it is), by `rule`; past 65504, 65504 or +inf.
    fn f16(x: f64, rule: Rounding, rng: &mut Lcg) -> f64 {
        assert!(x >= 0.0, "{x}");
        if x == 0.0 || x.is_infinite() {
            return x;
        }
        let exponent = ((x.to_bits() >> 52) & 0x7ff) as i32 - 1023;
        if exponent > 15 {
            // At 65536 or more: past the largest finite f16 by more than half its ulp.
            let finite = match rule {
                Rounding::Down => true,
                Rounding::Up | Rounding::NearestEven => false,
                Rounding::Either => rng.next() & 1 == 1,
            };
            return if finite { 65504.0 } else { f64::INFINITY };
        }
        let ulp = 2f64.powi(exponent.max(-14) - 10);
        let q = x / ulp;
        let low = q.floor();
        let pick_high = if low == q {
            false
        } else {
            match rule {
                Rounding::Down => false,
                Rounding::Up => true,
                Rounding::NearestEven => q - low > 0.5 || (q - low == 0.5 && low % 2.0 == 1.0),
                Rounding::Either => rng.next() & 1 == 1,
            }
        };
        let r = if pick_high { low + 1.0 } else { low } * ulp;
        if r > 65504.0 {
            f64::INFINITY
        } else {
            r
        }
    }

    #[test]
    fn f16_rounding_matches_known_values() {
        let mut rng = Lcg(1);
        let mut near = |x| f16(x, Rounding::NearestEven, &mut rng);
        assert_eq!(near(1.0), 1.0);
        assert_eq!(near(1.0 + 2f64.powi(-11)), 1.0); // a tie, to even
        assert_eq!(near(1.0 + 3.0 * 2f64.powi(-11)), 1.0 + 2f64.powi(-9)); // a tie, to even
        assert_eq!(near(65504.0), 65504.0);
        assert_eq!(near(65519.0), 65504.0);
        assert_eq!(near(65520.0), f64::INFINITY);
        assert_eq!(near(2f64.powi(-25)), 0.0); // half the smallest subnormal, to even
        assert_eq!(near(3.0 * 2f64.powi(-25)), 2f64.powi(-23));
        assert_eq!(near(0.1), 0.0999755859375);
        let mut down = |x| f16(x, Rounding::Down, &mut rng);
        assert_eq!(down(0.1), 0.0999755859375);
        assert_eq!(down(1e6), 65504.0);
        assert_eq!(down(2047.9), 2047.0);
        let mut up = |x| f16(x, Rounding::Up, &mut rng);
        assert_eq!(up(0.1), 0.10003662109375);
        assert_eq!(up(2047.1), 2048.0);
        assert_eq!(up(65504.5), f64::INFINITY);
    }

    /// One pixel channel through both paths, every f16 conversion by the side's rule; returns
    /// the two HDR values (forward's first).
    fn simulate(path: PixelPath, rules: (Rounding, Rounding), rng: &mut Lcg) -> (f64, f64) {
        let (rf, rd) = rules;
        // A magnitude per pixel, light terms spread below it, sometimes none.
        let scale = 2f64.powf(-26.0 + 44.0 * rng.unit());
        let term = |rng: &mut Lcg| {
            if rng.unit() < 0.1 {
                0.0
            } else {
                scale * rng.unit() * rng.unit()
            }
        };
        let emission = (if path.emissive { term(rng) } else { 0.0 }) as f32;
        let tint = 2f64.powf(-14.0 * rng.unit()) as f32;
        let lights: Vec<f32> = (0..path.lights).map(|_| term(rng) as f32).collect();
        let tint16 = f16(f64::from(tint), rd, rng) as f32;
        // Forward: the f32 sum, stored once.
        let sum = lights.iter().fold(emission, |s, &g| s + tint * g);
        let mut forward = f16(f64::from(sum), rf, rng);
        // The exact technique: emission stored, then per light or summed.
        let under = f16(f64::from(emission), rd, rng);
        let mut deferred = match path.accumulation {
            Accumulation::Blended => lights.iter().fold(under, |s, &g| {
                let source = f16(f64::from(tint16 * g), rd, rng);
                f16(s + source, rd, rng)
            }),
            Accumulation::Summed => {
                let lit = lights.iter().fold(0.0f32, |s, &g| s + tint16 * g);
                f16(f64::from(under as f32 + lit), rd, rng)
            }
        };
        // Alpha layers over both: the same premultiplied source and opacity.
        for _ in 0..path.alpha_layers {
            let a = f16(rng.unit(), rf, rng);
            let source = f16(term(rng) * a, rf, rng);
            let keep = 1.0 - a;
            forward = f16(source + f16(forward * keep, rf, rng), rf, rng);
            deferred = f16(source + f16(deferred * keep, rd, rng), rd, rng);
        }
        (forward, deferred)
    }

    /// Largest difference either-neighbour UNORM conversions can make of two display values.
    fn quantised_difference(a: f64, b: f64) -> u8 {
        let (fa, ca, fb, cb) = (a.floor(), a.ceil(), b.floor(), b.ceil());
        (ca - fb).abs().max((cb - fa).abs()) as u8
    }

    /// The bound holds against a driver that rounds every f16 conversion of one image down and
    /// of the other up (or to nearest, or at random), and every UNORM conversion to the worse
    /// neighbour; and the spec's freedom shows: 2 steps apart happens, so 1 was never promised.
    #[test]
    fn adversarial_roundings_stay_within_the_bound() {
        let mut rng = Lcg(0x5eed);
        let mut reached_two = false;
        for lights in 1..=64u32 {
            for accumulation in [Accumulation::Blended, Accumulation::Summed] {
                for alpha_layers in [0, lights % 3] {
                    let path = PixelPath {
                        lights,
                        emissive: lights % 2 == 0,
                        alpha_layers,
                        accumulation,
                    };
                    let bound = exact_bound(path.roundings());
                    for rf in ROUNDINGS {
                        for rd in ROUNDINGS {
                            for _ in 0..24 {
                                let (forward, deferred) = simulate(path, (rf, rd), &mut rng);
                                let difference =
                                    quantised_difference(display(forward), display(deferred));
                                assert!(
                                    difference <= bound.max,
                                    "{path:?} {rf:?}/{rd:?}: {forward} vs {deferred}, \
                                     {difference} steps > {}",
                                    bound.max
                                );
                                reached_two |= difference >= 2;
                            }
                        }
                    }
                }
            }
        }
        assert!(reached_two);
    }

    #[test]
    fn lights_at_a_point_counts_ranges_over_one_point_and_every_directional() {
        use histencil_scene::{Light, LightKind};
        let point = |x: f32, radius| Light::point([x, 0.0, 0.0].into(), radius, [1.0; 3].into());
        let apart = [point(0.0, 1.0), point(5.0, 1.0), point(10.0, 1.0)];
        assert_eq!(lights_at_a_point(&apart), 1);
        // A chain: no point is in all three, but the middle one meets both and is no larger.
        let chain = [point(0.0, 1.0), point(1.5, 1.0), point(3.0, 1.0)];
        assert_eq!(lights_at_a_point(&chain), 3);
        // A huge light over small ones apart: at most two over any point.
        let mut under_huge = apart.to_vec();
        under_huge.push(point(5.0, 100.0));
        assert_eq!(lights_at_a_point(&under_huge), 2);
        let sun = Light {
            kind: LightKind::Directional {
                direction: [0.0, -1.0, 0.0].into(),
            },
            ..point(0.0, 1.0)
        };
        let mut lit = under_huge.clone();
        lit.push(sun);
        assert_eq!(lights_at_a_point(&lit), 3);
        // A dark light adds nothing.
        lit.push(Light::point([5.0, 0.0, 0.0].into(), 1.0, [0.0; 3].into()));
        assert_eq!(lights_at_a_point(&lit), 3);
        assert_eq!(lights_at_a_point(&[]), 0);
    }

    #[test]
    fn alpha_layers_count_what_one_view_ray_can_cross() {
        let mut scene = histencil_scene::embedded("default").unwrap();
        assert_eq!(alpha_layers(&scene), 0);
        let glass = histencil_scene::embedded("alpha").unwrap();
        let layers = alpha_layers(&glass);
        assert!(layers >= 2, "{layers}");
        // Every layer of every entity at most, and more than what one entity adds.
        let everything = 2 * glass.alpha_objects.len()
            + glass
                .particle_systems
                .iter()
                .map(|s| 2 * s.particles.len())
                .sum::<usize>();
        assert!(layers as usize <= everything, "{layers} of {everything}");
        // The camera inside an entity: every ray crosses it.
        scene.alpha_objects = vec![glass.alpha_objects[0].clone()];
        let (lo, hi) = scene.alpha_objects[0].world_bounds();
        scene.camera.eye = (lo + hi) * 0.5;
        assert_eq!(alpha_layers(&scene), 2);
    }
}
