//! Wheel/rail contact, the one home of it in the project: contact geometry from real profiles
//! (rigid contact search, rolling radius difference Δr(y), contact angles, roll angle, EN 15302
//! equivalent conicity), the contact-geometry table the time-domain models interpolate
//! ([`table`]), and the creep-force laws of one wheel ([`creep`]: Hertz/Kalker coefficients,
//! Vermeulen-Johnson saturation) and the lateral track alignment they run on ([`track`]: ERRI
//! B176 spectrum and generator, spatial delay line).
//!
//! # API (what the master's `contact-geometry` command calls)
//! ```no_run
//! use wheel_rail::{compute_table, equivalent_conicity, ContactSetup, Profile};
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let wheel = Profile::from_file("RUIC519A.dat")?; // mm, see `profile` for the formats
//! let rail = Profile::from_file("SUIC519A.dat")?;
//! let setup = ContactSetup::symmetric(wheel, rail, 0.46, 1.43516); // or fill the struct
//! let table = compute_table(&setup, -10e-3, 10e-3, 0.05e-3)?; // SI units
//! let c = equivalent_conicity(&table, 3e-3)?; // c.tan_gamma_e, c.wavelength_m
//! std::fs::write("wheel_rail.csv", table.to_bogie_csv())?;
//! # Ok(()) }
//! ```
//! `cargo run -p wheel-rail --release --example bogie_table [out.csv]` writes the E1 table in
//! the bogie's format (the bogie's shipped table is a calibration input and predates the
//! contact-zone centroid: see the example's docs).
//!
//! # Coordinate conventions (established from the EN 15302 benchmark data, `data/`)
//! * **Profile files**: lateral coordinate positive towards the FIELD side (away from the track
//!   centre; the wheel flange is at negative lateral values: flange tip of wheel A at -55 mm,
//!   back of flange at -70 mm), vertical positive UP, millimetres.
//! * **Wheel origin** = nominal rolling circle (taping line, 70 mm from the back face for wheel A):
//!   rolling radius at lateral s is `r0 - z(s)`.
//! * **Rail origin**: a point of the rail head (z = 0 at s = 0, top of rail at z = +0.49 mm,
//!   s = +14.3 mm). In the E1 set-up the rail origins sit at ±750 mm, i.e. at the same lateral
//!   position as the wheel taping lines of the centred wheelset (profile origins 1500 mm apart);
//!   the gauge 1435.16 mm measured 14 mm below the top of rail places them at ±749.98 mm, which is
//!   what [`ContactSetup::symmetric`] does (gauge face point at s = -32.40 mm).
//! * **Rail inclination is already in the rail file.** Circle fits of the 60E1 head arcs in
//!   SUIC519A.dat (R13 corners centred at (-19.65, -15.88) and (26.34, -13.60) mm, R80 at
//!   (-1.06, -80.40) and (14.30, -79.50), R300 at (17.58, -299.18)) all lie on one axis tilted by
//!   0.0496 rad (≈ 1:20) towards the track centre. Applying any additional rotation makes the E1
//!   agreement worse (±0.001 rad doubles the RMS error), so [`ContactSetup::rail_inclination`] is
//!   the rotation to APPLY to a profile given upright (e.g. 1/40), and 0 for the benchmark rail.
//! * **Track frame**: Y positive to the RIGHT, Z up; the right rail at Y > 0; left-side profiles
//!   are mirrored.
//! * **y** = wheelset lateral displacement, positive to the RIGHT, i.e. the right wheel moves
//!   towards its flange contact, so Δr = r_right - r_left > 0 for y > 0 (the E1 reference file is
//!   antisymmetric with Δr > 0 for y > 0, consistent with this). y is measured at RAIL LEVEL (centre
//!   plane of the wheelset at the height of the nominal rolling circles); measuring it at the axle
//!   centre shifts it by r0·sin(roll) and worsens the E1 agreement from 0.038 to 0.163 mm RMS
//!   (test `rail_level_is_the_convention_of_the_e1_reference`), so rail level is the
//!   benchmark's convention ([`LateralReference`]).
//! * **Roll** positive = right wheel up. **Contact angle** tanγ of each wheel is the slope of the
//!   contact tangent in the track frame, positive when the surface rises towards the field side
//!   (conical tread), large on the flange (wheel A: up to 2.79 = 70°).
//!
//! # Method and limits
//! Rigid, single-point contact per wheel, piecewise-linear profiles (see [`contact`]); the flange
//! limit is the steepest point of the flange (E1: |y| = 7.40 mm on a 0.05 mm grid), beyond it the
//! table's grid rows repeat the last reachable row (the time-domain models' table), while the
//! search goes on up the flange ([`ContactTable::flange_climb_rows`]). A jump of a contact point
//! between grid rows (two-point contact: tread to flange, or between the two bands of a
//! hollow-worn tread) is located by bisection on y to 1e-8 m ([`ContactTable::jumps`]).
//! Unequal nominal radii enter as [`ContactSetup::radius_convention`] says: EN 15302's offset of
//! Δr (default of [`ContactSetup::symmetric`], the conicity's convention) or the rigid wheelset's
//! roll (the bogie tables' convention, [`RadiusConvention`]). The equivalent conicity follows
//! EN 15302 Annex B, with the Annex C regression and the harmonic linearisation beside it (see
//! [`conicity`]): it is 0 where Δr does not restore (a flat tread), and an error only where the
//! method gives no value.
//!
//! **Contact point in nearly conformal zones.** The benchmark profile tables carry a periodic
//! curvature ripple (a resampling artefact: on the rail's R300 crown the curvature oscillates
//! between 1/380 and 1/230 mm⁻¹ with a ~3 mm period, on the R80 arcs ±15 %; the wheel tread shows
//! ±20 % with a ~2 mm period), while wheel and rail are nearly conformal over most of the tread
//! (relative curvature 0.0004-0.005 mm⁻¹, e.g. wheel R≈96 mm against rail R80 for y = 4-6 mm,
//! wheel R14 against rail R13 at the flange root). The bare minimum-distance point then jumps
//! between ripple lobes: Δr becomes a staircase with ±0.1-0.2 mm teeth (E1 max error 0.20 mm at
//! 5.9 mm, 111/121 points within 0.1 mm). Cubic / Hermite interpolation of the tables does not
//! help (113/121: the ripple is in the data, not in the linear kinks); a smoothing spline of
//! the profiles removes the tread staircase but rings at the curvature steps of the flange root
//! (115/121). The contact point is therefore the penetration-weighted centroid of the zone where
//! the gap is within [`ContactSetup::contact_zone_depth_m`] (default 7.5 µm, a "virtual
//! penetration" far below the elastic approach of a loaded wheel) of its minimum; the roll angle
//! and the wheelset height still follow from the minimum gaps.
//!
//! E1 results: Δr within 0.1 mm of the reference for all 121 points with |y| <= 6 mm (RMS 0.038 mm,
//! max 0.076 mm at |y| = 5.6 mm; also met for zone depths 5-10 µm); flange contact (tanγ > 1) from
//! 6.62 mm, largest Δr jump 9.2 -> 12.2 mm at 6.68-6.69 mm (issue: between 6.3 and 6.8 mm);
//! tanγe = 0.123 / 0.182 / 0.258 / 0.523 / 0.648 at 1 / 3 / 5 / 7 / 7.5 mm (EN 15302 Annex E:
//! 0.125 / 0.188 / 0.254 / 0.505 / 0.640), every 0.5 mm within 0.019 of Annex E. Case E5 (920 /
//! 918 mm) in the EN 15302 convention: within 0.012 of Annex E from 1 to 7.5 mm (rigid roll:
//! 0.017), tests/en15302_e5.rs.
//!
//! # For time-domain models (bogie, vehicle)
//! This crate has no `Params`/`step` model of its own: the models hold a [`GeometryTable`]
//! (read from the CSV with [`GeometryTable::load`], or converted from a profile search with
//! [`ContactTable::geometry_table`]), share it between wheelsets (`Arc` or a borrow), and look it
//! up per wheelset and evaluation ([`GeometryTable::lookup`], or
//! [`GeometryTable::lookup_with_hint`] with one [`SegmentHint`] per wheelset); the creep forces
//! use [`creep::saturation_factor`]; the track under each wheelset comes from
//! [`track::TrackGenerator`] or a [`track::DelayLine`].

pub mod conicity;
pub mod contact;
pub mod creep;
pub mod profile;
pub mod table;
pub mod text_file;
pub mod track;

pub use conicity::{
    equivalent_conicity, harmonic_linearisation, linear_regression, Conicity, ConicityError,
    DeltaR, LinearRegression,
};
pub use contact::{
    compute_table, compute_table_until, solve_contact, ContactError, ContactJump, ContactRow,
    ContactSetup, ContactTable, LateralReference, RadiusConvention, RailPlacement, WheelContact,
    WheelPlacement, WheelSide, CONTACT_ZONE_DEPTH_M,
};
pub use creep::{
    hertz_kalker, saturated_wheelset_creep, saturation_factor, HertzKalker, WheelsetCreepForces,
};
pub use profile::{Profile, ProfileError, MIN_POINTS};
pub use table::{
    write_csv, ContactGeometry, CsvNumbers, CsvRow, FlangeNotCovered, GeometryTable, SegmentHint,
    TableError, BOGIE_CSV_HEADER, FLANGE_TAN_GAMMA, MAX_TABLE_REACH_M,
};
