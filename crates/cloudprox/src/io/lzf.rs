//! LZF compression as used by PCD `binary_compressed` (liblzf's format).
//!
//! A stream is a sequence of runs, each starting with a control byte `c`:
//! - `c < 32`: a literal run, the next `c + 1` bytes are copied as they are;
//! - otherwise a back-reference: length `l = c >> 5` (when `l == 7` the next
//!   byte is added to it), then one byte `b`; the `l + 2` bytes starting
//!   `((c & 31) << 8 | b) + 1` bytes back in the output are copied (they may
//!   overlap the bytes being written).

/// Longest literal run.
const MAX_LITERAL: usize = 32;
/// Longest back-reference: `7 + 255 + 2`.
const MAX_MATCH: usize = 264;
/// Farthest back-reference: 13 bits of offset, plus one.
const MAX_OFFSET: usize = 1 << 13;
const HASH_BITS: u32 = 14;

/// Decompresses `input`, which must expand to exactly `expected_len` bytes.
///
/// # Errors
/// A message naming the problem and the offset in `input`: a literal run or a
/// back-reference's offset byte past the end of the input, a back-reference to
/// before the start of the output, output longer or shorter than expected.
pub(crate) fn decompress(input: &[u8], expected_len: usize) -> Result<Vec<u8>, String> {
    // Never allocate more than the input could expand to (each 2-byte
    // back-reference makes at most 264 bytes).
    let bound = input.len().saturating_mul(MAX_MATCH / 2 + 1);
    let mut out: Vec<u8> = Vec::with_capacity(expected_len.min(bound));
    let mut ip = 0;
    while ip < input.len() {
        let ctrl = input[ip] as usize;
        let at = ip;
        ip += 1;
        if ctrl < 32 {
            let n = ctrl + 1;
            if n > input.len() - ip {
                return Err(format!(
                    "LZF literal run of {n} bytes at compressed offset {at} runs past the end of the compressed data ({} bytes)",
                    input.len()
                ));
            }
            if out.len() + n > expected_len {
                return Err(format!(
                    "LZF data expands to more than the {expected_len} bytes the header gives (at compressed offset {at})"
                ));
            }
            out.extend_from_slice(&input[ip..ip + n]);
            ip += n;
        } else {
            let mut len = ctrl >> 5;
            if len == 7 {
                let Some(&extra) = input.get(ip) else {
                    return Err(format!(
                        "LZF back-reference at compressed offset {at} is cut off (no length byte)"
                    ));
                };
                len += extra as usize;
                ip += 1;
            }
            let Some(&low) = input.get(ip) else {
                return Err(format!(
                    "LZF back-reference at compressed offset {at} is cut off (no offset byte)"
                ));
            };
            ip += 1;
            let back = (((ctrl & 31) << 8) | low as usize) + 1;
            let len = len + 2;
            if back > out.len() {
                return Err(format!(
                    "LZF back-reference at compressed offset {at} points {back} bytes back, but only {} bytes were written",
                    out.len()
                ));
            }
            if out.len() + len > expected_len {
                return Err(format!(
                    "LZF data expands to more than the {expected_len} bytes the header gives (at compressed offset {at})"
                ));
            }
            let start = out.len() - back;
            for k in 0..len {
                let b = out[start + k];
                out.push(b);
            }
        }
    }
    if out.len() != expected_len {
        return Err(format!(
            "LZF data expands to {} bytes, but the header gives {expected_len}",
            out.len()
        ));
    }
    Ok(out)
}

fn hash3(b: &[u8]) -> usize {
    let v = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
    (v.wrapping_mul(2_654_435_761) >> (32 - HASH_BITS)) as usize
}

fn flush_literals(out: &mut Vec<u8>, literals: &[u8]) {
    for chunk in literals.chunks(MAX_LITERAL) {
        out.push((chunk.len() - 1) as u8);
        out.extend_from_slice(chunk);
    }
}

