//! Many wheel profiles at once (a fleet's measured worn profiles): each profile on both wheels
//! of the wheelset, on the rails and with the set-up of the single run, into one conicity table
//! (a row per profile) and a figure of the conicity at 3 mm per profile.
//!
//! A profile that cannot be read, or whose conicity the EN 15302 method does not define at an
//! amplitude of the table, gets a row with its reason and no numbers (a fleet of measured
//! wheels holds a few bad measurements; they must not withhold the others' table); the
//! command then exits with status 1 naming them. Only when no profile gives a table is nothing
//! written.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use rayon::prelude::*;
use wheel_rail::DeltaR;

use super::{
    check_options, conicity_at, setup_of, stopped, table_over_grid, ConicityPoint, GeometryInputs,
    ProfileSource,
};
use crate::analysis::{AnalysisError, Artefacts};
use crate::plot::{
    colour, draw_legend, legend_width, longest, tick_label, LegendEntry, PlotError, Swatch,
};
use master::output::csv_field;

/// File name endings read from a `--wheel-dir` folder (case-insensitive).
pub const PROFILE_EXTENSIONS: [&str; 4] = ["dat", "txt", "csv", "prf"];

/// Amplitude of the fleet figure \[m\].
pub const FIGURE_AMPLITUDE_M: f64 = 3e-3;

/// The entries of a `--wheel-dir` folder, sorted by name.
#[derive(Debug, Default)]
pub struct ProfileFolder {
    /// The profile files: one of [`PROFILE_EXTENSIONS`], not hidden, not a result.
    pub files: Vec<PathBuf>,
    /// The names of the other entries, skipped.
    pub skipped: Vec<String>,
    /// The names of the files that are results of an earlier contact-geometry run, skipped.
    pub results: Vec<String>,
}

/// The profile files of a folder ([`ProfileFolder`]); `is_result` tells the names of the
/// command's own results, which a run into that folder may have left there.
pub fn profiles_in(
    dir: &Path,
    is_result: fn(&str) -> bool,
) -> Result<ProfileFolder, AnalysisError> {
    let io = |e: std::io::Error| AnalysisError::Input(format!("{}: {e}", dir.display()));
    let mut found = ProfileFolder::default();
    for entry in std::fs::read_dir(dir).map_err(io)? {
        let entry = entry.map_err(io)?;
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().to_string();
        if is_result(&name) {
            found.results.push(name);
            continue;
        }
        let is_profile = path.is_file()
            && !name.starts_with('.')
            && path
                .extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| PROFILE_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()));
        if is_profile {
            found.files.push(path);
        } else {
            found.skipped.push(name);
        }
    }
    found.files.sort();
    found.skipped.sort();
    found.results.sort();
    if found.files.is_empty() {
        return Err(AnalysisError::Input(format!(
            "{}: no wheel profile files (.{}) in the folder",
            dir.display(),
            PROFILE_EXTENSIONS.join(", .")
        )));
    }
    Ok(found)
}

/// One profile's row.
#[derive(Debug, Clone, PartialEq)]
pub struct FleetRow {
    /// The profile as given (file path).
    pub profile: String,
    /// Largest reachable y (flange limit) \[m\].
    pub flange_limit_m: f64,
    /// First y > 0 with flange contact (tanγ > 1 on the right wheel) \[m\], if any.
    pub flange_contact_m: Option<f64>,
    /// At 1, 2, ... mm up to the largest amplitude.
    pub conicity: Vec<ConicityPoint>,
}

impl FleetRow {
    /// The point at `a` \[m\], if it is one of the table's amplitudes.
    pub fn at(&self, a: f64) -> Option<&ConicityPoint> {
        self.conicity
            .iter()
            .find(|p| (p.amplitude_m - a).abs() < 1e-12)
    }
}

/// The fleet table.
#[derive(Debug, Clone, PartialEq)]
pub struct FleetResults {
    /// Set-up (the wheels of `inputs` are not used).
    pub inputs: GeometryInputs,
    pub rows: Vec<FleetRow>,
    /// The profiles without a complete table: (profile as given, why).
    pub failed: Vec<(String, String)>,
    /// Amplitudes of the table \[m\]: 1, 2, ... mm up to the largest amplitude.
    pub amplitudes_m: Vec<f64>,
}

