//! Track alignment under each wheelset.
//!
//! Every wheelset sees the same track, delayed by its distance behind the leading wheelset
//! divided by the speed. [`TrackRecord`] keeps the alignment under the leading wheelset against
//! the travelled distance (the external input, or the generator's values), and the trailing
//! wheelsets read it back at their own positions by linear interpolation. Memory is bounded:
//! samples closer than `max_delay / 4000` are merged, the ring holds 8192 of them.

use serde::{Deserialize, Serialize};

const CAPACITY: usize = 8192;

/// Alignment under the leading wheelset against travelled distance (ring buffer).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrackRecord {
    x: Vec<f64>,
    v: Vec<f64>,
    head: usize,
    len: usize,
    min_spacing_m: f64,
}

impl TrackRecord {
    /// A record able to look back at least `max_delay_m`.
    pub fn new(max_delay_m: f64) -> Self {
        Self {
            x: vec![0.0; CAPACITY],
            v: vec![0.0; CAPACITY],
            head: 0,
            len: 0,
            min_spacing_m: (max_delay_m.abs() / 4000.0).max(1e-9),
        }
    }

    fn idx(&self, k: usize) -> usize {
        (self.head + CAPACITY - self.len + k) % CAPACITY
    }

    /// Records `value` at position `x` (non-decreasing); a sample closer than the minimum
    /// spacing to the one before the newest replaces the newest.
    pub fn push(&mut self, x: f64, value: f64) {
        if self.len >= 2 {
            let last = self.idx(self.len - 1);
            let prev = self.idx(self.len - 2);
            if x - self.x[prev] < self.min_spacing_m {
                self.x[last] = x;
                self.v[last] = value;
                return;
            }
        }
        self.x[self.head] = x;
        self.v[self.head] = value;
        self.head = (self.head + 1) % CAPACITY;
        self.len = (self.len + 1).min(CAPACITY);
    }

    /// Newest sample, if any.
    pub fn last(&self) -> Option<(f64, f64)> {
        (self.len > 0).then(|| {
            let i = self.idx(self.len - 1);
            (self.x[i], self.v[i])
        })
    }

    /// Value at position x: linear interpolation between the recorded samples and the
    /// `pending` sample (x, value) not yet recorded (ahead of all samples). Before the first
    /// sample the first value holds (the track is taken as straight before the start); without
    /// any sample the pending value holds.
    pub fn at(&self, x: f64, pending: (f64, f64)) -> f64 {
        let Some((x_last, v_last)) = self.last() else {
            return pending.1;
        };
        if x >= x_last {
            let dx = pending.0 - x_last;
            if x >= pending.0 || dx <= 0.0 {
                return pending.1;
            }
            return v_last + (x - x_last) / dx * (pending.1 - v_last);
        }
        let first = self.idx(0);
        if x <= self.x[first] {
            return self.v[first];
        }
        let (mut lo, mut hi) = (0usize, self.len - 1);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if self.x[self.idx(mid)] <= x {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let (a, b) = (self.idx(lo), self.idx(hi));
        let dx = self.x[b] - self.x[a];
        if dx <= 0.0 {
            return self.v[b];
        }
        self.v[a] + (x - self.x[a]) / dx * (self.v[b] - self.v[a])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn record_returns_past_values_and_the_pending_one() {
        let mut r = TrackRecord::new(20.0);
        assert_eq!(r.at(5.0, (0.0, 0.3)), 0.3);
        for k in 0..200_000 {
            let x = k as f64 * 1e-3;
            r.push(x, x.sin());
        }
        let x = 199.999 - 17.5;
        assert!((r.at(x, (200.0, 200f64.sin())) - x.sin()).abs() < 1e-5);
        // between the last sample and the pending one
        let v = r.at(199.9995, (200.0, 1.0));
        let l = 199.999f64.sin();
        assert!((v - (l + 0.5 * (1.0 - l))).abs() < 1e-9, "{v}");
        assert_eq!(r.at(1e6, (200.0, 1.0)), 1.0);
    }
}
