//! PFM maps, HCI's variant: `Pf`, `W H`, a scale whose sign gives the byte order (negative =
//! little-endian), then float32 rows from the bottom row up.

use super::atomic::write_atomic;
use super::error::{IoError, IoResult};
use super::raster::Raster;
use std::path::Path;

/// Reads a single-channel PFM into a top-row-first raster.
pub fn read_pfm(path: &Path) -> IoResult<Raster> {
    let bytes = std::fs::read(path).map_err(|e| IoError::os(path, e))?;
    decode_pfm(&bytes).map_err(|problem| IoError::new(path, problem))
}

/// Writes a single-channel raster as a little-endian PFM, whole or not at all.
pub fn write_pfm(path: &Path, map: &Raster) -> IoResult<()> {
    if map.channels != 1 {
        return Err(IoError::new(path, format!("PFM maps have 1 channel, this one has {}", map.channels)));
    }
    write_atomic(path, &encode_pfm(map))
}

/// The bytes of a little-endian single-channel PFM of `map`.
pub fn encode_pfm(map: &Raster) -> Vec<u8> {
    let mut out = format!("Pf\n{} {}\n-1\n", map.width, map.height).into_bytes();
    out.reserve(map.data.len() * 4);
    for row in map.data.chunks_exact(map.width.max(1)).rev() {
        for v in row {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out
}

/// Parses PFM bytes; the error says what is wrong.
pub fn decode_pfm(bytes: &[u8]) -> Result<Raster, String> {
    let mut pos = 0;
    let mut token = |what: &str| -> Result<String, String> {
        while pos < bytes.len() && bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        let start = pos;
        while pos < bytes.len() && !bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        if start == pos || pos - start > 32 {
            return Err(format!("not a PFM file: header has no {what}"));
        }
        Ok(String::from_utf8_lossy(&bytes[start..pos]).into_owned())
    };
    match token("magic")?.as_str() {
        "Pf" => {}
        "PF" => return Err("3-channel PFM (`PF`) given where a 1-channel map (`Pf`) was expected".into()),
        other => return Err(format!("not a PFM file (starts with `{}`)", other.escape_debug())),
    }
    let width: usize = token("width")?.parse().map_err(|_| "PFM header: width is not a number".to_string())?;
    let height: usize = token("height")?.parse().map_err(|_| "PFM header: height is not a number".to_string())?;
    let scale: f32 = token("scale")?.parse().map_err(|_| "PFM header: scale is not a number".to_string())?;
    if width == 0 || height == 0 || width > 1 << 16 || height > 1 << 16 {
        return Err(format!("PFM header: implausible size {width}x{height}"));
    }
    if scale == 0.0 || !scale.is_finite() {
        return Err("PFM header: scale must be a non-zero number".into());
    }
    // Exactly one whitespace byte separates the header from the data.
    pos += 1;
    let needed = width * height * 4;
    let data = bytes.get(pos..).unwrap_or(&[]);
    if data.len() < needed {
        return Err(format!("truncated PFM: {} of {} data bytes for {width}x{height}", data.len(), needed));
    }
    if data.len() > needed {
        return Err(format!("PFM has {} bytes after its {width}x{height} data", data.len() - needed));
    }
    let little = scale < 0.0;
    let mut values = vec![0.0f32; width * height];
    for (i, chunk) in data.chunks_exact(4).enumerate() {
        let raw = [chunk[0], chunk[1], chunk[2], chunk[3]];
        let v = if little { f32::from_le_bytes(raw) } else { f32::from_be_bytes(raw) };
        let (row_from_bottom, x) = (i / width, i % width);
        values[(height - 1 - row_from_bottom) * width + x] = v;
    }
    Ok(Raster { width, height, channels: 1, data: values })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_is_bit_exact_including_non_finite_values() {
        let data = vec![0.0, -0.0, 1.5, f32::MIN_POSITIVE / 3.0, f32::NAN, f32::INFINITY, -7.25e-12, 3.0e38];
        let map = Raster::from_vec(4, 2, 1, data.clone()).unwrap();
        let back = decode_pfm(&encode_pfm(&map)).unwrap();
        assert_eq!((back.width, back.height), (4, 2));
        let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&back.data), bits(&data));
    }

    #[test]
    fn rows_are_stored_bottom_first_and_big_endian_is_read() {
        // 2x2, big-endian (positive scale): stored rows bottom (3, 4) then top (1, 2).
        let mut bytes = b"Pf\n2 2\n1.0\n".to_vec();
        for v in [3.0f32, 4.0, 1.0, 2.0] {
            bytes.extend_from_slice(&v.to_be_bytes());
        }
        let map = decode_pfm(&bytes).unwrap();
        assert_eq!(map.data, vec![1.0, 2.0, 3.0, 4.0]);
    }

    #[test]
    fn truncated_and_foreign_files_are_refused() {
        let map = Raster::from_vec(3, 3, 1, vec![1.0; 9]).unwrap();
        let bytes = encode_pfm(&map);
        assert!(decode_pfm(&bytes[..bytes.len() - 1]).unwrap_err().contains("truncated"));
        assert!(decode_pfm(b"P6\n3 3\n255\n").unwrap_err().contains("not a PFM"));
        assert!(decode_pfm(b"Pf\nx 3\n-1\n").unwrap_err().contains("width"));
        assert!(decode_pfm(b"").is_err());
    }
}