/// Whether two sources are the same profile: equal, or files that are one file.
fn same_profile(a: &ProfileSource, b: &ProfileSource) -> bool {
    match (a, b) {
        (ProfileSource::File(x), ProfileSource::File(y)) => {
            x == y
                || matches!(
                    (std::fs::canonicalize(x), std::fs::canonicalize(y)),
                    (Ok(cx), Ok(cy)) if cx == cy
                )
        }
        _ => a == b,
    }
}

/// Computes the table for `wheels` (each on both wheels) with the set-up of `inputs`, profiles in
/// parallel.
pub fn fleet(
    inputs: &GeometryInputs,
    wheels: &[ProfileSource],
    cancel: &AtomicBool,
) -> Result<FleetResults, AnalysisError> {
    check_options(inputs)?;
    if wheels.is_empty() {
        return Err(AnalysisError::Input("no wheel profiles given".into()));
    }
    // one row per profile: the same file twice (named twice, or named and in the folder) is
    // a slip, not a second wheel
    for (i, wheel) in wheels.iter().enumerate() {
        if let Some(j) = wheels[..i].iter().position(|w| same_profile(w, wheel)) {
            return Err(AnalysisError::Input(format!(
                "wheel profile {} is given twice (profiles {} and {} of the fleet)",
                wheel.describe(),
                j + 1,
                i + 1
            )));
        }
    }
    if inputs.amplitude_max_m < FIGURE_AMPLITUDE_M - 1e-12 {
        return Err(AnalysisError::Option {
            option: "--amplitude-max",
            value: master::show::num(inputs.amplitude_max_m * 1e3).to_string(),
            reason: "must be at least 3 mm for the fleet table (its figure is at 3 mm)".into(),
        });
    }
    // the fleet table gives the conicity from 1 mm: at least 10 table steps there
    if super::lowest_amplitude_m(inputs.step_m) > 1e-3 + 1e-12 {
        return Err(AnalysisError::Option {
            option: "--step",
            value: master::show::num(inputs.step_m * 1e3).to_string(),
            reason: "must be at most 0.1 mm for the fleet table (its conicity from 1 mm needs \
                     10 table steps there)"
                .into(),
        });
    }
    let n_amp = (inputs.amplitude_max_m * 1e3 + 1e-9).floor() as usize;
    let amplitudes_m: Vec<f64> = (1..=n_amp).map(|k| k as f64 * 1e-3).collect();
    let results: Vec<Result<FleetRow, AnalysisError>> = wheels
        .par_iter()
        .map(|wheel| {
            if cancel.load(Ordering::SeqCst) {
                return Err(AnalysisError::Cancelled);
            }
            let single = GeometryInputs {
                wheel_left: wheel.clone(),
                wheel_right: wheel.clone(),
                ..inputs.clone()
            };
            let setup = setup_of(&single)?;
            let table = table_over_grid(&setup, inputs, cancel).map_err(stopped)?;
            let d = DeltaR::from_table(&table);
            let conicity = amplitudes_m
                .iter()
                .map(|&a| conicity_at(&d, a))
                .collect::<Result<Vec<_>, _>>()?;
            let flange_contact_m = table
                .reachable_rows()
                .filter(|r| r.y_m > 0.0 && r.right.tan_gamma > 1.0)
                .map(|r| r.y_m)
                .reduce(f64::min);
            Ok(FleetRow {
                profile: wheel.describe(),
                flange_limit_m: table.y_reachable_max_m,
                flange_contact_m,
                conicity,
            })
        })
        .collect();
    if cancel.load(Ordering::SeqCst) {
        return Err(AnalysisError::Cancelled);
    }
    let mut rows = Vec::with_capacity(results.len());
    let mut failed = Vec::new();
    for (wheel, r) in wheels.iter().zip(results) {
        match r {
            Ok(row) => rows.push(row),
            Err(AnalysisError::Cancelled) => return Err(AnalysisError::Cancelled),
            Err(e) => failed.push((wheel.describe(), e.to_string())),
        }
    }
    if rows.is_empty() {
        let list: Vec<String> = failed.iter().map(|(p, e)| format!("  {p}: {e}")).collect();
        return Err(AnalysisError::Geometry(format!(
            "none of the {} wheel profiles has a complete conicity table (nothing written; \
             lower --amplitude-max, or see each reason):\n{}",
            wheels.len(),
            list.join("\n")
        )));
    }
    Ok(FleetResults {
        inputs: inputs.clone(),
        rows,
        failed,
        amplitudes_m,
    })
}

