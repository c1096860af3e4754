//! Keys that take several forms (a number or a list, a text or a table), read by one visitor
//! that names every form a key takes when a value takes none.

use serde::de::SeqAccess;
use serde::Deserialize;

/// A value of a key that takes several forms, read by a visitor that names them all when the
/// value takes none (serde's untagged enums say only "did not match any variant"): numbers,
/// strings, lists and tables each go to `number`, `text`, `list` or `table`, those not given
/// (`None`) refused with `forms`.
macro_rules! forms {
    ($ty:ty, $forms:expr, {
        number: $num:expr, text: $text:expr, list: $list:expr, table: $table:expr $(,)?
    }) => {
        impl<'de> ::serde::Deserialize<'de> for $ty {
            fn deserialize<D: ::serde::Deserializer<'de>>(d: D) -> Result<$ty, D::Error> {
                struct V;
                impl<'de> ::serde::de::Visitor<'de> for V {
                    type Value = $ty;
                    fn expecting(&self, f: &mut ::std::fmt::Formatter) -> ::std::fmt::Result {
                        f.write_str($forms)
                    }
                    fn visit_f64<E: ::serde::de::Error>(self, v: f64) -> Result<$ty, E> {
                        let number: Option<fn(f64) -> $ty> = $num;
                        number.map(|n| n(v)).ok_or_else(|| {
                            E::invalid_type(::serde::de::Unexpected::Float(v), &self)
                        })
                    }
                    fn visit_i64<E: ::serde::de::Error>(self, v: i64) -> Result<$ty, E> {
                        let number: Option<fn(f64) -> $ty> = $num;
                        number.map(|n| n(v as f64)).ok_or_else(|| {
                            E::invalid_type(::serde::de::Unexpected::Signed(v), &self)
                        })
                    }
                    fn visit_u64<E: ::serde::de::Error>(self, v: u64) -> Result<$ty, E> {
                        self.visit_i64(v.min(i64::MAX as u64) as i64)
                    }
                    fn visit_str<E: ::serde::de::Error>(self, v: &str) -> Result<$ty, E> {
                        let text: Option<fn(String) -> $ty> = $text;
                        text.map(|t| t(v.to_string()))
                            .ok_or_else(|| E::invalid_type(::serde::de::Unexpected::Str(v), &self))
                    }
                    fn visit_seq<A: ::serde::de::SeqAccess<'de>>(
                        self,
                        seq: A,
                    ) -> Result<$ty, A::Error> {
                        let list: Option<fn(A) -> Result<$ty, A::Error>> = $list;
                        match list {
                            Some(l) => l(seq),
                            None => Err(::serde::de::Error::invalid_type(
                                ::serde::de::Unexpected::Seq,
                                &self,
                            )),
                        }
                    }
                    fn visit_map<A: ::serde::de::MapAccess<'de>>(
                        self,
                        map: A,
                    ) -> Result<$ty, A::Error> {
                        let table: Option<fn(A) -> Result<$ty, A::Error>> = $table;
                        match table {
                            Some(t) => t(map),
                            None => Err(::serde::de::Error::invalid_type(
                                ::serde::de::Unexpected::Map,
                                &self,
                            )),
                        }
                    }
                }
                d.deserialize_any(V)
            }
        }
    };
}
pub(crate) use forms;

/// The elements of a list, each read as `T`.
pub(crate) fn elements<'de, T: Deserialize<'de>, A: SeqAccess<'de>>(
    mut seq: A,
) -> Result<Vec<T>, A::Error> {
    let mut v = Vec::new();
    while let Some(x) = seq.next_element::<T>()? {
        v.push(x);
    }
    Ok(v)
}