/// Compresses `input` (greedy matching over a hash table of 3-byte sequences).
pub(crate) fn compress(input: &[u8]) -> Vec<u8> {
    let n = input.len();
    let mut out = Vec::with_capacity(n / 2 + 16);
    let mut table = vec![usize::MAX; 1 << HASH_BITS];
    let mut lit_start = 0;
    let mut i = 0;
    while i + 2 < n {
        let h = hash3(&input[i..]);
        let cand = table[h];
        table[h] = i;
        if cand != usize::MAX
            && cand < i
            && i - cand <= MAX_OFFSET
            && input[cand..cand + 3] == input[i..i + 3]
        {
            let max = MAX_MATCH.min(n - i);
            let mut len = 3;
            while len < max && input[cand + len] == input[i + len] {
                len += 1;
            }
            flush_literals(&mut out, &input[lit_start..i]);
            let off = i - cand - 1;
            let l = len - 2;
            if l < 7 {
                out.push(((l << 5) | (off >> 8)) as u8);
            } else {
                out.push(((7 << 5) | (off >> 8)) as u8);
                out.push((l - 7) as u8);
            }
            out.push((off & 0xff) as u8);
            // Index the positions inside the match so later data can refer to them.
            for k in i + 1..(i + len).min(n.saturating_sub(2)) {
                table[hash3(&input[k..])] = k;
            }
            i += len;
            lit_start = i;
        } else {
            i += 1;
        }
    }
    flush_literals(&mut out, &input[lit_start..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn round_trip(data: &[u8]) {
        let c = compress(data);
        assert_eq!(decompress(&c, data.len()).unwrap(), data);
    }

    #[test]
    fn round_trips() {
        round_trip(b"");
        round_trip(b"a");
        round_trip(b"ab");
        round_trip(b"abcabcabcabcabcabcabcabcabcabcabcabc");
        round_trip(&[0u8; 10_000]);
        let noise: Vec<u8> = (0..5000u32)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
            .collect();
        round_trip(&noise);
        let mixed: Vec<u8> = (0..20_000u32).map(|i| ((i / 7) % 13) as u8).collect();
        round_trip(&mixed);
    }

    #[test]
    fn compresses_repetition() {
        let c = compress(&[7u8; 10_000]);
        assert!(c.len() < 200, "{} bytes", c.len());
    }

    #[test]
    fn decodes_hand_made_streams() {
        // Literal run "abc", then a back-reference of length 5 to offset 3 (overlapping).
        let stream = [2, b'a', b'b', b'c', (3 << 5), 2];
        assert_eq!(decompress(&stream, 8).unwrap(), b"abcabcab");
        // Long back-reference: ctrl len 7 + extra 10 -> 19 bytes, offset 1.
        let stream = [0, b'z', (7 << 5), 10, 0];
        assert_eq!(decompress(&stream, 20).unwrap(), vec![b'z'; 20]);
        // Back-reference with a high offset bit pattern: offset ((1 << 8) | 0) + 1 = 257.
        let mut stream = Vec::new();
        let lit: Vec<u8> = (0..=255u8).chain([0u8]).collect();
        for chunk in lit.chunks(32) {
            stream.push((chunk.len() - 1) as u8);
            stream.extend_from_slice(chunk);
        }
        stream.extend_from_slice(&[(1 << 5) | 1, 0]);
        let out = decompress(&stream, 260).unwrap();
        assert_eq!(&out[257..260], &[0, 1, 2]);
    }

    #[test]
    fn rejects_corrupt_streams() {
        let e = decompress(&[5, b'a'], 6).unwrap_err();
        assert!(e.contains("literal run"), "{e}");
        let e = decompress(&[(1 << 5), 0], 3).unwrap_err();
        assert!(e.contains("points 1 bytes back"), "{e}");
        let e = decompress(&[0, b'a', (7 << 5)], 30).unwrap_err();
        assert!(e.contains("no length byte"), "{e}");
        let e = decompress(&[0, b'a', (1 << 5)], 30).unwrap_err();
        assert!(e.contains("no offset byte"), "{e}");
        let e = decompress(&[1, b'a', b'b'], 1).unwrap_err();
        assert!(e.contains("more than"), "{e}");
        let e = decompress(&[1, b'a', b'b'], 3).unwrap_err();
        assert!(e.contains("expands to 2 bytes"), "{e}");
    }
}
