//! Finding a float that JSON cannot hold. `serde_json` writes NaN and infinities as `null`,
//! which a non-optional `f64` field then refuses to read back (and an optional one reads as
//! "absent"): a record with such a value is a record the tool wrote but cannot read. Every JSON
//! file goes through [`first_non_finite`] before it is written (see `write_json`).
//!
//! The check walks the value with a serde `Serializer` that looks only at floats, so it sees
//! every float of every type the crate writes, with the path that leads to it
//! (`levels[3].estimate`), without a list of fields to keep up to date.

use serde::Serialize;
use serde::ser::{self, Impossible};
use std::fmt;

/// A float that is not finite, and where it is: a path such as `levels[3].estimate`.
#[derive(Clone, Debug, PartialEq)]
pub struct NonFinite {
    pub path: String,
    pub value: f64,
}

impl fmt::Display for NonFinite {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} is {}, not a finite number", if self.path.is_empty() { "the value" } else { &self.path }, self.value)
    }
}

/// The first float in `value` (in serialisation order) that is NaN or infinite.
pub fn first_non_finite<T: Serialize + ?Sized>(value: &T) -> Option<NonFinite> {
    let mut walker = Walker::default();
    let _ = value.serialize(&mut walker);
    walker.found
}

/// One step of a path: a field or map key, or a sequence index.
enum Step {
    Key(String),
    Index(usize),
}

#[derive(Default)]
struct Walker {
    path: Vec<Step>,
    found: Option<NonFinite>,
}

impl Walker {
    fn path(&self) -> String {
        let mut s = String::new();
        for step in &self.path {
            match step {
                Step::Key(k) if s.is_empty() => s += k,
                Step::Key(k) => s += &format!(".{k}"),
                Step::Index(i) => s += &format!("[{i}]"),
            }
        }
        s
    }

    fn float(&mut self, value: f64) -> Result<(), Stop> {
        if value.is_finite() {
            return Ok(());
        }
        self.found = Some(NonFinite { path: self.path(), value });
        Err(Stop)
    }

    /// Walk `value` one step further down the path.
    fn visit<T: Serialize + ?Sized>(&mut self, step: Step, value: &T) -> Result<(), Stop> {
        self.path.push(step);
        let r = value.serialize(&mut *self);
        self.path.pop();
        r
    }
}

/// Ends the walk: a non-finite float was found (or a value refused to serialise, which the
/// writer will report itself).
#[derive(Debug)]
struct Stop;

impl fmt::Display for Stop {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("stop")
    }
}

impl std::error::Error for Stop {}

impl ser::Error for Stop {
    fn custom<T: fmt::Display>(_: T) -> Self {
        Stop
    }
}

/// A sequence, tuple, map or struct being walked: counts its elements, remembers a map's key.
struct Compound<'a> {
    walker: &'a mut Walker,
    index: usize,
    key: String,
}

impl Compound<'_> {
    fn element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Stop> {
        self.index += 1;
        self.walker.visit(Step::Index(self.index - 1), value)
    }
}

macro_rules! ignore {
    ($($method:ident($ty:ty)),* $(,)?) => {
        $(fn $method(self, _: $ty) -> Result<(), Stop> { Ok(()) })*
    };
}

impl<'a> ser::Serializer for &'a mut Walker {
    type Ok = ();
    type Error = Stop;
    type SerializeSeq = Compound<'a>;
    type SerializeTuple = Compound<'a>;
    type SerializeTupleStruct = Compound<'a>;
    type SerializeTupleVariant = Compound<'a>;
    type SerializeMap = Compound<'a>;
    type SerializeStruct = Compound<'a>;
    type SerializeStructVariant = Compound<'a>;

