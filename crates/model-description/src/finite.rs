//! Whether every floating-point number in a value is finite, by walking the value with serde
//! (a serializer that writes nothing). The glue checks a deserialised FMU state with it: a
//! state carrying NaN or inf would otherwise be restored into the model and poison its outputs.

use serde::ser::{self, Serialize};

/// Why a value did not pass.
#[derive(Debug)]
pub struct NotFinite(String);

impl std::fmt::Display for NotFinite {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for NotFinite {}

impl ser::Error for NotFinite {
    fn custom<T: std::fmt::Display>(msg: T) -> Self {
        NotFinite(msg.to_string())
    }
}

/// `Ok` if every `f32`/`f64` inside `value` is finite.
pub fn check_finite<T: Serialize + ?Sized>(value: &T) -> Result<(), NotFinite> {
    value.serialize(Walker)
}

struct Walker;

fn float(x: f64) -> Result<(), NotFinite> {
    if x.is_finite() {
        Ok(())
    } else {
        Err(NotFinite(format!(
            "the state holds the non-finite number {x}"
        )))
    }
}

/// Serialize the children of a compound with the walker.
impl ser::SerializeSeq for Walker {
    type Ok = ();
    type Error = NotFinite;
    fn serialize_element<T: Serialize + ?Sized>(&mut self, v: &T) -> Result<(), NotFinite> {
        v.serialize(Walker)
    }
    fn end(self) -> Result<(), NotFinite> {
        Ok(())
    }
}

macro_rules! compound {
    ($trait:ident, $method:ident $(, $key:ty)?) => {
        impl ser::$trait for Walker {
            type Ok = ();
            type Error = NotFinite;
            fn $method<T: Serialize + ?Sized>(
                &mut self,
                $(_key: $key,)?
                v: &T,
            ) -> Result<(), NotFinite> {
                v.serialize(Walker)
            }
            fn end(self) -> Result<(), NotFinite> {
                Ok(())
            }
        }
    };
}

compound!(SerializeTuple, serialize_element);
compound!(SerializeTupleStruct, serialize_field);
compound!(SerializeTupleVariant, serialize_field);
compound!(SerializeStruct, serialize_field, &'static str);
compound!(SerializeStructVariant, serialize_field, &'static str);

impl ser::SerializeMap for Walker {
    type Ok = ();
    type Error = NotFinite;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, k: &T) -> Result<(), NotFinite> {
        k.serialize(Walker)
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, v: &T) -> Result<(), NotFinite> {
        v.serialize(Walker)
    }
    fn end(self) -> Result<(), NotFinite> {
        Ok(())
    }
}

macro_rules! leaf {
    ($($method:ident($ty:ty)),*) => {
        $(fn $method(self, _v: $ty) -> Result<(), NotFinite> {
            Ok(())
        })*
    };
}

impl ser::Serializer for Walker {
    type Ok = ();
    type Error = NotFinite;
    type SerializeSeq = Walker;
    type SerializeTuple = Walker;
    type SerializeTupleStruct = Walker;
    type SerializeTupleVariant = Walker;
    type SerializeMap = Walker;
    type SerializeStruct = Walker;
    type SerializeStructVariant = Walker;

    leaf!(
        serialize_bool(bool),
        serialize_i8(i8),
        serialize_i16(i16),
        serialize_i32(i32),
        serialize_i64(i64),
        serialize_u8(u8),
        serialize_u16(u16),
        serialize_u32(u32),
        serialize_u64(u64),
        serialize_char(char),
        serialize_str(&str),
        serialize_bytes(&[u8])
    );

    fn serialize_f32(self, v: f32) -> Result<(), NotFinite> {
        float(f64::from(v))
    }
    fn serialize_f64(self, v: f64) -> Result<(), NotFinite> {
        float(v)
    }
    fn serialize_none(self) -> Result<(), NotFinite> {
        Ok(())
    }
    fn serialize_some<T: Serialize + ?Sized>(self, v: &T) -> Result<(), NotFinite> {
        v.serialize(Walker)
    }
    fn serialize_unit(self) -> Result<(), NotFinite> {
        Ok(())
    }
    fn serialize_unit_struct(self, _name: &'static str) -> Result<(), NotFinite> {
        Ok(())
    }
    fn serialize_unit_variant(
        self,
        _name: &'static str,
        _index: u32,
        _variant: &'static str,
    ) -> Result<(), NotFinite> {
        Ok(())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _name: &'static str,
        v: &T,
    ) -> Result<(), NotFinite> {
        v.serialize(Walker)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _name: &'static str,
        _index: u32,
        _variant: &'static str,
        v: &T,
    ) -> Result<(), NotFinite> {
        v.serialize(Walker)
    }
    fn serialize_seq(self, _len: Option<usize>) -> Result<Walker, NotFinite> {
        Ok(Walker)
    }
    fn serialize_tuple(self, _len: usize) -> Result<Walker, NotFinite> {
        Ok(Walker)
    }
    fn serialize_tuple_struct(self, _name: &'static str, _len: usize) -> Result<Walker, NotFinite> {
        Ok(Walker)
    }
    fn serialize_tuple_variant(
        self,
        _name: &'static str,
        _index: u32,
        _variant: &'static str,
        _len: usize,
    ) -> Result<Walker, NotFinite> {
        Ok(Walker)
    }
    fn serialize_map(self, _len: Option<usize>) -> Result<Walker, NotFinite> {
        Ok(Walker)
    }
    fn serialize_struct(self, _name: &'static str, _len: usize) -> Result<Walker, NotFinite> {
        Ok(Walker)
    }
    fn serialize_struct_variant(
        self,
        _name: &'static str,
        _index: u32,
        _variant: &'static str,
        _len: usize,
    ) -> Result<Walker, NotFinite> {
        Ok(Walker)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(serde::Serialize)]
    struct S {
        a: f64,
        b: Vec<(u8, Option<f64>)>,
        c: [f64; 2],
    }

    #[test]
    fn finds_non_finite_numbers_anywhere() {
        let ok = S {
            a: 1.0,
            b: vec![(1, Some(2.0)), (2, None)],
            c: [0.0, -1.0],
        };
        assert!(check_finite(&ok).is_ok());
        for bad in [
            S {
                a: f64::NAN,
                ..ok_s()
            },
            S {
                b: vec![(1, Some(f64::INFINITY))],
                ..ok_s()
            },
            S {
                c: [0.0, f64::NEG_INFINITY],
                ..ok_s()
            },
        ] {
            assert!(check_finite(&bad).is_err());
        }
    }

    fn ok_s() -> S {
        S {
            a: 1.0,
            b: Vec::new(),
            c: [0.0; 2],
        }
    }
}
