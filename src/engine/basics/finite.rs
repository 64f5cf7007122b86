//! The boundary check of every answer: no NaN or infinity leaves the engine.
//!
//! Inputs are checked first (finite, in a physical range, by the models' constructors); this is the
//! last line. Every answer is walked field by field before it is returned (a serde serializer that
//! only looks at the numbers), and a number that is not finite is an error that names the field
//! and the request that led to it, instead of a `null` in JSON or `inf` in a table.

use serde::ser::{self, Serialize};

use crate::error::Error;

/// `Ok(answer)` when every number in it is finite, else [`Error::NonFinite`] naming the first
/// field that is not (`answer` says which answer, `request` which inputs led to it).
///
/// # Errors
/// [`Error::NonFinite`].
pub(crate) fn finite<T: Serialize>(
    answer: T,
    what: &'static str,
    request: impl FnOnce() -> String,
) -> Result<T, Error> {
    match first_non_finite(&answer) {
        None => Ok(answer),
        Some((field, value)) => Err(Error::NonFinite {
            answer: what,
            field,
            value,
            request: request(),
        }),
    }
}

/// The path and value of the first number in `value` that is not finite, if any.
pub(crate) fn first_non_finite<T: Serialize + ?Sized>(value: &T) -> Option<(String, f64)> {
    let mut walker = Walker::default();
    // The walker's only error is the finding itself.
    match value.serialize(&mut walker) {
        Ok(()) => None,
        Err(Found(value)) => {
            walker.path.reverse();
            Some((walker.path.join("."), value))
        }
    }
}

/// The error a walk stops with: the first number that is not finite.
#[derive(Debug)]
struct Found(f64);

impl std::fmt::Display for Found {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "non-finite number {}", self.0)
    }
}

impl std::error::Error for Found {}

impl ser::Error for Found {
    fn custom<M: std::fmt::Display>(_msg: M) -> Self {
        // A type that cannot serialise is not a number: not this check's concern.
        Found(0.0)
    }
}

/// Walks a value. The path to a finding is written on the way back out of it, innermost name
/// first, so a walk that finds nothing allocates nothing (the power batch walks every row).
#[derive(Default)]
struct Walker {
    path: Vec<String>,
}

impl Walker {
    fn number(&mut self, v: f64) -> Result<(), Found> {
        if v.is_finite() {
            Ok(())
        } else {
            Err(Found(v))
        }
    }
}

/// Compound parts of a value: each element or field is walked with its name on the path.
struct Part<'w> {
    walker: &'w mut Walker,
    index: usize,
    /// The key of the map entry being walked (flattened structs arrive as maps).
    key: Option<String>,
}

impl Part<'_> {
    fn element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Found> {
        let index = self.index;
        self.index += 1;
        self.named(value, || index.to_string())
    }

    fn field<T: Serialize + ?Sized>(&mut self, key: &str, value: &T) -> Result<(), Found> {
        self.named(value, || key.to_string())
    }

    /// Walks `value`; a finding in it adds `name` to the path on its way out.
    fn named<T: Serialize + ?Sized>(
        &mut self,
        value: &T,
        name: impl FnOnce() -> String,
    ) -> Result<(), Found> {
        value.serialize(&mut *self.walker).inspect_err(|_| {
            self.walker.path.push(name());
        })
    }
}

macro_rules! ok_scalars {
    ($($name:ident: $t:ty),*) => {
        $(fn $name(self, _v: $t) -> Result<(), Found> { Ok(()) })*
    };
}

/// Tuple and struct variants are walked as sequences (a trait method each, so a macro).
macro_rules! variants_are_sequences {
    ($($name:ident: $part:ident),*) => {$(
        fn $name(
            self,
            _: &'static str,
            _: u32,
            _: &'static str,
            len: usize,
        ) -> Result<Self::$part, Found> {
            self.serialize_seq(Some(len))
        }
    )*};
}

