//! The table and figures every root locus draws, whichever linear model the eigenvalues come
//! from (the 2-dof bogie or the coach): all eigenvalues per speed as CSV, the locus in the
//! complex plane coloured by speed (and zoomed on the followed mode), and the followed mode's
//! damping ratio and frequency over speed.

use super::figures::ColourScatter;
use super::{AnalysisError, Artefacts, Table};
use crate::plot::Chart;

/// omega / 2 pi \[Hz\] of an eigenvalue's imaginary part.
pub fn freq_hz(im: f64) -> f64 {
    im.abs() / (2.0 * std::f64::consts::PI)
}

/// -re / |lambda| [-] (negative = unstable).
pub fn damping_ratio(re: f64, im: f64) -> f64 {
    let n = re.hypot(im);
    if n > 0.0 {
        -re / n
    } else {
        0.0
    }
}

/// One speed of a root locus.
#[derive(Debug, Clone, Copy)]
pub struct LocusSpeed<'a> {
    pub speed_kmh: f64,
    /// Every eigenvalue (re, im) at this speed.
    pub eigenvalues: &'a [(f64, f64)],
    /// The followed mode's eigenvalue (re, im), if one is oscillatory.
    pub mode: Option<(f64, f64)>,
}

impl<'a> LocusSpeed<'a> {
    /// The speeds of a locus from its grid and, per speed, every eigenvalue and the followed
    /// mode.
    pub fn over(
        speeds_kmh: &[f64],
        per_speed: impl IntoIterator<Item = (&'a [(f64, f64)], Option<(f64, f64)>)>,
    ) -> Vec<Self> {
        speeds_kmh
            .iter()
            .zip(per_speed)
            .map(|(v, (eigenvalues, mode))| LocusSpeed {
                speed_kmh: *v,
                eigenvalues,
                mode,
            })
            .collect()
    }
}

/// A root locus to draw: the model and damper it is of, the mode it follows, its speeds.
#[derive(Debug, Clone)]
pub struct LocusFigures<'a> {
    /// The model as the titles name it ("bogie", "coach").
    pub model: &'static str,
    /// The damper as the locus title names it.
    pub damper: String,
    /// The followed mode as the legends and titles name it ("hunting mode").
    pub mode: &'static str,
    /// Header of the eigenvalue table's column that flags the followed mode.
    pub mode_column: &'static str,
    /// Title of the frequency figure.
    pub frequency_title: String,
    pub speeds: Vec<LocusSpeed<'a>>,
}

impl LocusFigures<'_> {
    /// `root_locus_eigenvalues.csv`: every eigenvalue per speed, the followed mode flagged.
    pub fn add_eigenvalue_table(&self, a: &mut Artefacts) -> Result<(), AnalysisError> {
        let mut all = Table::new(&[
            "speed [km/h]",
            "eigenvalue index",
            "real part [1/s]",
            "imaginary part [rad/s]",
            "frequency [Hz]",
            "damping ratio [-]",
            self.mode_column,
        ]);
        for s in &self.speeds {
            for (i, &(re, im)) in s.eigenvalues.iter().enumerate() {
                let followed = s
                    .mode
                    .is_some_and(|(m_re, m_im)| m_re == re && m_im.abs() == im.abs());
                all.rows.push(vec![
                    s.speed_kmh,
                    i as f64,
                    re,
                    im,
                    freq_hz(im),
                    damping_ratio(re, im),
                    if followed { 1.0 } else { 0.0 },
                ]);
            }
        }
        a.add_table("root_locus_eigenvalues.csv", &all)?;
        Ok(())
    }

    /// `root_locus.svg`, `root_locus_zoom.svg` (when a mode is followed), `damping_ratio.svg`
    /// and `hunting_frequency.svg`.
    pub fn add_figures(&self, a: &mut Artefacts) -> Result<(), AnalysisError> {
        // upper half-plane only (conjugates carry no information)
        let upper: Vec<(f64, f64, f64)> = self
            .speeds
            .iter()
            .flat_map(|s| {
                s.eigenvalues
                    .iter()
                    .filter(|e| e.1 >= 0.0)
                    .map(move |&(re, im)| (re, im, s.speed_kmh))
            })
            .collect();
        // (re, im, speed) of the followed mode
        let followed: Vec<(f64, f64, f64)> = self
            .speeds
            .iter()
            .filter_map(|s| s.mode.map(|(re, im)| (re, im, s.speed_kmh)))
            .collect();
        let title = format!(
            "Root locus of the linear {}, {} to {} km/h ({})",
            self.model,
            self.speeds.first().map_or(0.0, |s| s.speed_kmh),
            self.speeds.last().map_or(0.0, |s| s.speed_kmh),
            self.damper
        );
        let mut full =
            ColourScatter::new(&title, "real part [1/s]", "imaginary part [rad/s]", "km/h");
        full.points = upper.clone();
        full.highlight = Some((
            self.mode.into(),
            followed.iter().map(|p| (p.0, p.1)).collect(),
        ));
        full.zero_line_x = true;
        a.add_text("root_locus.svg", full.to_svg()?);
        // zoom on the followed mode: real parts within a few times its excursion
        if !followed.is_empty() {
            let span = followed
                .iter()
                .map(|p| p.0.abs())
                .fold(0.0, f64::max)
                .max(1.0);
            let im_max = followed.iter().map(|p| p.1).fold(0.0, f64::max);
            let mut zoom = full.clone();
            zoom.title = format!("{title}: zoom on the {}", self.mode);
            zoom.points = upper
                .into_iter()
                .filter(|p| p.0 >= -3.0 * span && p.1 <= 2.0 * im_max)
                .collect();
            a.add_text("root_locus_zoom.svg", zoom.to_svg()?);
        }
        let series = |f: fn(&(f64, f64, f64)) -> f64| -> Vec<(f64, f64)> {
            followed.iter().map(|p| (p.2, f(p))).collect()
        };
        let zeta = Chart::new(
            &format!(
                "Damping ratio of the {} vs speed (linear {})",
                self.mode, self.model
            ),
            "speed [km/h]",
            "damping ratio -Re/|lambda| [-]",
        )
        .with_series(self.mode, series(|p| damping_ratio(p.0, p.1)))
        .with_limit(0.0, "stability limit");
        a.add_lines("damping_ratio.svg", &zeta)?;
        let freq = Chart::new(&self.frequency_title, "speed [km/h]", "frequency [Hz]")
            .with_series(self.mode, series(|p| freq_hz(p.1)));
        a.add_lines("hunting_frequency.svg", &freq)?;
        Ok(())
    }
}

/// The summary line naming the speed grid.
pub fn speeds_line(speeds_kmh: &[f64]) -> String {
    format!(
        "speeds {} to {} km/h, {} points\n",
        speeds_kmh.first().copied().unwrap_or(0.0),
        speeds_kmh.last().copied().unwrap_or(0.0),
        speeds_kmh.len()
    )
}
