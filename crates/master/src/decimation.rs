//! Decimation of recorded results without aliasing, and the sampling record a results file
//! carries so that a reader knows which band its signals cover.
//!
//! Keeping every `m`-th sample of a signal folds everything above the new Nyquist frequency
//! `fs / (2 m)` back into the band below it: the wheelset and frame accelerations of a
//! hunting bogie in flange contact carry energy far above 50 Hz, so a 1 kHz record reduced to
//! 100 Hz by picking samples has a wrong spectrum in the band EN 14363 assesses. [`decimate`]
//! therefore low-passes every Real column first: a Butterworth low-pass of order
//! [`ANTI_ALIAS_ORDER`] run forward and backward (zero phase, gain `|H|^2`, roll-off of an
//! order-8 filter) with its cut-off at [`ANTI_ALIAS_CUTOFF`] of the new sampling rate; what
//! would fold back into the lower 40 % of the new band is then attenuated by more than
//! 40 dB. Integer, Boolean, Enumeration and String columns are picked (a filtered state is no
//! state), as is the time column.

use signal_processing::LowPass;

use crate::coupling::SimOutput;
use crate::slave::ScalarType;

/// Prototype order of the anti-aliasing low-pass (per pass; forward and backward doubles the
/// roll-off).
pub const ANTI_ALIAS_ORDER: usize = 4;
/// Cut-off of the anti-aliasing low-pass as a fraction of the new sampling rate.
pub const ANTI_ALIAS_CUTOFF: f64 = 0.4;
/// Largest amplitude error a stored signal may have inside its recorded pass band (1 %):
/// [`Sampling::passband_hz`] is where the anti-aliasing filter's gain falls to 0.99.
pub const PASSBAND_GAIN: f64 = 0.99;

/// How a decimated results file was made from the record at every communication point.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Decimation {
    /// Every `factor`-th row of the full-rate record is kept.
    pub factor: usize,
    /// Sampling rate of the full-rate record \[Hz\].
    pub source_rate_hz: f64,
    /// The anti-aliasing filter applied to every Real column before the rows were picked.
    pub filter: String,
    /// Its prototype order (per pass).
    pub filter_order: usize,
    /// Its -3 dB cut-off (per pass) \[Hz\].
    pub cutoff_hz: f64,
}

/// The sampling of the stored rows, written into every results file's metadata.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Sampling {
    /// Rate of the stored rows \[Hz\].
    pub rate_hz: f64,
    /// Highest frequency the stored Real signals carry with less than 1 % amplitude error
    /// and free of aliases \[Hz\]: the Nyquist frequency of a full-rate record, the frequency
    /// where the anti-aliasing filter's gain falls to [`PASSBAND_GAIN`] in a decimated one.
    pub passband_hz: f64,
    /// How the rows were decimated; `None`: every communication point is stored.
    pub decimation: Option<Decimation>,
}

/// Why results cannot be decimated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DecimationError {
    #[error("cannot decimate: the time column is not uniformly increasing ({0})")]
    Time(String),
    #[error("cannot design the anti-aliasing filter: {0}")]
    Filter(#[from] signal_processing::DesignError),
}

/// Mean sampling rate of the recorded rows from the time column \[Hz\]; `None` with fewer than
/// two rows or a time column that does not increase.
pub fn sample_rate_hz(out: &SimOutput) -> Option<f64> {
    let w = out.header.len().max(1);
    let n = out.data.len() / w;
    if n < 2 {
        return None;
    }
    let dt = (out.data[(n - 1) * w] - out.data[0]) / (n - 1) as f64;
    (dt.is_finite() && dt > 0.0).then_some(1.0 / dt)
}

/// Frequency where the forward-backward Butterworth of order `order` and cut-off `cutoff_hz`
/// has the gain `PASSBAND_GAIN`: `1 / (1 + q^(2n)) = g` at `q = f / f_c` (analogue formula;
/// the bilinear transform makes the digital pass band slightly wider, so this is safe).
fn filter_passband_hz(order: usize, cutoff_hz: f64) -> f64 {
    let q = ((1.0 - PASSBAND_GAIN) / PASSBAND_GAIN).powf(1.0 / (2 * order) as f64);
    q * cutoff_hz
}

impl Sampling {
    /// Every communication point stored: the signals carry everything up to the Nyquist
    /// frequency.
    pub fn full_rate(rate_hz: f64) -> Self {
        Sampling {
            rate_hz,
            passband_hz: 0.5 * rate_hz,
            decimation: None,
        }
    }
}

