//! Order statistics of per-frame timings: medians, quantiles, and the spread of a difference
//! between two configurations over the same frames.

use serde::{Deserialize, Serialize};

/// Median and minimum of a sample (sorts it in place; NaN sorts last).
pub fn median_min(v: &mut [f64]) -> (f64, f64) {
    v.sort_by(|a, b| a.total_cmp(b));
    (quantile_sorted(v, 0.5), v.first().copied().unwrap_or(f64::NAN))
}

/// The `q`-quantile (0 ≤ q ≤ 1) of sorted values by linear interpolation between the closest
/// ranks (R's type 7: the median of an even count is the mean of the middle two). NaN when
/// `sorted` is empty.
pub fn quantile_sorted(sorted: &[f64], q: f64) -> f64 {
    match sorted.len() {
        0 => f64::NAN,
        1 => sorted[0],
        n => {
            let h = (n - 1) as f64 * q.clamp(0.0, 1.0);
            let (lo, frac) = (h.floor() as usize, h - h.floor());
            let hi = (lo + 1).min(n - 1);
            sorted[lo] + frac * (sorted[hi] - sorted[lo])
        }
    }
}

/// How a per-frame difference (k layers − 1 layer, in ms) is distributed over the timed frames.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spread {
    pub median_ms: f64,
    /// First and third quartiles: the middle half of the per-frame differences.
    pub q1_ms: f64,
    pub q3_ms: f64,
    pub min_ms: f64,
    pub max_ms: f64,
    /// Frames the differences were taken over.
    pub frames: usize,
}

impl Spread {
    /// The spread of `with[i] − without[i]` over the frames both measured (frame i of one run
    /// against frame i of the other: the same camera). `None` without any pair.
    pub fn of_differences(with: &[f64], without: &[f64]) -> Option<Spread> {
        let mut d: Vec<f64> = with.iter().zip(without).map(|(a, b)| a - b).collect();
        if d.is_empty() {
            return None;
        }
        d.sort_by(|a, b| a.total_cmp(b));
        Some(Spread {
            median_ms: quantile_sorted(&d, 0.5),
            q1_ms: quantile_sorted(&d, 0.25),
            q3_ms: quantile_sorted(&d, 0.75),
            min_ms: d[0],
            max_ms: d[d.len() - 1],
            frames: d.len(),
        })
    }

    /// Whether the interquartile range includes zero: the sign of the difference is not
    /// established by these frames (it is within the frame-to-frame noise).
    pub fn includes_zero(&self) -> bool {
        self.q1_ms <= 0.0 && self.q3_ms >= 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_and_min_of_odd_and_even_counts() {
        assert_eq!(median_min(&mut [3.0, 1.0, 2.0]), (2.0, 1.0));
        assert_eq!(median_min(&mut [4.0, 1.0, 3.0, 2.0]), (2.5, 1.0));
        let (m, min) = median_min(&mut []);
        assert!(m.is_nan() && min.is_nan());
    }

    #[test]
    fn quantiles_interpolate_between_ranks() {
        let v = [1.0, 2.0, 3.0, 4.0, 5.0];
        assert_eq!(quantile_sorted(&v, 0.25), 2.0);
        assert_eq!(quantile_sorted(&v, 0.75), 4.0);
        assert_eq!(quantile_sorted(&[1.0, 2.0], 0.25), 1.25);
        assert_eq!(quantile_sorted(&[7.0], 0.9), 7.0);
    }

    #[test]
    fn increment_spread_of_known_frames() {
        // per-frame differences: 0.2, -0.5, 0.1, 0.4, -0.3 → sorted -0.5, -0.3, 0.1, 0.2, 0.4
        let k2 = [1.2, 0.5, 1.1, 1.4, 0.7];
        let k1 = [1.0, 1.0, 1.0, 1.0, 1.0];
        let s = Spread::of_differences(&k2, &k1).unwrap();
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        assert!(close(s.median_ms, 0.1), "{s:?}");
        assert!(close(s.q1_ms, -0.3) && close(s.q3_ms, 0.2), "{s:?}");
        assert!(close(s.min_ms, -0.5) && close(s.max_ms, 0.4), "{s:?}");
        assert_eq!(s.frames, 5);
        assert!(s.includes_zero());
    }

    #[test]
    fn a_consistent_increment_is_not_within_noise() {
        let k2 = [1.5, 1.6, 1.4, 1.55];
        let k1 = [1.0, 1.1, 1.0, 1.0];
        let s = Spread::of_differences(&k2, &k1).unwrap();
        // differences 0.5, 0.5, 0.4, 0.55 → sorted 0.4, 0.5, 0.5, 0.55
        assert!((s.median_ms - 0.5).abs() < 1e-12);
        assert!(
            (s.q1_ms - 0.475).abs() < 1e-12 && (s.q3_ms - 0.5125).abs() < 1e-12,
            "{s:?}"
        );
        assert!(!s.includes_zero());
        // consistently negative: also established (not within noise)
        let s = Spread::of_differences(&k1, &k2).unwrap();
        assert!(s.median_ms < 0.0 && !s.includes_zero());
        assert!(Spread::of_differences(&[], &[]).is_none());
    }
}
