//! Spatial delay line for an external track input: the alignment recorded at the leading
//! wheelset against travelled distance, read back at each following wheelset's distance.

use serde::{Deserialize, Serialize};

/// What [`DelayLine::undo`] needs to take back one push.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DelayUndo {
    head: usize,
    len: usize,
    slot: usize,
    x: f64,
    v: f64,
}

/// Spatial delay line: records the external alignment input at the front wheelset against
/// travelled distance, so the wheelsets behind it (e.g. the bogie's rear wheelset, 2p behind)
/// see the same track. Samples are stored every `spacing` metres at most (bounded memory for
/// any speed/step): 2048 samples over the delay it was made for.
/// A deserialised line (a saved FMU state, say) is checked for the ring's invariants, so that
/// no push or read can index out of it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "DelayRing")]
pub struct DelayLine {
    x: Vec<f64>,
    v: Vec<f64>,
    head: usize,
    len: usize,
    spacing: f64,
}

/// The serialised form of [`DelayLine`] before its checks.
#[derive(Deserialize)]
struct DelayRing {
    x: Vec<f64>,
    v: Vec<f64>,
    head: usize,
    len: usize,
    spacing: f64,
}

impl TryFrom<DelayRing> for DelayLine {
    type Error = String;
    fn try_from(r: DelayRing) -> Result<Self, String> {
        let cap = r.x.len();
        if cap < 2 || r.v.len() != cap || r.head >= cap || r.len > cap {
            return Err(format!(
                "delay line: {} positions, {} values, head {}, length {}: not a ring of at \
                 least 2 samples",
                cap,
                r.v.len(),
                r.head,
                r.len
            ));
        }
        if !(r.spacing.is_finite() && r.spacing > 0.0) {
            return Err(format!("delay line: spacing {} m", r.spacing));
        }
        Ok(DelayLine {
            x: r.x,
            v: r.v,
            head: r.head,
            len: r.len,
            spacing: r.spacing,
        })
    }
}

impl DelayLine {
    /// Line able to look back `delay_m` metres (the distance of the last wheelset behind the
    /// first).
    pub fn new(delay_m: f64) -> Self {
        let cap = 4096;
        Self {
            x: vec![0.0; cap],
            v: vec![0.0; cap],
            head: 0,
            len: 0,
            spacing: (delay_m.abs() / (cap as f64 / 2.0)).max(1e-9),
        }
    }

    /// As [`Self::push`], returning what [`Self::undo`] needs to take it back (so a failed
    /// step leaves the line unchanged).
    pub fn push_undoable(&mut self, x: f64, value: f64) -> DelayUndo {
        let cap = self.x.len();
        let slot = if self.len >= 2 && x - self.x[(self.head + cap - 2) % cap] < self.spacing {
            (self.head + cap - 1) % cap
        } else {
            self.head
        };
        let u = DelayUndo {
            head: self.head,
            len: self.len,
            slot,
            x: self.x[slot],
            v: self.v[slot],
        };
        self.push(x, value);
        u
    }

    /// Takes back the push that returned `u` (must be the last change).
    pub fn undo(&mut self, u: DelayUndo) {
        self.head = u.head;
        self.len = u.len;
        self.x[u.slot] = u.x;
        self.v[u.slot] = u.v;
    }

    /// Records the value at position x (x non-decreasing).
    pub fn push(&mut self, x: f64, value: f64) {
        let cap = self.x.len();
        if self.len >= 2 {
            let last = (self.head + cap - 1) % cap;
            let prev = (self.head + cap - 2) % cap;
            if x - self.x[prev] < self.spacing {
                // closer than `spacing` to the sample before: replace the newest one
                self.x[last] = x;
                self.v[last] = value;
                return;
            }
        }
        self.x[self.head] = x;
        self.v[self.head] = value;
        self.head = (self.head + 1) % cap;
        self.len = (self.len + 1).min(cap);
    }

    /// Value at position x (linear interpolation); before the first sample, the first value
    /// (the track is taken as straight before the start); `None` if nothing was recorded.
    pub fn at(&self, x: f64) -> Option<f64> {
        if self.len == 0 {
            return None;
        }
        let cap = self.x.len();
        let idx = |k: usize| (self.head + cap - self.len + k) % cap; // k = 0 oldest
        let first = idx(0);
        if x <= self.x[first] {
            return Some(self.v[first]);
        }
        let last = idx(self.len - 1);
        if x >= self.x[last] {
            return Some(self.v[last]);
        }
        // binary search over the logical order
        let (mut lo, mut hi) = (0usize, self.len - 1);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if self.x[idx(mid)] <= x {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let (a, b) = (idx(lo), idx(hi));
        let dx = self.x[b] - self.x[a];
        if dx <= 0.0 {
            return Some(self.v[b]);
        }
        let t = (x - self.x[a]) / dx;
        Some(self.v[a] + t * (self.v[b] - self.v[a]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_deserialised_line_must_be_a_ring() {
        let mut d = DelayLine::new(2.5);
        d.push(0.0, 1.0);
        let good = serde_json::to_value(&d).unwrap();
        let back: DelayLine = serde_json::from_value(good.clone()).unwrap();
        assert_eq!(back, d);
        for (field, value) in [
            ("head", serde_json::json!(4096)),
            ("len", serde_json::json!(5000)),
            ("x", serde_json::json!([0.0])),
            ("v", serde_json::json!([0.0, 1.0])),
            ("spacing", serde_json::json!(0.0)),
        ] {
            let mut bad = good.clone();
            bad[field] = value;
            let e = serde_json::from_value::<DelayLine>(bad).unwrap_err();
            assert!(e.to_string().contains("delay line"), "{field}: {e}");
        }
    }

    #[test]
    fn delay_line_returns_past_values() {
        let mut d = DelayLine::new(2.5);
        assert!(d.at(0.0).is_none());
        for k in 0..100_000 {
            let x = k as f64 * 1e-3;
            d.push(x, x.sin());
        }
        let x = 99.999 - 2.5;
        let v = d.at(x).unwrap();
        assert!((v - x.sin()).abs() < 1e-5, "{v} {}", x.sin());
    }
}
