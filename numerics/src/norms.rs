//! Maximum norms in four independent lanes: the implicit path takes them at every Newton
//! iteration and step, and a sequential max is one chain of dependent instructions. A max is
//! exact, so the lanes change no bit.

/// max |v_i| (0 for an empty slice; NaN entries are passed over, as by `f64::max`). Four
/// independent lanes: the implicit path asks for its positions' scale at every step, and a
/// sequential max is one chain of dependent instructions (the FE paper run's round-off bound
/// cost 1.4 % of it). A max is exact, so the lanes change no bit.
pub fn max_abs(v: &[f64]) -> f64 {
    let mut largest = [0.0f64; 4];
    let chunks = v.chunks_exact(4);
    let tail = chunks.remainder();
    for chunk in chunks {
        for (m, &x) in largest.iter_mut().zip(chunk) {
            let a = x.abs();
            *m = if a > *m { a } else { *m };
        }
    }
    let head = tail.iter().fold(largest[0], |m, x| m.max(x.abs()));
    largest[1..].iter().fold(head, |m, &x| m.max(x))
}
/// max |r_i|, or the index of the first non-finite r_i. Four independent lanes (this runs at
/// every Newton iteration, and a sequential max is one chain of dependent instructions); a max is
/// exact, so the lanes change no bit of the norm. Non-finite entries are caught by a lane sum of
/// r_i · 0, which is NaN exactly when some r_i is NaN or infinite.
pub fn max_norm(r: &[f64]) -> Result<f64, usize> {
    let (mut largest, mut poison) = ([0.0f64; 4], [0.0f64; 4]);
    let chunks = r.chunks_exact(4);
    let tail = chunks.remainder();
    for chunk in chunks {
        for ((m, p), &v) in largest.iter_mut().zip(&mut poison).zip(chunk) {
            let a = v.abs();
            *m = if a > *m { a } else { *m };
            *p += v * 0.0;
        }
    }
    for &v in tail {
        largest[0] = largest[0].max(v.abs());
        poison[0] += v * 0.0;
    }
    if poison.iter().sum::<f64>().is_finite() {
        Ok(largest.into_iter().fold(0.0, f64::max))
    } else {
        Err(r.iter().position(|v| !v.is_finite()).unwrap_or(0))
    }
}
