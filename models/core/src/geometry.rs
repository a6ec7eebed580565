//! Plane geometry the cable models share for their starting shapes.

use nalgebra::Vector2;

/// N equal chords of length `chord` from `a` to `b` (N + 1 points): a straight line with equal
/// spacing if N·chord ≤ |ab|, else a circular-arc polygon sagging below ab, its angle per chord θ
/// found by bisection on sin(Nθ/2)/sin(θ/2) = |ab|/chord. A cable started on it has every segment
/// at the same length, so none is slack when chord exceeds the unstrained length.
pub fn sagging_polygon(
    a: Vector2<f64>,
    b: Vector2<f64>,
    n: usize,
    chord: f64,
) -> Vec<Vector2<f64>> {
    let count = n as f64;
    let span = (b - a).norm();
    if span >= count * chord {
        return (0..=n).map(|k| a + (b - a) * (k as f64 / count)).collect();
    }
    let along = (b - a) / span;
    let ratio = span / chord;
    let (mut lo, mut hi) = (0.0, 2.0 * std::f64::consts::PI / count);
    for _ in 0..200 {
        let theta = 0.5 * (lo + hi);
        if (count * theta / 2.0).sin() / (theta / 2.0).sin() > ratio {
            lo = theta;
        } else {
            hi = theta;
        }
    }
    let theta = 0.5 * (lo + hi);
    let radius = chord / (2.0 * (theta / 2.0).sin());
    // Unit normal pointing down (the sag side).
    let mut down = Vector2::new(-along.y, along.x);
    if down.y > 0.0 {
        down = -down;
    }
    let centre = (a + b) * 0.5 - down * (radius * (count * theta / 2.0).cos());
    (0..=n)
        .map(|k| {
            let angle = -count * theta / 2.0 + k as f64 * theta;
            centre + (along * angle.sin() + down * angle.cos()) * radius
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polygon_has_equal_chords_and_ends() {
        let (a, b) = (Vector2::new(0.0, 0.0), Vector2::new(1.0, -0.2));
        for (n, chord) in [(10, 0.12), (7, 0.2), (4, 0.2)] {
            let p = sagging_polygon(a, b, n, chord);
            assert_eq!(p.len(), n + 1);
            assert!((p[0] - a).norm() < 1e-12 && (p[n] - b).norm() < 1e-12);
            let straight = (b - a).norm() >= n as f64 * chord;
            for w in p.windows(2) {
                let len = (w[1] - w[0]).norm();
                // Bisection to 200 halvings: chords equal to round-off; a straight line spaces
                // its points at |ab|/N instead.
                let want = if straight {
                    (b - a).norm() / n as f64
                } else {
                    chord
                };
                assert!((len - want).abs() < 1e-12, "{len} vs {want}");
            }
        }
    }
}
