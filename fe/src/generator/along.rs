//! The grid lines' own support along their axes: a factor on `K_friction`
//! for each grid line that ends on the walls, the same at both its ends.
//! A line slides along its axis as one body (its members are thousands of
//! times stiffer axially than a clip), so what its two ends give together
//! is what moves its modes; clips scatter from one end to the next, and a
//! specimen's lines are held unequally. A cross-tee row at y = Y mm (ends
//! on the x walls) is `along_factor_row_yY`; a main or sub tee line at
//! x = X mm (ends on the y walls) is `along_factor_line_xX`, Y and X whole
//! millimetres. Unset, a factor is 1 and the model is unchanged.

use std::collections::BTreeMap;
use std::sync::{Mutex, OnceLock};

use super::params::{Domain, ParamInfo};

/// Prefix of a cross-tee row's factor (its ends on the x walls).
const ROW: &str = "along_factor_row_y";
/// Prefix of a y-line's factor (its ends on the y walls).
const LINE: &str = "along_factor_line_x";
/// Largest position a name may give (mm): 100 m, beyond any specimen, so
/// that names parsed from input stay few.
const MAX_POS_MM: u64 = 100_000;

/// The factor's description: unit-less, positive, 1 unless given; its prior
/// bounds (0.5 to 2, a clip half or twice as stiff as the wall's mean) are
/// a description only: a calibration sets its own prior.
fn info(name: &'static str) -> ParamInfo {
    ParamInfo {
        name,
        unit: "-",
        low: 0.5,
        high: 2.0,
        modelled: true,
        domain: Domain::Positive,
        default: Some(1.0),
    }
}

/// The one `&'static str` of each factor name (names are few: one per grid
/// line of the specimens a process builds).
fn intern(name: String) -> &'static str {
    static NAMES: OnceLock<Mutex<BTreeMap<String, &'static str>>> = OnceLock::new();
    let mut names = NAMES.get_or_init(Default::default).lock().unwrap_or_else(|e| e.into_inner());
    if let Some(s) = names.get(&name) {
        return s;
    }
    let s: &'static str = Box::leak(name.clone().into_boxed_str());
    names.insert(name, s);
    s
}

/// The factor of the cross-tee row at `y_mm` (`along_factor_row_yY`).
pub fn row_factor_name(y_mm: f64) -> &'static str {
    intern(format!("{ROW}{}", y_mm.round() as i64))
}

/// The factor of the y-line at `x_mm` (`along_factor_line_xX`).
pub fn line_factor_name(x_mm: f64) -> &'static str {
    intern(format!("{LINE}{}", x_mm.round() as i64))
}

/// The position (mm) `name` gives if it names a line's factor: a prefix and
/// a whole number of millimetres up to [`MAX_POS_MM`], written without
/// leading zeros. Allocates nothing: it is asked of every parameter name a
/// calibration sets.
fn position_mm(name: &str) -> Option<u64> {
    let digits = name.strip_prefix(ROW).or_else(|| name.strip_prefix(LINE))?;
    let plain = !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit());
    let canonical = plain && (digits == "0" || !digits.starts_with('0'));
    digits.parse().ok().filter(|p| canonical && *p <= MAX_POS_MM)
}

/// Whether `name` names a grid line's along factor.
pub fn is_along_factor(name: &str) -> bool {
    position_mm(name).is_some()
}

/// The description of `name` if it names a line's factor ([`is_along_factor`]).
pub fn along_factor_info(name: &str) -> Option<ParamInfo> {
    position_mm(name).map(|_| info(intern(name.to_string())))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_back_and_others_do_not() {
        let row = row_factor_name(1200.0);
        assert_eq!(row, "along_factor_row_y1200");
        assert_eq!(along_factor_info(row).unwrap().name, row);
        assert!(std::ptr::eq(row, row_factor_name(1200.0000001)), "interned once");
        assert_eq!(along_factor_info("along_factor_line_x0").unwrap().default, Some(1.0));
        assert!(is_along_factor(row) && !is_along_factor("K_friction"));
        for bad in [
            "along_factor_row_y",
            "along_factor_row_y-600",
            "along_factor_row_y0600",
            "along_factor_row_y600.0",
            "along_factor_row_y999999",
            "along_factor_col_x600",
            "K_friction",
        ] {
            assert!(along_factor_info(bad).is_none() && !is_along_factor(bad), "{bad}");
        }
    }
}
