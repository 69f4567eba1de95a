//! JSON out. serde_json writes a NaN or an infinity as `null`, the same as an absent
//! value, so a number a bug made non-finite would read as "not given" (issue 28). Every
//! JSON rtid writes goes through [`pretty`] or [`compact`], which first walk the value
//! and refuse a non-finite number naming where it is (`uncertainty.standard_errors.Kw`).

use std::fmt;

use serde::ser::{self, Serialize};

/// A value that cannot be written as JSON.
#[derive(Debug, thiserror::Error)]
pub enum JsonError {
    #[error("{value} at `{path}` is not a finite number: it would be written as null")]
    NonFinite { path: String, value: f64 },
    #[error(transparent)]
    Serde(#[from] serde_json::Error),
}

/// `value` as indented JSON, refusing a non-finite number.
pub fn pretty<T: Serialize + ?Sized>(value: &T) -> Result<String, JsonError> {
    check(value)?;
    Ok(serde_json::to_string_pretty(value)?)
}

/// `value` as one line of JSON, refusing a non-finite number.
pub fn compact<T: Serialize + ?Sized>(value: &T) -> Result<String, JsonError> {
    check(value)?;
    Ok(serde_json::to_string(value)?)
}

/// `value` as a [`serde_json::Value`] (to add fields to), refusing a non-finite number
/// (which `serde_json::to_value` turns into null).
pub fn value<T: Serialize + ?Sized>(value: &T) -> Result<serde_json::Value, JsonError> {
    check(value)?;
    Ok(serde_json::to_value(value)?)
}

/// The first non-finite number in `value`, with its path.
pub fn check<T: Serialize + ?Sized>(value: &T) -> Result<(), JsonError> {
    match value.serialize(&mut Walk::default()) {
        Err(Stop::Found { path, value }) => Err(JsonError::NonFinite { path, value }),
        // Anything else serde_json reports itself when it writes.
        Err(Stop::Other) | Ok(()) => Ok(()),
    }
}

/// Where the walk is: fields, map keys and indices from the root.
#[derive(Default)]
struct Walk {
    path: Vec<String>,
}

impl Walk {
    fn float(&self, value: f64) -> Result<(), Stop> {
        if value.is_finite() {
            return Ok(());
        }
        let path = self.path.iter().fold(String::new(), |mut p, s| {
            if !(p.is_empty() || s.starts_with('[')) {
                p.push('.');
            }
            p.push_str(s);
            p
        });
        Err(Stop::Found { path, value })
    }

    fn child<T: Serialize + ?Sized>(&mut self, at: String, value: &T) -> Result<(), Stop> {
        self.path.push(at);
        let r = value.serialize(&mut *self);
        self.path.pop();
        r
    }
}

/// Why the walk stopped.
#[derive(Debug)]
enum Stop {
    Found { path: String, value: f64 },
    Other,
}

impl fmt::Display for Stop {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{self:?}")
    }
}

impl std::error::Error for Stop {}

impl ser::Error for Stop {
    fn custom<T: fmt::Display>(_: T) -> Self {
        Stop::Other
    }
}

/// A map key as the path shows it.
fn key_text<K: Serialize + ?Sized>(key: &K) -> String {
    match serde_json::to_value(key) {
        Ok(serde_json::Value::String(s)) => s,
        Ok(other) => other.to_string(),
        Err(_) => "?".into(),
    }
}

/// Sequences, tuples and their variants: elements by index.
struct Items<'a> {
    walk: &'a mut Walk,
    index: usize,
}

impl Items<'_> {
    fn item<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Stop> {
        let at = format!("[{}]", self.index);
        self.index += 1;
        self.walk.child(at, value)
    }
}

/// Maps: values by their key.
struct Entries<'a> {
    walk: &'a mut Walk,
    key: String,
}

/// Structs and struct variants: values by field name.
struct Fields<'a> {
    walk: &'a mut Walk,
}

/// Serializer methods of values that hold no number.
macro_rules! ignored {
    ($($method:ident: $t:ty),* $(,)?) => {
        $(fn $method(self, _: $t) -> Result<(), Stop> {
            Ok(())
        })*
    };
}

impl<'a> ser::Serializer for &'a mut Walk {
    type Ok = ();
    type Error = Stop;
    type SerializeSeq = Items<'a>;
    type SerializeTuple = Items<'a>;
    type SerializeTupleStruct = Items<'a>;
    type SerializeTupleVariant = Items<'a>;
    type SerializeMap = Entries<'a>;
    type SerializeStruct = Fields<'a>;
    type SerializeStructVariant = Fields<'a>;