impl FleetResults {
    /// The error a run with [`FleetResults::failed`] profiles ends with, once its files are
    /// written: each such profile with its reason.
    pub fn incomplete(&self) -> Option<String> {
        if self.failed.is_empty() {
            return None;
        }
        let list: Vec<String> = self
            .failed
            .iter()
            .map(|(p, e)| format!("  {p}: {e}"))
            .collect();
        Some(format!(
            "{} of {} wheel profiles have no complete conicity table (their rows in \
             fleet_conicity.csv give the reason; lower --amplitude-max, or see each reason):\n{}",
            self.failed.len(),
            self.failed.len() + self.rows.len(),
            list.join("\n")
        ))
    }
}

impl FleetResults {
    /// CSV text: a row per profile.
    pub fn to_csv(&self) -> String {
        let conv = self.inputs.radius_convention.name();
        let mut head = vec![
            "profile".to_string(),
            "flange limit y [mm]".to_string(),
            "first flange contact y [mm] (empty: none before the flange limit)".to_string(),
        ];
        for a in &self.amplitudes_m {
            head.push(format!(
                "tan gamma_e EN 15302 Annex B at {:.0} mm ({conv})",
                a * 1e3
            ));
        }
        head.push(format!(
            "tan gamma_e EN 15302 Annex C regression at 3 mm ({conv})"
        ));
        head.push("wavelength at 3 mm [m] (inf: not restored)".to_string());
        head.push("error (empty: a complete table)".to_string());
        let mut out: String = head
            .iter()
            .map(|h| csv_field(h))
            .collect::<Vec<_>>()
            .join(",");
        out.push('\n');
        for r in &self.rows {
            let mut cells = vec![
                csv_field(&r.profile),
                (r.flange_limit_m * 1e3).to_string(),
                r.flange_contact_m
                    .map(|y| (y * 1e3).to_string())
                    .unwrap_or_default(),
            ];
            cells.extend(r.conicity.iter().map(|p| p.tan_gamma_e.to_string()));
            let at3 = r.at(FIGURE_AMPLITUDE_M);
            cells.push(at3.map(|p| p.regression.to_string()).unwrap_or_default());
            cells.push(at3.map(|p| p.wavelength_m.to_string()).unwrap_or_default());
            cells.push(String::new());
            out.push_str(&cells.join(","));
            out.push('\n');
        }
        // a profile without a complete table: its name, empty numbers, why
        let empty = 2 + self.amplitudes_m.len() + 2;
        for (profile, error) in &self.failed {
            let mut cells = vec![csv_field(profile)];
            cells.extend(std::iter::repeat_n(String::new(), empty));
            cells.push(csv_field(error));
            out.push_str(&cells.join(","));
            out.push('\n');
        }
        out
    }

    /// Short names for the figure: the file name without its folder.
    fn labels(&self) -> Vec<String> {
        self.rows
            .iter()
            .map(|r| {
                Path::new(&r.profile)
                    .file_name()
                    .map(|n| n.to_string_lossy().to_string())
                    .unwrap_or_else(|| r.profile.clone())
            })
            .collect()
    }

