//! Unit definitions written to `<UnitDefinitions>`: SI base-unit exponents per unit, plus
//! display units (km/h for m/s, kN for N, bar for Pa, mm for m, deg for rad, % for 1). A unit
//! whose SI exponents are not integers (an orifice coefficient in m3/(s.Pa^0.5)) is written
//! without a BaseUnit, which FMI 2.0 allows.

/// A unit and its SI base-unit exponents (kg, m, s, A, K, mol, cd, rad).
#[derive(Clone, Copy, Debug)]
pub struct UnitDef {
    pub name: &'static str,
    pub kg: i32,
    pub m: i32,
    pub s: i32,
    pub a: i32,
    pub rad: i32,
    /// Whether the exponents above are the unit's (false: no integer exponents exist, no
    /// BaseUnit is written).
    pub base: bool,
    /// (name, factor, offset): display value = factor * value + offset.
    pub display: &'static [(&'static str, f64, f64)],
}

const fn unit(
    name: &'static str,
    kg: i32,
    m: i32,
    s: i32,
    a: i32,
    rad: i32,
    display: &'static [(&'static str, f64, f64)],
) -> UnitDef {
    UnitDef {
        name,
        kg,
        m,
        s,
        a,
        rad,
        base: true,
        display,
    }
}

/// A unit with no integer SI exponents (no BaseUnit in the XML).
const fn unit_without_base(
    name: &'static str,
    display: &'static [(&'static str, f64, f64)],
) -> UnitDef {
    UnitDef {
        base: false,
        ..unit(name, 0, 0, 0, 0, 0, display)
    }
}

/// Every unit a model may use. A variable with a unit not listed here is a declaration error,
/// caught when the model description is generated.
pub const UNITS: &[UnitDef] = &[
    unit("1", 0, 0, 0, 0, 0, &[("%", 100.0, 0.0)]),
    unit("m", 0, 1, 0, 0, 0, &[("mm", 1000.0, 0.0)]),
    unit(
        "m/s",
        0,
        1,
        -1,
        0,
        0,
        &[("km/h", 3.6, 0.0), ("mm/s", 1000.0, 0.0)],
    ),
    unit("m/s2", 0, 1, -2, 0, 0, &[]),
    unit("m2", 0, 2, 0, 0, 0, &[("cm2", 1.0e4, 0.0)]),
    unit("m3", 0, 3, 0, 0, 0, &[("l", 1000.0, 0.0)]),
    unit("m3/s", 0, 3, -1, 0, 0, &[("l/min", 60000.0, 0.0)]),
    unit("m3/(s.Pa)", -1, 4, 1, 0, 0, &[]),
    // Orifice flow coefficient Q = C sqrt(dP): kg^-1/2 m^7/2, no integer exponents.
    unit_without_base("m3/(s.Pa^0.5)", &[]),
    unit("kg", 1, 0, 0, 0, 0, &[("t", 1.0e-3, 0.0)]),
    unit("kg.m2", 1, 2, 0, 0, 0, &[]),
    unit("kg/m3", 1, -3, 0, 0, 0, &[]),
    unit("N", 1, 1, -2, 0, 0, &[("kN", 1.0e-3, 0.0)]),
    unit(
        "N/m",
        1,
        0,
        -2,
        0,
        0,
        &[("kN/m", 1.0e-3, 0.0), ("MN/m", 1.0e-6, 0.0)],
    ),
    unit("N.s/m", 1, 0, -1, 0, 0, &[("kN.s/m", 1.0e-3, 0.0)]),
    unit("N.m", 1, 2, -2, 0, 0, &[("kN.m", 1.0e-3, 0.0)]),
    unit("N.m/rad", 1, 2, -2, 0, -1, &[("MN.m/rad", 1.0e-6, 0.0)]),
    unit("Pa", 1, -1, -2, 0, 0, &[("bar", 1.0e-5, 0.0)]),
    unit("Pa/s", 1, -1, -3, 0, 0, &[]),
    unit("W", 1, 2, -3, 0, 0, &[("kW", 1.0e-3, 0.0)]),
    unit("V", 1, 2, -3, -1, 0, &[]),
    unit("s", 0, 0, 1, 0, 0, &[("ms", 1000.0, 0.0)]),
    unit("Hz", 0, 0, -1, 0, 0, &[]),
    unit("rad", 0, 0, 0, 0, 1, &[("deg", 57.295_779_513_082_32, 0.0)]),
    unit(
        "rad/s",
        0,
        0,
        -1,
        0,
        1,
        &[("deg/s", 57.295_779_513_082_32, 0.0)],
    ),
    unit("rad/s2", 0, 0, -2, 0, 1, &[]),
    unit("1/s", 0, 0, -1, 0, 0, &[]),
    unit("m/N", -1, 0, 2, 0, 0, &[("mm/kN", 1.0e6, 0.0)]),
    unit("m2/s2", 0, 2, -2, 0, 0, &[]),
];

pub fn find(name: &str) -> Option<&'static UnitDef> {
    UNITS.iter().find(|u| u.name == name)
}
