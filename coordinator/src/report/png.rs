//! Inline images for the report: an 8-bit RGB PNG compressed by the `png`
//! crate (adaptive filters, deflate), as base64 (the `base64` crate) for a
//! `data:` URI.

use base64::Engine;

/// Base64 of a PNG of `width` x `height` RGB pixels (`rgb`: rows top to
/// bottom, 3 bytes per pixel, length `3 * width * height`); an error says
/// why the encoder refused (e.g. a length that does not match).
pub(crate) fn png_rgb_base64(width: u32, height: u32, rgb: &[u8]) -> Result<String, String> {
    let png = png_rgb(width, height, rgb).map_err(|e| e.to_string())?;
    Ok(base64::engine::general_purpose::STANDARD.encode(png))
}

/// The PNG file bytes.
fn png_rgb(width: u32, height: u32, rgb: &[u8]) -> Result<Vec<u8>, png::EncodingError> {
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::High);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use base64::Engine;

    /// Decodes a PNG back to (width, height, RGB bytes).
    fn decode(png: &[u8]) -> (u32, u32, Vec<u8>) {
        let mut reader = png::Decoder::new(std::io::Cursor::new(png)).read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        buf.truncate(info.buffer_size());
        (info.width, info.height, buf)
    }

    #[test]
    fn pixels_survive_the_round_trip() {
        let rgb: Vec<u8> = (0..3 * 40 * 30).map(|i| (i * 7 % 251) as u8).collect();
        let b64 = png_rgb_base64(40, 30, &rgb).unwrap();
        let png = base64::engine::general_purpose::STANDARD.decode(b64).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
        assert_eq!(decode(&png), (40, 30, rgb));
    }

    #[test]
    fn a_smooth_map_compresses() {
        let rgb: Vec<u8> = (0..200 * 100).flat_map(|i| [(i % 200) as u8, 100, 50]).collect();
        let png = png_rgb(200, 100, &rgb).unwrap();
        assert!(png.len() * 10 < rgb.len(), "{} bytes for {} raw", png.len(), rgb.len());
    }

    #[test]
    fn a_wrong_length_is_an_error_not_a_panic() {
        let e = png_rgb_base64(2, 2, &[0; 5]).unwrap_err();
        assert!(!e.is_empty());
    }
}
