//! Serde for `Vec<f64>` sample arrays as one byte blob (little-endian IEEE
//! 754): the codec copies a time history once instead of visiting every
//! sample, which is what makes megabyte results cheap on shared memory.

use serde::de::{Error, Visitor};
use serde::{Deserializer, Serializer};
use std::fmt;

/// Serialises samples as their little-endian bytes.
pub fn serialize<S: Serializer>(data: &[f64], s: S) -> Result<S::Ok, S::Error> {
    if cfg!(target_endian = "little") {
        s.serialize_bytes(bytemuck::cast_slice(data))
    } else {
        let bytes: Vec<u8> = data.iter().flat_map(|x| x.to_le_bytes()).collect();
        s.serialize_bytes(&bytes)
    }
}

/// Reads samples back from their little-endian bytes.
pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
    d.deserialize_bytes(SamplesVisitor)
}

/// Samples from a little-endian byte image; `None` unless whole samples.
pub fn from_le_bytes(bytes: &[u8]) -> Option<Vec<f64>> {
    if !bytes.len().is_multiple_of(8) {
        return None;
    }
    // Written once, straight into a fresh buffer: a zeroed one (and then a
    // copy over it) writes every byte twice. On a little-endian machine the
    // compiler makes this loop a plain copy.
    let mut out = Vec::with_capacity(bytes.len() / 8);
    out.extend(bytes.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes"))));
    Some(out)
}

struct SamplesVisitor;

impl<'de> Visitor<'de> for SamplesVisitor {
    type Value = Vec<f64>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a byte string of little-endian f64 samples")
    }

    fn visit_bytes<E: Error>(self, v: &[u8]) -> Result<Vec<f64>, E> {
        from_le_bytes(v).ok_or_else(|| {
            E::custom(format!("{} bytes is not a whole number of f64 samples", v.len()))
        })
    }

    fn visit_byte_buf<E: Error>(self, v: Vec<u8>) -> Result<Vec<f64>, E> {
        self.visit_bytes(&v)
    }
}

#[cfg(test)]
mod tests {
    use super::from_le_bytes;
    use proptest::prelude::*;

    #[test]
    fn partial_samples_are_refused() {
        assert_eq!(from_le_bytes(&[0; 7]), None);
        assert_eq!(from_le_bytes(&[]), Some(vec![]));
    }

    proptest! {
        #[test]
        fn bytes_round_trip_bit_for_bit(v in proptest::collection::vec(any::<f64>(), 0..200)) {
            let bytes: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
            let back = from_le_bytes(&bytes).unwrap();
            let bits = |s: &[f64]| s.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            prop_assert_eq!(bits(&back), bits(&v));
        }
    }
}