    fn serialize_f64(self, v: f64) -> Result<(), Stop> {
        self.float(v)
    }
    fn serialize_f32(self, v: f32) -> Result<(), Stop> {
        self.float(f64::from(v))
    }
    ignored! {
        serialize_bool: bool,
        serialize_i8: i8,
        serialize_i16: i16,
        serialize_i32: i32,
        serialize_i64: i64,
        serialize_u8: u8,
        serialize_u16: u16,
        serialize_u32: u32,
        serialize_u64: u64,
        serialize_char: char,
        serialize_str: &str,
        serialize_bytes: &[u8],
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
    fn serialize_unit_struct(self, _: &'static str) -> Result<(), Stop> {
        Ok(())
    }
    fn serialize_unit_variant(self, _: &'static str, _: u32, _: &'static str) -> Result<(), Stop> {
        Ok(())
    }
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        value: &T,
    ) -> Result<(), Stop> {
        value.serialize(self)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        value: &T,
    ) -> Result<(), Stop> {
        self.child(variant.into(), value)
    }
    fn serialize_seq(self, _: Option<usize>) -> Result<Items<'a>, Stop> {
        Ok(Items {
            walk: self,
            index: 0,
        })
    }
    fn serialize_tuple(self, _: usize) -> Result<Items<'a>, Stop> {
        self.serialize_seq(None)
    }
    fn serialize_tuple_struct(self, _: &'static str, _: usize) -> Result<Items<'a>, Stop> {
        self.serialize_seq(None)
    }
    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        _: usize,
    ) -> Result<Items<'a>, Stop> {
        self.path.push(variant.into());
        self.serialize_seq(None)
    }
    fn serialize_map(self, _: Option<usize>) -> Result<Entries<'a>, Stop> {
        Ok(Entries {
            walk: self,
            key: String::new(),
        })
    }
    fn serialize_struct(self, _: &'static str, _: usize) -> Result<Fields<'a>, Stop> {
        Ok(Fields { walk: self })
    }
    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        _: usize,
    ) -> Result<Fields<'a>, Stop> {
        self.path.push(variant.into());
        Ok(Fields { walk: self })
    }
}

/// The four element-wise traits of [`Items`] differ only in their method's name and
/// in whether a variant's name is to be taken off the path at the end.
macro_rules! items {
    ($trait:ident, $method:ident, $variant:expr) => {
        impl ser::$trait for Items<'_> {
            type Ok = ();
            type Error = Stop;
            fn $method<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Stop> {
                self.item(value)
            }
            fn end(self) -> Result<(), Stop> {
                if $variant {
                    self.walk.path.pop();
                }
                Ok(())
            }
        }
    };
}

items!(SerializeSeq, serialize_element, false);
items!(SerializeTuple, serialize_element, false);
items!(SerializeTupleStruct, serialize_field, false);
items!(SerializeTupleVariant, serialize_field, true);

impl ser::SerializeMap for Entries<'_> {
    type Ok = ();
    type Error = Stop;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, key: &T) -> Result<(), Stop> {
        self.key = key_text(key);
        Ok(())
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Stop> {
        let at = std::mem::take(&mut self.key);
        self.walk.child(at, value)
    }
    fn end(self) -> Result<(), Stop> {
        Ok(())
    }
}

impl ser::SerializeStruct for Fields<'_> {
    type Ok = ();
    type Error = Stop;
    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        name: &'static str,
        value: &T,
    ) -> Result<(), Stop> {
        self.walk.child(name.into(), value)
    }
    fn end(self) -> Result<(), Stop> {
        Ok(())
    }
}

impl ser::SerializeStructVariant for Fields<'_> {
    type Ok = ();
    type Error = Stop;
    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        name: &'static str,
        value: &T,
    ) -> Result<(), Stop> {
        self.walk.child(name.into(), value)
    }
    fn end(self) -> Result<(), Stop> {
        self.walk.path.pop();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Serialize;
    use std::collections::BTreeMap;

    #[derive(Serialize)]
    struct Fit {
        name: String,
        value: Option<f64>,
        errors: BTreeMap<String, f64>,
        residuals: Vec<Residual>,
    }

    #[derive(Serialize)]
    enum Detail {
        Peak { model_hz: f64 },
    }

    #[derive(Serialize)]
    struct Residual {
        detail: Detail,
        pair: (f64, f32),
    }

    fn fit() -> Fit {
        Fit {
            name: "NaN".into(),
            value: None,
            errors: BTreeMap::from([("Kw".into(), 1.0)]),
            residuals: vec![
                Residual {
                    detail: Detail::Peak { model_hz: 90.0 },
                    pair: (1.0, 2.0),
                },
                Residual {
                    detail: Detail::Peak { model_hz: 1e300 },
                    pair: (3.0, 4.0),
                },
            ],
        }
    }

    fn refused(f: &Fit) -> String {
        match pretty(f) {
            Err(JsonError::NonFinite { path, .. }) => path,
            other => panic!("not refused: {other:?}"),
        }
    }

    #[test]
    fn finite_values_and_absent_ones_are_written_as_serde_json_writes_them() {
        let f = fit();
        assert_eq!(
            pretty(&f).unwrap(),
            serde_json::to_string_pretty(&f).unwrap()
        );
        assert_eq!(compact(&f).unwrap(), serde_json::to_string(&f).unwrap());
    }

    #[test]
    fn a_non_finite_number_is_refused_naming_its_path() {
        let mut f = fit();
        f.value = Some(f64::NAN);
        assert_eq!(refused(&f), "value");
        let mut f = fit();
        f.errors.insert("Kg".into(), f64::INFINITY);
        assert_eq!(refused(&f), "errors.Kg");
        let mut f = fit();
        f.residuals[1].detail = Detail::Peak {
            model_hz: f64::NEG_INFINITY,
        };
        assert_eq!(refused(&f), "residuals[1].detail.Peak.model_hz");
        let mut f = fit();
        f.residuals[0].pair.1 = f32::NAN;
        assert_eq!(refused(&f), "residuals[0].pair[1]");
        let e = pretty(&f).unwrap_err().to_string();
        assert!(e.contains("NaN at `residuals[0].pair[1]`"), "{e}");
        let v = serde_json::json!({"a": [1.0, 2.0]});
        assert!(pretty(&v).is_ok());
    }
}