impl SimOutput {
    /// The sampling of the rows as stored; `None` with fewer than two rows.
    pub fn sampling(&self) -> Option<Sampling> {
        let rate_hz = sample_rate_hz(self)?;
        Some(match &self.decimation {
            Some(d) => Sampling {
                rate_hz,
                passband_hz: filter_passband_hz(d.filter_order, d.cutoff_hz).min(0.5 * rate_hz),
                decimation: Some(d.clone()),
            },
            None => Sampling::full_rate(rate_hz),
        })
    }
}

/// The factor that takes `out` closest to `rate_hz` (at least 1).
pub fn factor_for_rate(out: &SimOutput, rate_hz: f64) -> usize {
    sample_rate_hz(out).map_or(1, |fs| (fs / rate_hz).round().max(1.0) as usize)
}

/// `out` with every `factor`-th row (the first always) of its anti-alias filtered Real
/// columns and of its other columns as recorded; a factor of 0 or 1, or fewer than two rows,
/// gives `out` unchanged. The result records the decimation ([`SimOutput::decimation`]).
pub fn decimate(out: &SimOutput, factor: usize) -> Result<SimOutput, DecimationError> {
    let w = out.header.len().max(1);
    let n = out.data.len() / w;
    let Some(fs) = sample_rate_hz(out).filter(|_| factor > 1) else {
        return Ok(out.clone());
    };
    let t = &out.data;
    if let Some(k) = (1..n).find(|&k| t[k * w] <= t[(k - 1) * w]) {
        return Err(DecimationError::Time(format!(
            "t = {} s follows t = {} s",
            t[k * w],
            t[(k - 1) * w]
        )));
    }
    let source_rate_hz = match &out.decimation {
        Some(d) => d.source_rate_hz,
        None => fs,
    };
    let cutoff_hz = ANTI_ALIAS_CUTOFF * fs / factor as f64;
    let lp = LowPass::butterworth(ANTI_ALIAS_ORDER, cutoff_hz, 1.0 / fs)?;
    // the filter's response has died out after about ten periods of its cut-off
    let pad = ((10.0 * fs / cutoff_hz).ceil() as usize).min(n - 1);
    let kept: Vec<usize> = (0..n).step_by(factor).collect();
    let mut data = vec![0.0; kept.len() * w];
    for c in 0..w {
        let picked: Vec<f64> = if c > 0 && out.column_info(c).scalar_type() == ScalarType::Real {
            let x: Vec<f64> = (0..n).map(|k| t[k * w + c]).collect();
            let y = lp.filtfilt(&x, pad);
            kept.iter().map(|&k| y[k]).collect()
        } else {
            kept.iter().map(|&k| t[k * w + c]).collect()
        };
        for (r, v) in picked.into_iter().enumerate() {
            data[r * w + c] = v;
        }
    }
    let total_factor = out.decimation.as_ref().map_or(1, |d| d.factor) * factor;
    Ok(SimOutput {
        header: out.header.clone(),
        data,
        summary: out.summary.clone(),
        columns: out.columns.clone(),
        strings: out.strings.clone(),
        decimation: Some(Decimation {
            factor: total_factor,
            source_rate_hz,
            filter: format!(
                "Butterworth low-pass of order {ANTI_ALIAS_ORDER}, cut-off {cutoff_hz} Hz \
                 ({ANTI_ALIAS_CUTOFF} x the stored rate), run forward and backward (zero \
                 phase, gain |H|^2) over every Real column before every {factor}-th row was \
                 kept"
            ),
            filter_order: ANTI_ALIAS_ORDER,
            cutoff_hz,
        }),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coupling::{ColumnInfo, Summary};
    use std::f64::consts::PI;

    /// `time`, one Real and one Integer column sampled at `fs` for `secs`.
    fn record(fs: f64, secs: f64, real: impl Fn(f64) -> f64) -> SimOutput {
        let n = (secs * fs) as usize + 1;
        let mut data = Vec::with_capacity(3 * n);
        for k in 0..n {
            let t = k as f64 / fs;
            data.extend([t, real(t), (k % 7) as f64]);
        }
        SimOutput {
            header: vec!["time [s]".into(), "a.x [m/s2]".into(), "a.n".into()],
            data,
            summary: Summary {
                steps: n as u64,
                rejected_steps: 0,
                simulated_time_s: secs,
                wall_time_s: 0.0,
                realtime_ratio: 0.0,
                terminated: None,
                failed: None,
            },
            columns: vec![
                ColumnInfo::default(),
                ColumnInfo {
                    ty: Some(ScalarType::Integer),
                    ..Default::default()
                },
            ],
            strings: vec![],
            decimation: None,
        }
    }

    #[test]
    fn real_columns_are_filtered_others_picked_and_the_decimation_recorded() {
        let out = record(1000.0, 2.0, |t| (2.0 * PI * 3.0 * t).sin());
        let d = decimate(&out, 10).unwrap();
        assert_eq!(d.rows().count(), 201);
        let s = d.sampling().unwrap();
        assert!((s.rate_hz - 100.0).abs() < 1e-9, "{s:?}");
        let dec = s.decimation.clone().unwrap();
        assert_eq!((dec.factor, dec.filter_order), (10, 4));
        assert!((dec.source_rate_hz - 1000.0).abs() < 1e-9 && (dec.cutoff_hz - 40.0).abs() < 1e-9);
        // |H|^2 = 0.99 at 40 Hz x (1/99)^(1/8) = 22.5 Hz
        assert!((s.passband_hz - 22.49).abs() < 0.05, "{s:?}");
        for (r, row) in d.rows().enumerate() {
            assert_eq!(row[0], out.rows().nth(10 * r).unwrap()[0]);
            assert_eq!(row[2], ((10 * r) % 7) as f64);
            // 3 Hz passes unchanged, in phase
            assert!(
                (row[1] - (2.0 * PI * 3.0 * row[0]).sin()).abs() < 1e-3,
                "{row:?}"
            );
        }
        // decimating again keeps the full-rate origin and multiplies the factors
        let dd = decimate(&d, 2).unwrap();
        let dec = dd.decimation.clone().unwrap();
        assert_eq!(dec.factor, 20);
        assert!((dec.source_rate_hz - 1000.0).abs() < 1e-9);
        // factor 1 and a single row: unchanged
        assert_eq!(decimate(&out, 1).unwrap(), out);
        assert_eq!(out.sampling().unwrap().passband_hz, 500.0);
    }

    /// Amplitude of the `f_hz` component of `x` sampled at `fs` (projection on a sine and a
    /// cosine over a whole number of periods).
    fn amplitude(x: &[f64], fs: f64, f_hz: f64) -> f64 {
        let n = x.len() as f64;
        let (c, s) = x.iter().enumerate().fold((0.0, 0.0), |(c, s), (k, v)| {
            let w = 2.0 * PI * f_hz * k as f64 / fs;
            (c + v * w.cos(), s + v * w.sin())
        });
        2.0 * (c * c + s * s).sqrt() / n
    }

    #[test]
    fn content_above_the_new_nyquist_frequency_leaves_no_alias_in_the_band() {
        // 1 kHz record: hunting-like 4 Hz of amplitude 1 and flange-contact-like 93 Hz of
        // amplitude 3; stored at 100 Hz, 93 Hz folds onto 100 - 93 = 7 Hz, inside the band
        // EN 14363 assesses (dominant frequency searched in 0.5-20 Hz, +-2 Hz around it)
        let out = record(1000.0, 20.0, |t| {
            (2.0 * PI * 4.0 * t).sin() + 3.0 * (2.0 * PI * 93.0 * t).sin()
        });
        let stored = |d: &SimOutput| -> Vec<f64> {
            // the middle 18 s (a whole number of periods of 4 and 7 Hz)
            d.rows().skip(100).take(1800).map(|r| r[1]).collect()
        };
        let filtered = stored(&decimate(&out, 10).unwrap());
        let w = out.header.len();
        let picked_rows = SimOutput {
            data: out
                .data
                .chunks(w)
                .step_by(10)
                .flat_map(|r| r.iter().copied())
                .collect(),
            ..out.clone()
        };
        let picked = stored(&picked_rows);
        // plain picking: the full 93 Hz amplitude reappears at 7 Hz
        assert!((amplitude(&picked, 100.0, 7.0) - 3.0).abs() < 0.01);
        // through the filter: |H(93 Hz)|^2 = 1 / (1 + (93/40)^8) = 0.0012, no alias left
        let alias = amplitude(&filtered, 100.0, 7.0);
        assert!(alias < 0.01, "alias of {alias} at 7 Hz");
        // the in-band content is kept in both
        assert!((amplitude(&filtered, 100.0, 4.0) - 1.0).abs() < 1e-3);
        assert!((amplitude(&picked, 100.0, 4.0) - 1.0).abs() < 1e-3);
    }

    #[test]
    fn a_time_column_that_goes_back_is_refused() {
        let mut out = record(1000.0, 0.1, |_| 0.0);
        out.data[3 * 5] = 0.0;
        assert!(matches!(decimate(&out, 10), Err(DecimationError::Time(_))));
    }
}
