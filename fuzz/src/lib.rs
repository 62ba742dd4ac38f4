//! Shared by the decoder fuzz targets: an input is a mode byte and a body. Mode bit 0 clear:
//! the body is a whole file (headers, lengths, checksum: the container's own checks). Set:
//! the body is a postcard payload, wrapped here in a correct container (compressed, with the
//! right lengths and checksum), so that the fuzzer reaches postcard decoding and the
//! structure checks instead of stopping at the checksum.

use trisort_format::container::FileKind;

/// The container bytes to feed the reader for fuzz input `data`.
pub fn file_bytes(kind: FileKind, data: &[u8]) -> Option<Vec<u8>> {
    let (&mode, body) = data.split_first()?;
    if mode & 1 == 0 {
        return Some(body.to_vec());
    }
    Some(trisort_format::container::encode_payload(kind, body))
}