    /// Figure: conicity at 3 mm per profile (Annex B and Annex C).
    pub fn to_svg(&self) -> Result<String, PlotError> {
        let title = format!(
            "Equivalent conicity at 3 mm per wheel profile (EN 15302, {})",
            self.inputs.radius_convention.name()
        );
        let labels = self.labels();
        let annex_b: Vec<f64> = self
            .rows
            .iter()
            .filter_map(|r| r.at(FIGURE_AMPLITUDE_M).map(|p| p.tan_gamma_e))
            .collect();
        let annex_c: Vec<f64> = self
            .rows
            .iter()
            .filter_map(|r| r.at(FIGURE_AMPLITUDE_M).map(|p| p.regression))
            .collect();
        category_svg(
            &title,
            "wheel profile",
            "equivalent conicity tan gamma_e at 3 mm [-]",
            &labels,
            &[
                ("reference method (Annex B)", &annex_b),
                ("linear regression (Annex C)", &annex_c),
            ],
        )
    }

    pub fn add_artefacts(&self, a: &mut Artefacts) -> Result<(), AnalysisError> {
        a.add_text("fleet_conicity.csv", self.to_csv());
        a.add_text("fleet_conicity_3mm.svg", self.to_svg()?);
        Ok(())
    }

    pub fn summary(&self, folder: &ProfileFolder) -> String {
        let skipped = &folder.skipped;
        let mut s = format!(
            "{} wheel profiles, each on both wheels; rails {} / {}, nominal radius {:.1} / {:.1} \
             mm, gauge {:.2} mm; conicity in the {} convention\n",
            self.rows.len() + self.failed.len(),
            self.inputs.rail_left.describe(),
            self.inputs.rail_right.describe(),
            self.inputs.radius_left_m * 1e3,
            self.inputs.radius_right_m * 1e3,
            self.inputs.gauge_m * 1e3,
            self.inputs.radius_convention.name()
        );
        s.push_str(&super::placement_text(&self.inputs));
        s.push('\n');
        if !skipped.is_empty() {
            s.push_str(&format!(
                "skipped {} folder entries that are not profile files (.{}): {}\n",
                skipped.len(),
                PROFILE_EXTENSIONS.join(", ."),
                skipped.join(", ")
            ));
        }
        if !folder.results.is_empty() {
            s.push_str(&format!(
                "skipped {} results of an earlier contact-geometry run: {}\n",
                folder.results.len(),
                folder.results.join(", ")
            ));
        }
        for r in &self.rows {
            if let Some(p) = r.at(FIGURE_AMPLITUDE_M) {
                s.push_str(&format!(
                    "  {}: tan gamma_e at 3 mm {:.4} (regression {:.4}), flange limit {:.2} mm\n",
                    r.profile,
                    p.tan_gamma_e,
                    p.regression,
                    r.flange_limit_m * 1e3
                ));
            }
        }
        for (profile, _) in &self.failed {
            s.push_str(&format!(
                "  {profile}: no complete conicity table (the reason is in its row)\n"
            ));
        }
        s
    }
}

