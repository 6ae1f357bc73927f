//! How a model field is read and written as an FMI value: the field's type gives its FMI type
//! ([`FmiValue`]), a [`Codec`] converts a field whose FMI form is a convention.

use crate::enumeration::EnumType;
use crate::variable::Access;

/// The four FMI scalar types as Rust values: builds the matching [`Access`].
pub trait Scalar: Sized + 'static {
    fn access<M>(get: fn(&M) -> Self, set: Option<fn(&mut M, Self)>) -> Access<M>;
}

impl Scalar for f64 {
    fn access<M>(get: fn(&M) -> Self, set: Option<fn(&mut M, Self)>) -> Access<M> {
        Access::Real { get, set }
    }
}

impl Scalar for i32 {
    fn access<M>(get: fn(&M) -> Self, set: Option<fn(&mut M, Self)>) -> Access<M> {
        Access::Integer { get, set }
    }
}

impl Scalar for bool {
    fn access<M>(get: fn(&M) -> Self, set: Option<fn(&mut M, Self)>) -> Access<M> {
        Access::Boolean { get, set }
    }
}

impl Scalar for String {
    fn access<M>(get: fn(&M) -> Self, set: Option<fn(&mut M, Self)>) -> Access<M> {
        Access::String { get, set }
    }
}

/// A field type with a natural FMI form: `f64` is a Real, `bool` a Boolean, `String` a String,
/// `i32`/`u32`/`u64` an Integer (unsigned values saturate at `i32::MAX` when read; a negative
/// value set into an unsigned field becomes 0, which the declared min or the physics' validation
/// rejects), and every [`crate::FmiEnum`] an Enumeration.
pub trait FmiValue {
    type Fmi: Scalar;
    /// The Enumeration type of the field, if it is one.
    const ENUMERATION: Option<&'static EnumType> = None;
    fn to_fmi(&self) -> Self::Fmi;
    fn set_fmi(&mut self, value: Self::Fmi);
}

impl FmiValue for f64 {
    type Fmi = f64;
    fn to_fmi(&self) -> f64 {
        *self
    }
    fn set_fmi(&mut self, value: f64) {
        *self = value;
    }
}

impl FmiValue for i32 {
    type Fmi = i32;
    fn to_fmi(&self) -> i32 {
        *self
    }
    fn set_fmi(&mut self, value: i32) {
        *self = value;
    }
}

impl FmiValue for bool {
    type Fmi = bool;
    fn to_fmi(&self) -> bool {
        *self
    }
    fn set_fmi(&mut self, value: bool) {
        *self = value;
    }
}

impl FmiValue for String {
    type Fmi = String;
    fn to_fmi(&self) -> String {
        self.clone()
    }
    fn set_fmi(&mut self, value: String) {
        *self = value;
    }
}

impl FmiValue for u32 {
    type Fmi = i32;
    fn to_fmi(&self) -> i32 {
        i32::try_from(*self).unwrap_or(i32::MAX)
    }
    fn set_fmi(&mut self, value: i32) {
        *self = u32::try_from(value).unwrap_or(0);
    }
}

impl FmiValue for u64 {
    type Fmi = i32;
    fn to_fmi(&self) -> i32 {
        i32::try_from(*self).unwrap_or(i32::MAX)
    }
    fn set_fmi(&mut self, value: i32) {
        *self = u64::try_from(value).unwrap_or(0);
    }
}

/// How a field of type `F` is read and written as an FMI value. [`Native`] uses the field's
/// [`FmiValue`]; a model defines its own codec for a field whose FMI form is a convention (e.g.
/// a sign stored as `f64`, exposed as an Integer of -1 / +1), named in the declaration with
/// `as Codec`.
pub trait Codec<F> {
    type Fmi: Scalar;
    const ENUMERATION: Option<&'static EnumType> = None;
    fn get(field: &F) -> Self::Fmi;
    fn set(field: &mut F, value: Self::Fmi);
}

/// The field's own FMI form ([`FmiValue`]); the default codec of [`crate::declare!`].
pub struct Native;

impl<F: FmiValue> Codec<F> for Native {
    type Fmi = F::Fmi;
    const ENUMERATION: Option<&'static EnumType> = F::ENUMERATION;
    fn get(field: &F) -> F::Fmi {
        field.to_fmi()
    }
    fn set(field: &mut F, value: F::Fmi) {
        field.set_fmi(value);
    }
}

/// A sign held as `f64` (+1 / -1), exposed as the Enumeration [`SIGN`] (so the glue refuses
/// anything but -1 and +1 when it is set); reads 0 only for a zero field.
pub struct Sign;

/// The Enumeration of a sign: `minus` = -1, `plus` = +1.
pub static SIGN: EnumType = EnumType {
    name: "Sign",
    description: "A sign: -1 or +1",
    items: &[
        crate::enumeration::EnumItem {
            name: "minus",
            value: -1,
            description: "-1",
        },
        crate::enumeration::EnumItem {
            name: "plus",
            value: 1,
            description: "+1",
        },
    ],
};

impl Codec<f64> for Sign {
    type Fmi = i32;
    const ENUMERATION: Option<&'static EnumType> = Some(&SIGN);
    fn get(field: &f64) -> i32 {
        if *field > 0.0 {
            1
        } else if *field < 0.0 {
            -1
        } else {
            0
        }
    }
    fn set(field: &mut f64, value: i32) {
        *field = f64::from(value);
    }
}

/// An optional value exposed as a Real where 0 means "none" (e.g. an optional stiffness: 0 =
/// rigid). Reads 0 for `None`; setting 0 gives `None`, anything else `Some`.
pub struct ZeroIsNone;

impl Codec<Option<f64>> for ZeroIsNone {
    type Fmi = f64;
    fn get(field: &Option<f64>) -> f64 {
        field.unwrap_or(0.0)
    }
    fn set(field: &mut Option<f64>, value: f64) {
        *field = (value != 0.0).then_some(value);
    }
}

/// An optional value a model always holds as `Some` (reads 0 for `None`, which the model never
/// has).
pub struct AlwaysSome;

impl Codec<Option<f64>> for AlwaysSome {
    type Fmi = f64;
    fn get(field: &Option<f64>) -> f64 {
        field.unwrap_or(0.0)
    }
    fn set(field: &mut Option<f64>, value: f64) {
        *field = Some(value);
    }
}
