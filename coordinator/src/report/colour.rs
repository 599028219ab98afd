//! Colours: a categorical palette safe for colour-blind readers (Okabe and
//! Ito, 2008, with black first for the measured record) and a diverging
//! blue-white-red scale for signed values (after ColorBrewer RdBu).

/// Categorical colours in series order.
const PALETTE: [&str; 7] =
    ["#000000", "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9"];

/// Colour of the `i`-th series (cycles after seven).
pub(crate) fn series_colour(i: usize) -> &'static str {
    PALETTE[i % PALETTE.len()]
}

/// Anchors of the diverging scale from -1 to +1 (RdBu, 7 classes, reversed).
const DIVERGING: [[u8; 3]; 7] = [
    [33, 102, 172],
    [103, 169, 207],
    [209, 229, 240],
    [247, 247, 247],
    [253, 219, 199],
    [239, 138, 98],
    [178, 24, 43],
];

/// RGB of `t` in [-1, 1] on the diverging scale (clamped; NaN is grey).
pub(crate) fn diverging_rgb(t: f64) -> [u8; 3] {
    if !t.is_finite() {
        return [190, 190, 190];
    }
    let s = (t.clamp(-1.0, 1.0) + 1.0) / 2.0 * (DIVERGING.len() - 1) as f64;
    let i = (s.floor() as usize).min(DIVERGING.len() - 2);
    let f = s - i as f64;
    let mix = |a: u8, b: u8| (a as f64 + f * (b as f64 - a as f64)).round() as u8;
    let (a, b) = (DIVERGING[i], DIVERGING[i + 1]);
    [mix(a[0], b[0]), mix(a[1], b[1]), mix(a[2], b[2])]
}

/// `#rrggbb` of an RGB triple.
pub(crate) fn hex(rgb: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", rgb[0], rgb[1], rgb[2])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn diverging_ends_and_centre() {
        assert_eq!(diverging_rgb(-1.0), DIVERGING[0]);
        assert_eq!(diverging_rgb(0.0), [247, 247, 247]);
        assert_eq!(diverging_rgb(1.0), DIVERGING[6]);
        assert_eq!(diverging_rgb(7.0), DIVERGING[6]);
        assert_eq!(hex(diverging_rgb(f64::NAN)), "#bebebe");
    }
}