impl<'w> ser::Serializer for &'w mut Walker {
    type Ok = ();
    type Error = Found;
    type SerializeSeq = Part<'w>;
    type SerializeTuple = Part<'w>;
    type SerializeTupleStruct = Part<'w>;
    type SerializeTupleVariant = Part<'w>;
    type SerializeMap = Part<'w>;
    type SerializeStruct = Part<'w>;
    type SerializeStructVariant = Part<'w>;

    variants_are_sequences!(
        serialize_tuple_variant: SerializeTupleVariant,
        serialize_struct_variant: SerializeStructVariant
    );
    ok_scalars!(serialize_bool: bool, serialize_i8: i8, serialize_i16: i16, serialize_i32: i32,
        serialize_i64: i64, serialize_u8: u8, serialize_u16: u16, serialize_u32: u32,
        serialize_u64: u64, serialize_char: char, serialize_str: &str, serialize_bytes: &[u8]);

    fn serialize_f32(self, v: f32) -> Result<(), Found> {
        self.number(f64::from(v))
    }
    fn serialize_f64(self, v: f64) -> Result<(), Found> {
        self.number(v)
    }
    fn serialize_none(self) -> Result<(), Found> {
        Ok(())
    }
    fn serialize_some<T: Serialize + ?Sized>(self, value: &T) -> Result<(), Found> {
        value.serialize(self)
    }
    fn serialize_unit(self) -> Result<(), Found> {
        Ok(())
    }
    fn serialize_unit_struct(self, _name: &'static str) -> Result<(), Found> {
        Ok(())
    }
    fn serialize_unit_variant(self, _: &'static str, _: u32, _: &'static str) -> Result<(), Found> {
        Ok(())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _name: &'static str,
        value: &T,
    ) -> Result<(), Found> {
        value.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        value: &T,
    ) -> Result<(), Found> {
        Part {
            walker: self,
            index: 0,
            key: None,
        }
        .field(variant, value)
    }
    fn serialize_seq(self, _len: Option<usize>) -> Result<Part<'w>, Found> {
        Ok(Part {
            walker: self,
            index: 0,
            key: None,
        })
    }
    fn serialize_tuple(self, len: usize) -> Result<Part<'w>, Found> {
        self.serialize_seq(Some(len))
    }
    fn serialize_tuple_struct(self, _: &'static str, len: usize) -> Result<Part<'w>, Found> {
        self.serialize_seq(Some(len))
    }
    fn serialize_map(self, len: Option<usize>) -> Result<Part<'w>, Found> {
        self.serialize_seq(len)
    }
    fn serialize_struct(self, _: &'static str, len: usize) -> Result<Part<'w>, Found> {
        self.serialize_seq(Some(len))
    }
}

/// The serializers of sequences and tuples: every element is a part of its own (a trait impl
/// each, so a macro).
macro_rules! elements_are_parts {
    ($($trait:ident :: $method:ident),+) => {$(
        impl ser::$trait for Part<'_> {
            type Ok = ();
            type Error = Found;
            fn $method<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Found> {
                self.element(value)
            }
            fn end(self) -> Result<(), Found> {
                Ok(())
            }
        }
    )+};
}

elements_are_parts!(
    SerializeSeq::serialize_element,
    SerializeTuple::serialize_element,
    SerializeTupleStruct::serialize_field,
    SerializeTupleVariant::serialize_field
);

/// A map key as the path names it (a JSON string's text, else its JSON).
fn key_name<K: Serialize + ?Sized>(key: &K) -> Option<String> {
    match serde_json::to_value(key) {
        Ok(serde_json::Value::String(k)) => Some(k),
        Ok(other) => Some(other.to_string()),
        Err(_) => None,
    }
}