    ignore!(
        serialize_bool(bool),
        serialize_i8(i8),
        serialize_i16(i16),
        serialize_i32(i32),
        serialize_i64(i64),
        serialize_i128(i128),
        serialize_u8(u8),
        serialize_u16(u16),
        serialize_u32(u32),
        serialize_u64(u64),
        serialize_u128(u128),
        serialize_char(char),
        serialize_str(&str),
        serialize_bytes(&[u8]),
        serialize_unit_struct(&'static str),
    );

    fn serialize_f32(self, v: f32) -> Result<(), Stop> {
        self.float(v.into())
    }
    fn serialize_f64(self, v: f64) -> Result<(), Stop> {
        self.float(v)
    }
    fn serialize_none(self) -> Result<(), Stop> {
        Ok(())
    }
    fn serialize_some<T: Serialize + ?Sized>(self, value: &T) -> Result<(), Stop> {
        value.serialize(self)
    }
    fn serialize_unit(self) -> Result<(), Stop> {
        Ok(())
    }
    fn serialize_unit_variant(self, _: &'static str, _: u32, _: &'static str) -> Result<(), Stop> {
        Ok(())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(self, _: &'static str, value: &T) -> Result<(), Stop> {
        value.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        value: &T,
    ) -> Result<(), Stop> {
        self.visit(Step::Key(variant.into()), value)
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Compound<'a>, Stop> {
        Ok(Compound { walker: self, index: 0, key: String::new() })
    }
    fn serialize_tuple(self, len: usize) -> Result<Compound<'a>, Stop> {
        self.serialize_seq(Some(len))
    }
    fn serialize_tuple_struct(self, _: &'static str, len: usize) -> Result<Compound<'a>, Stop> {
        self.serialize_seq(Some(len))
    }
    fn serialize_tuple_variant(self, _: &'static str, _: u32, variant: &'static str, len: usize) -> Result<Compound<'a>, Stop> {
        self.path.push(Step::Key(variant.into()));
        self.serialize_seq(Some(len))
    }
    fn serialize_map(self, len: Option<usize>) -> Result<Compound<'a>, Stop> {
        self.serialize_seq(len)
    }
    fn serialize_struct(self, _: &'static str, len: usize) -> Result<Compound<'a>, Stop> {
        self.serialize_seq(Some(len))
    }
    fn serialize_struct_variant(self, _: &'static str, _: u32, variant: &'static str, len: usize) -> Result<Compound<'a>, Stop> {
        self.serialize_tuple_variant("", 0, variant, len)
    }
}

impl Compound<'_> {
    /// End a compound; a variant's (`variant`) name leaves the path with it.
    fn close(self, variant: bool) -> Result<(), Stop> {
        if variant {
            self.walker.path.pop();
        }
        Ok(())
    }
}

/// The compound traits whose elements are walked by position (`Trait::method => variant`):
/// sequences, tuples, tuple structs and tuple variants.
macro_rules! by_position {
    ($($trait:ident :: $method:ident => $variant:literal),* $(,)?) => {$(
        impl ser::$trait for Compound<'_> {
            type Ok = ();
            type Error = Stop;
            fn $method<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Stop> {
                self.element(value)
            }
            fn end(self) -> Result<(), Stop> {
                self.close($variant)
            }
        }
    )*};
}

by_position!(
    SerializeSeq::serialize_element => false,
    SerializeTuple::serialize_element => false,
    SerializeTupleStruct::serialize_field => false,
    SerializeTupleVariant::serialize_field => true,
);

/// The compound traits whose fields are walked by name: structs and struct variants.
macro_rules! by_name {
    ($($trait:ident => $variant:literal),* $(,)?) => {$(
        impl ser::$trait for Compound<'_> {
            type Ok = ();
            type Error = Stop;
            fn serialize_field<T: Serialize + ?Sized>(&mut self, key: &'static str, value: &T) -> Result<(), Stop> {
                self.walker.visit(Step::Key(key.into()), value)
            }
            fn end(self) -> Result<(), Stop> {
                self.close($variant)
            }
        }
    )*};
}

by_name!(SerializeStruct => false, SerializeStructVariant => true);

impl ser::SerializeMap for Compound<'_> {
    type Ok = ();
    type Error = Stop;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, key: &T) -> Result<(), Stop> {
        self.key = key.serialize(KeyText).unwrap_or_else(|_| format!("#{}", self.index));
        Ok(())
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Stop> {
        self.index += 1;
        self.walker.visit(Step::Key(std::mem::take(&mut self.key)), value)
    }
    fn end(self) -> Result<(), Stop> {
        self.close(false)
    }
}

/// A map key as text (JSON keys are strings; numbers and unit variants are written as such).
struct KeyText;

macro_rules! key_as_text {
    ($($method:ident($ty:ty)),* $(,)?) => {
        $(fn $method(self, v: $ty) -> Result<String, Stop> { Ok(v.to_string()) })*
    };
}

impl ser::Serializer for KeyText {
    type Ok = String;
    type Error = Stop;
    type SerializeSeq = Impossible<String, Stop>;
    type SerializeTuple = Impossible<String, Stop>;
    type SerializeTupleStruct = Impossible<String, Stop>;
    type SerializeTupleVariant = Impossible<String, Stop>;
    type SerializeMap = Impossible<String, Stop>;
    type SerializeStruct = Impossible<String, Stop>;
    type SerializeStructVariant = Impossible<String, Stop>;

    key_as_text!(
        serialize_bool(bool),
        serialize_i8(i8),
        serialize_i16(i16),
        serialize_i32(i32),
        serialize_i64(i64),
        serialize_i128(i128),
        serialize_u8(u8),
        serialize_u16(u16),
        serialize_u32(u32),
        serialize_u64(u64),
        serialize_u128(u128),
        serialize_f32(f32),
        serialize_f64(f64),
        serialize_char(char),
        serialize_str(&str),
    );

