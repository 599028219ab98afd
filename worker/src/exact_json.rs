//! Floats that survive JSON options bit for bit. The registry reads options
//! through `serde_json`, whose float parser may round a 17-digit value to a
//! neighbouring double; a model that must reproduce a coordinator's
//! computation exactly takes its floats as text instead:
//!
//! - [`f64_text`]: one value written as its shortest round-trip decimal
//!   string (`"0.005000000000000001"`); a plain JSON number is accepted too.
//! - [`samples_hex`]: a sample array as the hexadecimal text of its
//!   little-endian IEEE 754 bytes (16 characters per sample).

use serde::de::Error;
use serde::{Deserialize, Deserializer, Serializer};

/// One `f64` as round-trip text (a JSON number is read as well).
pub mod f64_text {
    use super::*;

    /// Writes the shortest decimal text that parses back to `v` exactly.
    pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&format!("{v:?}"))
    }

    /// Reads a decimal string (exact) or a JSON number.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Either {
            Number(f64),
            Text(String),
        }
        match Either::deserialize(d)? {
            Either::Number(v) => Ok(v),
            Either::Text(t) => t.trim().parse::<f64>().map_err(|_| {
                D::Error::custom(format!("{t:?}: expected a number (or its decimal text)"))
            }),
        }
    }
}

/// Optional sample arrays as hexadecimal little-endian bytes.
pub mod samples_hex {
    use super::*;

    /// Writes the samples' bytes as lowercase hexadecimal text.
    pub fn serialize<S: Serializer>(v: &Option<Vec<f64>>, s: S) -> Result<S::Ok, S::Error> {
        match v {
            None => s.serialize_none(),
            Some(v) => s.serialize_str(&encode(v)),
        }
    }

    /// Reads hexadecimal text back into samples.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Vec<f64>>, D::Error> {
        let text: Option<String> = Option::deserialize(d)?;
        text.map(|t| decode(&t).map_err(D::Error::custom)).transpose()
    }
}

/// Hexadecimal text of samples' little-endian bytes.
pub fn encode(v: &[f64]) -> String {
    use std::fmt::Write;
    let mut out = String::with_capacity(16 * v.len());
    for x in v {
        for b in x.to_le_bytes() {
            let _ = write!(out, "{b:02x}");
        }
    }
    out
}

/// Samples from [`encode`]'s text; an error says what is wrong.
pub fn decode(text: &str) -> Result<Vec<f64>, String> {
    let bytes = text.as_bytes();
    if !bytes.len().is_multiple_of(16) {
        return Err(format!(
            "{} hexadecimal characters: expected 16 per sample (little-endian f64 bytes)",
            bytes.len()
        ));
    }
    let digit = |c: u8| -> Result<u8, String> {
        (c as char)
            .to_digit(16)
            .map(|d| d as u8)
            .ok_or_else(|| format!("{:?}: expected a hexadecimal digit", c as char))
    };
    bytes
        .chunks_exact(16)
        .map(|chunk| {
            let mut le = [0u8; 8];
            for (k, pair) in chunk.chunks_exact(2).enumerate() {
                le[k] = digit(pair[0])? << 4 | digit(pair[1])?;
            }
            Ok(f64::from_le_bytes(le))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[derive(serde::Serialize, serde::Deserialize, Debug, PartialEq)]
    struct Probe {
        #[serde(with = "f64_text")]
        x: f64,
        #[serde(with = "samples_hex", default)]
        s: Option<Vec<f64>>,
    }

    proptest! {
        #[test]
        fn floats_and_samples_survive_json_bit_for_bit(
            x in proptest::num::f64::NORMAL | proptest::num::f64::SUBNORMAL | proptest::num::f64::ZERO,
            s in proptest::collection::vec(proptest::num::f64::ANY, 0..20),
        ) {
            let text = serde_json::to_string(&Probe { x, s: Some(s.clone()) }).unwrap();
            let back: Probe = serde_json::from_str(&text).unwrap();
            prop_assert_eq!(back.x.to_bits(), x.to_bits());
            let got: Vec<u64> = back.s.unwrap().iter().map(|v| v.to_bits()).collect();
            let want: Vec<u64> = s.iter().map(|v| v.to_bits()).collect();
            prop_assert_eq!(got, want);
        }
    }

    #[test]
    fn plain_numbers_and_bad_text_are_handled() {
        let p: Probe = serde_json::from_str(r#"{"x": 0.5}"#).unwrap();
        assert_eq!((p.x, p.s), (0.5, None));
        let e = serde_json::from_str::<Probe>(r#"{"x": "half"}"#).unwrap_err().to_string();
        assert!(e.contains("\"half\": expected a number"), "{e}");
        let e = serde_json::from_str::<Probe>(r#"{"x": 1, "s": "abc"}"#).unwrap_err().to_string();
        assert!(e.contains("3 hexadecimal characters: expected 16 per sample"), "{e}");
        let e = decode("zz00000000000000").unwrap_err();
        assert!(e.contains("'z': expected a hexadecimal digit"), "{e}");
    }
}
