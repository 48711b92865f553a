//! A minimal PNG encoder for the checkerboard texture: 8-bit RGB, filter 0
//! on every row, the zlib stream made of stored (uncompressed) deflate blocks.

/// Side of the checker image in pixels; it holds 2 × 2 squares.
pub const CHECKER_SIZE: u32 = 64;

/// A `CHECKER_SIZE`² RGB PNG with 2 × 2 squares (light and dark grey), each
/// square outlined by a one-pixel darker line so grid lines are visible.
pub fn checker_png() -> Vec<u8> {
    let n = CHECKER_SIZE as usize;
    let half = n / 2;
    let mut rgb = Vec::with_capacity(n * n * 3);
    for y in 0..n {
        for x in 0..n {
            let dark = (x < half) != (y < half);
            let line = x % half == 0 || y % half == 0;
            let c: [u8; 3] = match (dark, line) {
                (_, true) => [40, 40, 40],
                (true, false) => [90, 110, 160],
                (false, false) => [235, 235, 235],
            };
            rgb.extend_from_slice(&c);
        }
    }
    encode_rgb(CHECKER_SIZE, CHECKER_SIZE, &rgb)
}

/// Encodes `width × height` 8-bit RGB pixels, rows top to bottom.
pub fn encode_rgb(width: u32, height: u32, rgb: &[u8]) -> Vec<u8> {
    let row = width as usize * 3;
    assert_eq!(rgb.len(), row * height as usize, "pixel data size");
    let mut raw = Vec::with_capacity((row + 1) * height as usize);
    for r in rgb.chunks_exact(row.max(1)).take(height as usize) {
        raw.push(0); // filter type None
        raw.extend_from_slice(r);
    }
    let mut out = Vec::new();
    out.extend_from_slice(&[0x89, b'P', b'N', b'G', 0x0D, 0x0A, 0x1A, 0x0A]);
    let mut ihdr = Vec::with_capacity(13);
    ihdr.extend_from_slice(&width.to_be_bytes());
    ihdr.extend_from_slice(&height.to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]); // depth 8, RGB, deflate, filter 0, no interlace
    chunk(&mut out, b"IHDR", &ihdr);
    chunk(&mut out, b"IDAT", &zlib_stored(&raw));
    chunk(&mut out, b"IEND", &[]);
    out
}

fn chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
    out.extend_from_slice(&(data.len() as u32).to_be_bytes());
    let start = out.len();
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    let crc = crc32(&out[start..]);
    out.extend_from_slice(&crc.to_be_bytes());
}

/// A zlib stream (RFC 1950) of stored deflate blocks (RFC 1951 §3.2.4).
pub fn zlib_stored(data: &[u8]) -> Vec<u8> {
    const MAX: usize = 65535;
    let mut out = vec![0x78, 0x01]; // CM 8, 32K window; FCHECK makes 0x7801 % 31 == 0
    if data.is_empty() {
        out.extend_from_slice(&[1, 0, 0, 0xFF, 0xFF]);
    }
    let mut blocks = data.chunks(MAX).peekable();
    while let Some(b) = blocks.next() {
        let last = blocks.peek().is_none();
        out.push(u8::from(last)); // BFINAL, BTYPE = 00
        let len = b.len() as u16;
        out.extend_from_slice(&len.to_le_bytes());
        out.extend_from_slice(&(!len).to_le_bytes());
        out.extend_from_slice(b);
    }
    out.extend_from_slice(&adler32(data).to_be_bytes());
    out
}

pub fn adler32(data: &[u8]) -> u32 {
    let (mut a, mut b) = (1u32, 0u32);
    for chunk in data.chunks(5552) {
        for &x in chunk {
            a += u32::from(x);
            b += a;
        }
        a %= 65521;
        b %= 65521;
    }
    (b << 16) | a
}

/// CRC-32 (ISO 3309, reflected, polynomial 0xEDB88320), as PNG uses.
pub fn crc32(data: &[u8]) -> u32 {
    let mut crc = 0xFFFF_FFFFu32;
    for &x in data {
        crc ^= u32::from(x);
        for _ in 0..8 {
            crc = if crc & 1 != 0 { (crc >> 1) ^ 0xEDB8_8320 } else { crc >> 1 };
        }
    }
    !crc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checksums_match_known_values() {
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
        assert_eq!(crc32(b"IEND"), 0xAE42_6082);
        assert_eq!(adler32(b"Wikipedia"), 0x11E6_0398);
        assert_eq!(adler32(&[]), 1);
    }

    #[test]
    fn stored_blocks_split_and_terminate() {
        let data = vec![7u8; 70000];
        let z = zlib_stored(&data);
        assert_eq!(&z[..2], &[0x78, 0x01]);
        assert_eq!((u16::from(z[0]) << 8 | u16::from(z[1])) % 31, 0);
        // First block: not final, 65535 bytes.
        assert_eq!(z[2], 0);
        assert_eq!(u16::from_le_bytes([z[3], z[4]]), 65535);
        assert_eq!(u16::from_le_bytes([z[5], z[6]]), 0);
        let second = 2 + 5 + 65535;
        assert_eq!(z[second], 1);
        assert_eq!(u16::from_le_bytes([z[second + 1], z[second + 2]]) as usize, 70000 - 65535);
        assert_eq!(z.len(), 2 + 5 + 65535 + 5 + (70000 - 65535) + 4);
        assert_eq!(&z[z.len() - 4..], &adler32(&data).to_be_bytes());
    }

    #[test]
    fn checker_png_layout() {
        let png = checker_png();
        assert_eq!(&png[..8], &[0x89, b'P', b'N', b'G', 0x0D, 0x0A, 0x1A, 0x0A]);
        assert_eq!(&png[12..16], b"IHDR");
        assert_eq!(u32::from_be_bytes(png[16..20].try_into().unwrap()), CHECKER_SIZE);
        let crc = u32::from_be_bytes(png[29..33].try_into().unwrap());
        assert_eq!(crc, crc32(&png[12..29]));
        assert_eq!(&png[png.len() - 12..], &[0, 0, 0, 0, b'I', b'E', b'N', b'D', 0xAE, 0x42, 0x60, 0x82]);
    }
}
