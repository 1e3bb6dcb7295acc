//! IEEE binary16, the format of histencil's HDR and material targets, in the two conversions
//! histencil needs: rounding a value as a GPU stores it, and reading a stored value back. Written
//! here rather than taken from a crate so that an engine's build does not compile one for two
//! functions (the `half` crate brings `zerocopy` and a second `syn`); the tests hold both to
//! `half` bit for bit, every binary16 and the rounding's edges.

/// `x` rounded to the nearest binary16, ties to even, as an f64: what storing `x` in an f16
/// target keeps. Past the largest finite binary16 (65504) by half a step or more it is an
/// infinity of `x`'s sign; NaN stays NaN.
pub fn round_to_f16(x: f64) -> f64 {
    if x.is_nan() || x.is_infinite() {
        return x;
    }
    let a = x.abs();
    // 65520 lies halfway between 65504 and 2^16, and ties go to the even 2^16: infinity.
    if a >= 65520.0 {
        return f64::INFINITY.copysign(x);
    }
    // The spacing of binary16 values at `a`: 2^-24 below 2^-14 (subnormals), else 2^(e - 10).
    let exponent = ((a.to_bits() >> 52) & 0x7ff) as i64 - 1023;
    let step_exponent = exponent.max(-14) - 10;
    let step = f64::from_bits(((step_exponent + 1023) as u64) << 52);
    // Division and multiplication by a power of two are exact, so only the rounding rounds.
    ((a / step).round_ties_even() * step).copysign(x)
}

/// The value of the binary16 with bits `bits`, exactly (every binary16 is an f32).
pub fn f16_bits_to_f32(bits: u16) -> f32 {
    let sign = if bits & 0x8000 != 0 { -1.0f32 } else { 1.0 };
    let exponent = i32::from((bits >> 10) & 0x1f);
    let mantissa = f32::from(bits & 0x3ff);
    let magnitude = match exponent {
        0 => mantissa * 2f32.powi(-24),
        31 if mantissa == 0.0 => f32::INFINITY,
        31 => f32::NAN,
        e => (1024.0 + mantissa) * 2f32.powi(e - 25),
    };
    sign * magnitude
}

#[cfg(test)]
mod tests {
    use super::*;
    use half::f16;

    #[test]
    fn every_binary16_reads_back_as_half_reads_it() {
        for bits in 0..=u16::MAX {
            let ours = f16_bits_to_f32(bits);
            let theirs = f16::from_bits(bits).to_f32();
            if theirs.is_nan() {
                assert!(ours.is_nan(), "{bits:#06x}");
            } else {
                assert_eq!(ours.to_bits(), theirs.to_bits(), "{bits:#06x}");
            }
        }
    }

    /// Every finite binary16, the midpoints between neighbours (the ties), the next f32 either
    /// side of them, the overflow edge, and random f32s of every exponent: against `half`'s
    /// f32 conversion, which rounds on all of an f32's bits. (Its f64 conversion reads only an
    /// f64's upper 32 bits, so it rounds 2^-25 + 2^-60 down to 0, where the nearest binary16 is
    /// 2^-24; every value a GPU stores is an f32.)
    #[test]
    fn rounding_is_round_to_nearest_even() {
        let mut values = vec![0.0f32, 65519.99, 65520.0, 1e30, 1e-30, f32::MIN_POSITIVE];
        let finite: Vec<f32> = (0..0x7c00u16).map(|b| f16::from_bits(b).to_f32()).collect();
        for pair in finite.windows(2) {
            let mid = 0.5 * (pair[0] + pair[1]);
            values.extend([pair[0], mid, mid.next_up(), mid.next_down()]);
        }
        let mut state = 0x9e37_79b9u32;
        for _ in 0..400_000 {
            state ^= state << 13;
            state ^= state >> 17;
            state ^= state << 5;
            let x = f32::from_bits(state);
            if x.is_finite() {
                values.push(x);
            }
        }
        for x in values.iter().flat_map(|&x| [x, -x]) {
            let ours = round_to_f16(f64::from(x));
            let theirs = f16::from_f32(x).to_f64();
            assert_eq!(
                ours.to_bits(),
                theirs.to_bits(),
                "{x:e}: {ours:e} against {theirs:e}"
            );
        }
        let above_tie = 2f64.powi(-25) + 2f64.powi(-60);
        assert_eq!(round_to_f16(above_tie), 2f64.powi(-24));
        assert_eq!(round_to_f16(2f64.powi(-25)), 0.0);
        assert!(round_to_f16(f64::NAN).is_nan());
    }
}
