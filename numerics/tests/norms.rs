//! The lane norms against the plain sequential ones.

use cdpr_numerics::norms::{max_abs, max_norm};
use proptest::prelude::*;

proptest! {
    /// The four-lane norm is the plain max |r_i| bit for bit, and a NaN or infinity anywhere
    /// is reported at its first index.
    #[test]
    fn max_norm_is_the_plain_max_and_finds_the_first_non_finite(
        r in prop::collection::vec(-1e3f64..1e3, 0..40),
        bad in prop::option::of((0usize..40, prop::bool::ANY)),
    ) {
        let plain = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        prop_assert_eq!(max_norm(&r), Ok(plain));
        if let Some((at, nan)) = bad.filter(|&(at, _)| at < r.len()) {
            let mut r = r.clone();
            r[at] = if nan { f64::NAN } else { f64::NEG_INFINITY };
            let first = r.iter().position(|v| !v.is_finite()).unwrap();
            prop_assert_eq!(max_norm(&r), Err(first));
        }
    }

    /// max |v_i| in lanes is the sequential max bit for bit, NaN entries passed over as by
    /// `f64::max`.
    #[test]
    fn max_abs_is_the_sequential_max(
        v in prop::collection::vec(-1e3f64..1e3, 0..40),
        nan_at in prop::option::of(0usize..40),
    ) {
        let mut v = v;
        if let Some(at) = nan_at.filter(|&at| at < v.len()) {
            v[at] = f64::NAN;
        }
        let plain = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        prop_assert_eq!(max_abs(&v).to_bits(), plain.to_bits());
    }
}
