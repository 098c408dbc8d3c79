//! Sliding time windows and their domains (paper §"Dynamic Topological Mapping", eq. for
//! W_i and D_i).
//!
//! W_i = [t_{i−1} − Δt/2, t_i + Δt/2], i = 1..N, with t_0 < … < t_N evenly spaced over the
//! mapped span, clipped to it; consecutive windows overlap by Δt. The domain of a window
//! is D_i = ∪_{t ∈ W_i} D(t): with D(t) the full-height band of length l centred on the
//! leader, it is the band from the leftmost to the rightmost leader position in W_i,
//! widened by l/2 on each side.

/// One time window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    /// 1-based index i.
    pub index: usize,
    /// Start of W_i, seconds.
    pub start: f64,
    /// End of W_i, seconds.
    pub end: f64,
}

impl Window {
    /// Whether the closed interval `[a, b]` meets the window.
    pub fn meets(&self, a: f64, b: f64) -> bool {
        a <= self.end && self.start <= b
    }
}

/// The N windows over `[t0, t1]` with overlap `overlap` seconds.
pub fn windows(t0: f64, t1: f64, n: usize, overlap: f64) -> Vec<Window> {
    let step = (t1 - t0) / n as f64;
    (1..=n)
        .map(|i| Window {
            index: i,
            start: (t0 + (i - 1) as f64 * step - overlap / 2.0).max(t0),
            end: (t0 + i as f64 * step + overlap / 2.0).min(t1),
        })
        .collect()
}

/// The x-range `(x_min, x_max)` of D_i for a window, from the leader's track
/// (`(time, x)` samples sorted by time, linearly interpolated) and the window length
/// `l` in metres, clipped to `[0, width]`.
pub fn domain(track: &[(f64, f64)], window: &Window, l: f64, width: f64) -> Option<(f64, f64)> {
    let inside = track
        .iter()
        .filter(|(t, _)| window.meets(*t, *t))
        .map(|&(_, x)| x);
    let ends = [window.start, window.end]
        .into_iter()
        .filter_map(|t| leader_at(track, t));
    let (lo, hi) = inside
        .chain(ends)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
            (lo.min(x), hi.max(x))
        });
    (lo <= hi).then(|| ((lo - l / 2.0).max(0.0), (hi + l / 2.0).min(width)))
}

/// The leader's x at time `t`, interpolated; held at the first/last sample outside the track.
pub fn leader_at(track: &[(f64, f64)], t: f64) -> Option<f64> {
    let (first, last) = (track.first()?, track.last()?);
    if t <= first.0 {
        return Some(first.1);
    }
    if t >= last.0 {
        return Some(last.1);
    }
    let k = track.partition_point(|(s, _)| *s <= t);
    let ((t0, x0), (t1, x1)) = (track[k - 1], track[k]);
    Some(if t1 > t0 {
        x0 + (x1 - x0) * (t - t0) / (t1 - t0)
    } else {
        x1
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_overlap_by_delta_and_cover_the_span() {
        let w = windows(0.0, 400.0, 4, 20.0);
        assert_eq!(w.len(), 4);
        assert_eq!((w[0].start, w[0].end), (0.0, 110.0));
        assert_eq!((w[1].start, w[1].end), (90.0, 210.0));
        assert_eq!((w[3].start, w[3].end), (290.0, 400.0));
        for p in w.windows(2) {
            assert!((p[0].end - p[1].start - 20.0).abs() < 1e-12);
        }
    }

    #[test]
    fn domain_is_the_swept_band() {
        let track = vec![(0.0, 1.5), (100.0, 1.5), (1100.0, 6.5)];
        let w = Window {
            index: 1,
            start: 50.0,
            end: 600.0,
        };
        let (a, b) = domain(&track, &w, 3.0, 30.0).unwrap();
        assert!((a - 0.0).abs() < 1e-12);
        assert!((b - (4.0 + 1.5)).abs() < 1e-12);
        assert_eq!(leader_at(&track, 600.0), Some(4.0));
    }
}
