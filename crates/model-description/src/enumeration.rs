//! Choice parameters as FMI 2.0 Enumeration types. A model's Rust enum is declared once with
//! [`crate::fmi_enum!`] (type name, items with their FMI names, values and descriptions); a
//! field of that enum type then declares an Enumeration variable (`<Enumeration
//! declaredType=".." start=".."/>`) whose type goes to `<TypeDefinitions>`. The glue rejects an
//! Integer that is not one of the items before it reaches the model.

/// One item of an Enumeration type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EnumItem {
    /// Item name shown by hosts (e.g. `nonlinear`).
    pub name: &'static str,
    /// The Integer the host sets and gets.
    pub value: i32,
    pub description: &'static str,
}

/// An Enumeration type: `<SimpleType name=".."><Enumeration><Item .../>...`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EnumType {
    /// Type name, unique in the model and different from every variable name.
    pub name: &'static str,
    pub description: &'static str,
    pub items: &'static [EnumItem],
}

impl EnumType {
    /// The item with this value, if any.
    pub fn item(&self, value: i32) -> Option<&'static EnumItem> {
        self.items.iter().find(|i| i.value == value)
    }

    /// "0 = linear, 1 = nonlinear", for messages.
    pub fn item_list(&self) -> String {
        self.items
            .iter()
            .map(|i| format!("{} = {}", i.value, i.name))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// A Rust enum (unit variants) that is an FMI Enumeration. Implement it with
/// [`crate::fmi_enum!`].
pub trait FmiEnum: Sized + 'static {
    const TYPE: &'static EnumType;
    fn to_value(&self) -> i32;
    fn from_value(value: i32) -> Option<Self>;
}

impl<E: FmiEnum> crate::codec::FmiValue for E {
    type Fmi = i32;
    const ENUMERATION: Option<&'static EnumType> = Some(E::TYPE);
    fn to_fmi(&self) -> i32 {
        self.to_value()
    }
    fn set_fmi(&mut self, value: i32) {
        // The glue accepts only item values, so the match never misses.
        if let Some(e) = E::from_value(value) {
            *self = e;
        }
    }
}

/// Make an existing enum of unit variants an FMI Enumeration, naming each item once:
///
/// ```ignore
/// model_description::fmi_enum! {
///     ModelKind as "WheelRailForceLaw", "Wheel/rail force law of the time-domain model" {
///         Linear = 0, "linear", "(5.1)-(5.18): Kalker linear creep, constant conicity";
///         NonLinear = 1, "nonlinear", "(5.19)-(5.27): contact table, saturation";
///     }
/// }
/// ```
///
/// Every variant must be listed (the generated `match` is exhaustive), so adding a variant to
/// the enum without an item does not compile.
#[macro_export]
macro_rules! fmi_enum {
    ($ty:ident as $type_name:literal, $type_description:literal {
        $($variant:ident = $value:literal, $item:literal, $description:literal;)+
    }) => {
        impl $crate::enumeration::FmiEnum for $ty {
            const TYPE: &'static $crate::enumeration::EnumType = &$crate::enumeration::EnumType {
                name: $type_name,
                description: $type_description,
                items: &[$($crate::enumeration::EnumItem {
                    name: $item,
                    value: $value,
                    description: $description,
                }),+],
            };
            fn to_value(&self) -> i32 {
                match self {
                    $($ty::$variant => $value,)+
                }
            }
            fn from_value(value: i32) -> Option<Self> {
                match value {
                    $($value => Some($ty::$variant),)+
                    _ => None,
                }
            }
        }
    };
}