    fn serialize_bytes(self, _: &[u8]) -> Result<String, Stop> {
        Err(Stop)
    }
    fn serialize_none(self) -> Result<String, Stop> {
        Err(Stop)
    }
    fn serialize_some<T: Serialize + ?Sized>(self, value: &T) -> Result<String, Stop> {
        value.serialize(self)
    }
    fn serialize_unit(self) -> Result<String, Stop> {
        Err(Stop)
    }
    fn serialize_unit_struct(self, _: &'static str) -> Result<String, Stop> {
        Err(Stop)
    }
    fn serialize_unit_variant(self, _: &'static str, _: u32, variant: &'static str) -> Result<String, Stop> {
        Ok(variant.into())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(self, _: &'static str, value: &T) -> Result<String, Stop> {
        value.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(self, _: &'static str, _: u32, _: &'static str, _: &T) -> Result<String, Stop> {
        Err(Stop)
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Self::SerializeSeq, Stop> {
        Err(Stop)
    }
    fn serialize_tuple(self, _: usize) -> Result<Self::SerializeTuple, Stop> {
        Err(Stop)
    }
    fn serialize_tuple_struct(self, _: &'static str, _: usize) -> Result<Self::SerializeTupleStruct, Stop> {
        Err(Stop)
    }
    fn serialize_tuple_variant(self, _: &'static str, _: u32, _: &'static str, _: usize) -> Result<Self::SerializeTupleVariant, Stop> {
        Err(Stop)
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Self::SerializeMap, Stop> {
        Err(Stop)
    }
    fn serialize_struct(self, _: &'static str, _: usize) -> Result<Self::SerializeStruct, Stop> {
        Err(Stop)
    }
    fn serialize_struct_variant(self, _: &'static str, _: u32, _: &'static str, _: usize) -> Result<Self::SerializeStructVariant, Stop> {
        Err(Stop)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    #[derive(Serialize)]
    struct Level {
        level: usize,
        estimate: f64,
        error: Option<f64>,
    }

    #[derive(Serialize)]
    struct Run {
        id: String,
        constants: BTreeMap<String, f64>,
        levels: Vec<Level>,
    }

    fn run(estimate: f64, error: Option<f64>, constant: f64) -> Run {
        let lvl = |level| Level { level, estimate: 1.0, error: Some(0.5) };
        Run {
            id: "a".into(),
            constants: [("delta".to_string(), constant)].into(),
            levels: vec![lvl(0), Level { level: 1, estimate, error }, lvl(2)],
        }
    }

    #[test]
    fn finds_every_kind_of_non_finite_float_with_its_path() {
        assert_eq!(first_non_finite(&run(1.0, Some(2.0), 0.1)), None);
        assert_eq!(first_non_finite(&run(1.0, None, 0.1)), None, "an absent optional value is fine");
        assert_eq!(first_non_finite(&run(f64::INFINITY, None, 0.1)).unwrap().path, "levels[1].estimate");
        let nan = first_non_finite(&run(1.0, Some(f64::NAN), 0.1)).unwrap();
        assert_eq!(nan.path, "levels[1].error");
        assert!(nan.value.is_nan());
        assert_eq!(first_non_finite(&run(1.0, None, f64::NEG_INFINITY)).unwrap().path, "constants.delta");
        assert_eq!(first_non_finite(&vec![[0.0, 1.0], [f64::NAN, 2.0]]).unwrap().path, "[1][0]");
        assert_eq!(first_non_finite(&f32::INFINITY).unwrap().to_string(), "the value is inf, not a finite number");
    }

    #[derive(Serialize)]
    enum Shape {
        Pair(f64, f64),
        Named { x: f64 },
    }

    #[derive(Serialize)]
    struct Shapes {
        shapes: Vec<Shape>,
        after: f64,
    }

    #[test]
    fn a_variant_names_its_floats_and_leaves_the_path_when_it_ends() {
        let shapes = |x: f64, after: f64| Shapes { shapes: vec![Shape::Pair(1.0, 2.0), Shape::Named { x }], after };
        assert_eq!(first_non_finite(&shapes(1.0, 0.0)), None);
        assert_eq!(first_non_finite(&shapes(f64::NAN, 0.0)).unwrap().path, "shapes[1].Named.x");
        assert_eq!(first_non_finite(&shapes(1.0, f64::INFINITY)).unwrap().path, "after");
        let pair = Shapes { shapes: vec![Shape::Pair(1.0, f64::NAN)], after: 0.0 };
        assert_eq!(first_non_finite(&pair).unwrap().path, "shapes[0].Pair[1]");
    }
}