impl ser::SerializeMap for Part<'_> {
    type Ok = ();
    type Error = Found;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, key: &T) -> Result<(), Found> {
        self.key = key_name(key);
        Ok(())
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Found> {
        match self.key.take() {
            Some(k) => self.field(&k, value),
            None => self.element(value),
        }
    }
    /// A whole entry (maps and flattened structs): the key is named only for a finding (by its
    /// place in the map where it does not serialise).
    fn serialize_entry<K: Serialize + ?Sized, V: Serialize + ?Sized>(
        &mut self,
        key: &K,
        value: &V,
    ) -> Result<(), Found> {
        let index = self.index;
        self.index += 1;
        self.named(value, || key_name(key).unwrap_or_else(|| index.to_string()))
    }
    fn end(self) -> Result<(), Found> {
        Ok(())
    }
}

/// The serializers of structs: every field is a part named by its key.
macro_rules! fields_are_parts {
    ($($trait:ident),+) => {$(
        impl ser::$trait for Part<'_> {
            type Ok = ();
            type Error = Found;
            fn serialize_field<T: Serialize + ?Sized>(
                &mut self,
                key: &'static str,
                value: &T,
            ) -> Result<(), Found> {
                self.field(key, value)
            }
            fn end(self) -> Result<(), Found> {
                Ok(())
            }
        }
    )+};
}

fields_are_parts!(SerializeStruct, SerializeStructVariant);

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Serialize;

    #[derive(Serialize)]
    struct Inner {
        power_w: f64,
        optional_w: Option<f64>,
    }

    #[derive(Serialize)]
    struct Answer {
        name: String,
        rows: Vec<Inner>,
        #[serde(flatten)]
        flat: Inner,
    }

    fn answer(x: f64) -> Answer {
        Answer {
            name: "n".into(),
            rows: vec![
                Inner {
                    power_w: 1.0,
                    optional_w: None,
                },
                Inner {
                    power_w: 2.0,
                    optional_w: Some(x),
                },
            ],
            flat: Inner {
                power_w: 3.0,
                optional_w: Some(4.0),
            },
        }
    }

    #[test]
    fn finite_answers_pass_and_the_first_non_finite_field_is_named() {
        assert!(first_non_finite(&answer(5.0)).is_none());
        let (path, value) = first_non_finite(&answer(f64::INFINITY)).unwrap();
        assert_eq!(path, "rows.1.optional_w");
        assert!(value.is_infinite());
        let (path, value) = first_non_finite(&answer(f64::NAN)).unwrap();
        assert_eq!(path, "rows.1.optional_w");
        assert!(value.is_nan());
        let e = finite(answer(f64::NEG_INFINITY), "power", || {
            "airspeed_mps 1e308".into()
        })
        .err()
        .unwrap()
        .to_string();
        assert!(
            e.contains("rows.1.optional_w") && e.contains("airspeed_mps 1e308"),
            "{e}"
        );
    }

    #[test]
    fn map_entries_are_named_by_their_keys_at_any_depth() {
        use std::collections::BTreeMap;
        let mut by_name = BTreeMap::new();
        by_name.insert("a".to_string(), vec![1.0, 2.0]);
        by_name.insert("b".to_string(), vec![3.0, f64::NAN]);
        let nested = vec![Some(by_name)];
        assert_eq!(first_non_finite(&nested).unwrap().0, "0.b.1");
        let mut by_number = BTreeMap::new();
        by_number.insert(3_u32, 1.0);
        by_number.insert(7_u32, f64::NEG_INFINITY);
        assert_eq!(first_non_finite(&by_number).unwrap().0, "7");
        assert_eq!(
            first_non_finite(&(1.0, [2.0, f64::INFINITY])).unwrap().0,
            "1.1"
        );
        let finite_map: BTreeMap<String, f64> = [("x".to_string(), 1.0)].into();
        assert!(first_non_finite(&finite_map).is_none());
    }

    #[test]
    fn flattened_fields_are_walked_too() {
        let mut a = answer(1.0);
        a.flat.power_w = f64::NAN;
        assert_eq!(first_non_finite(&a).unwrap().0, "power_w");
    }
}