/// Points per category (x = category index, labelled with its name), one colour per series,
/// axis descriptions with units.
fn category_svg(
    title: &str,
    x_desc: &str,
    y_desc: &str,
    labels: &[String],
    series: &[(&str, &[f64])],
) -> Result<String, PlotError> {
    let draw = |e: &dyn std::fmt::Display| PlotError::Draw {
        title: title.to_string(),
        reason: e.to_string(),
    };
    let values: Vec<f64> = series
        .iter()
        .flat_map(|(_, v)| v.iter().copied())
        .filter(|v| v.is_finite())
        .collect();
    if labels.is_empty() || values.is_empty() {
        return Err(PlotError::Data {
            title: title.to_string(),
            reason: "no finite points".into(),
        });
    }
    let hi = values.iter().copied().fold(0.0_f64, f64::max);
    let lo = values.iter().copied().fold(0.0_f64, f64::min);
    let pad = ((hi - lo) * 0.08).max(0.01);
    let n = labels.len();
    let rotate = n > 6 || labels.iter().any(|l| l.len() > 14);
    let longest_label = longest(labels.iter().map(String::as_str)).max(1);
    let x_area = if rotate {
        (40 + 7 * longest_label.min(40)) as u32
    } else {
        45
    };
    let legend_px = legend_width(longest(series.iter().map(|(name, _)| *name)));
    let width = (900_usize).max(60 + 28 * n).min(4000) as u32 + legend_px;
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, 560 + x_area)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| draw(&e))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(12)
            .margin_right(12 + legend_px)
            .x_label_area_size(x_area)
            .y_label_area_size(70)
            .build_cartesian_2d(-0.5..(n as f64 - 0.5), (lo - pad)..(hi + pad))
            .map_err(|e| draw(&e))?;
        // many or long names are written downwards from their tick, by hand (the mesh centres
        // rotated labels on the tick)
        let name_of = |x: &f64| {
            let k = x.round();
            if !rotate && (x - k).abs() < 1e-6 && k >= 0.0 && (k as usize) < n {
                labels[k as usize].clone()
            } else {
                String::new()
            }
        };
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc(y_desc)
            .x_labels(n)
            .axis_desc_style(("sans-serif", 15))
            .x_label_formatter(&name_of)
            .y_label_formatter(&|v| tick_label(*v, &((lo - pad)..(hi + pad))))
            .disable_x_mesh()
            .draw()
            .map_err(|e| draw(&e))?;
        if rotate {
            let style = ("sans-serif", 12)
                .into_font()
                .transform(FontTransform::Rotate90)
                .into_text_style(&root)
                .pos(Pos::new(HPos::Left, VPos::Center));
            for (k, label) in labels.iter().enumerate() {
                let (px, py) = chart.backend_coord(&(k as f64, lo - pad));
                root.draw(&Text::new(label.clone(), (px, py + 8), style.clone()))
                    .map_err(|e| draw(&e))?;
            }
        }
        let mut entries = Vec::with_capacity(series.len());
        for (i, (name, vals)) in series.iter().enumerate() {
            let color = colour(i);
            let marker = 4 - i.min(2) as i32;
            chart
                .draw_series(
                    vals.iter()
                        .enumerate()
                        .filter(|(_, v)| v.is_finite())
                        .map(|(k, &v)| Circle::new((k as f64, v), marker, color.filled())),
                )
                .map_err(|e| draw(&e))?;
            entries.push(LegendEntry::new(*name, Swatch::Dot(color, marker)));
        }
        // right of the plotting area, never over the data
        let (xs, ys) = chart.plotting_area().get_pixel_range();
        draw_legend(&root, title, &entries, (xs.end + 10, ys.start))?;
        root.present().map_err(|e| draw(&e))?;
    }
    Ok(svg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn category_figure_has_names_units_and_both_series() {
        let labels = vec!["worn_01.dat".to_string(), "worn_02.dat".to_string()];
        let svg = category_svg(
            "conicity",
            "wheel profile",
            "tan gamma_e at 3 mm [-]",
            &labels,
            &[("Annex B", &[0.2, 0.3]), ("Annex C", &[0.19, 0.28])],
        )
        .unwrap();
        for s in [
            "worn_01.dat",
            "worn_02.dat",
            "tan gamma_e at 3 mm [-]",
            "wheel profile",
            "Annex B",
            "Annex C",
        ] {
            assert!(svg.contains(s), "missing {s}");
        }
        assert!(category_svg("e", "x", "y", &labels, &[("s", &[f64::NAN])]).is_err());
    }

    #[test]
    fn folder_listing_keeps_profiles_and_names_the_rest() {
        let d = tempfile::tempdir().unwrap();
        for f in [
            "b.dat",
            "a.TXT",
            "notes.md",
            ".hidden.dat",
            "fleet_conicity.csv",
        ] {
            std::fs::write(d.path().join(f), "0 0\n1 0\n2 0\n").unwrap();
        }
        let found = profiles_in(d.path(), |n| n == "fleet_conicity.csv").unwrap();
        let names: Vec<_> = found
            .files
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().to_string())
            .collect();
        assert_eq!(names, ["a.TXT", "b.dat"]);
        assert_eq!(found.skipped, [".hidden.dat", "notes.md"]);
        assert_eq!(found.results, ["fleet_conicity.csv"]);
        let empty = tempfile::tempdir().unwrap();
        assert!(profiles_in(empty.path(), |_| false).is_err());
    }
}
