//! `KHR_texture_basisu` images: KTX2 files holding Basis Universal ETC1S or UASTC data,
//! transcoded to RGBA8 by the pure-Rust `basisu` crate.
//!
//! Only level 0 is read: a KTX2 file's own mip levels (gltfpack writes them) are dropped and
//! the mip chain is generated from level 0 like any other image's
//! ([`texture_with_mips`](crate::mips::texture_with_mips)). The bytes are the texels as
//! stored, whatever transfer function the file's data format descriptor names (as for PNG and
//! JPEG, the material slot decides how they are read).

use basisu::{DecodeFlags, TargetFormat, Transcoder};

/// The extension whose images these are.
pub(super) const EXTENSION: &str = "KHR_texture_basisu";

/// The MIME type of its images.
pub(super) const MIME_TYPE: &str = "image/ktx2";

/// The 12 bytes every KTX2 file starts with: `«KTX 20»\r\n\x1A\n`.
pub(super) const IDENTIFIER: [u8; 12] = [
    0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A,
];

/// The widest or tallest KTX2 image read (as large as any GPU's 2D texture limit); a larger
/// header is taken for a corrupt one before the transcoder sizes its output from it.
const MAX_SIDE: u32 = 16_384;

/// Transcodes level 0 of a KTX2 Basis Universal image to RGBA8: `(width, height, texels)`,
/// or what is wrong with it.
///
/// The header is checked first (identifier, a 2D image of at most [`MAX_SIDE`] texels a
/// side, one layer, one face, at most 32 levels, a `levelCount` of 0 read as 1) so that the
/// transcoder never sizes work from a corrupt one; the transcoder checks every offset and
/// length in the rest.
pub(super) fn decode(bytes: &[u8]) -> Result<(u32, u32, Vec<u8>), String> {
    if !bytes.starts_with(&IDENTIFIER) {
        return Err("is not a KTX2 file (it does not start with the KTX2 identifier)".into());
    }
    let word = |at: usize| {
        (bytes.get(at..at + 4)).map(|w| u32::from_le_bytes(w.try_into().expect("4 bytes")))
    };
    let (Some(width), Some(height), Some(depth), Some(layers), Some(faces), Some(levels)) =
        (word(20), word(24), word(28), word(32), word(36), word(40))
    else {
        return Err(format!(
            "KTX2 file of {} bytes is cut inside its header",
            bytes.len()
        ));
    };
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(format!(
            "KTX2 image is {width}x{height}; a texture must be 1 to {MAX_SIDE} texels a side"
        ));
    }
    if depth > 1 || layers > 1 || faces != 1 {
        return Err(format!(
            "KTX2 image has depth {depth}, {layers} layers and {faces} faces; a glTF texture \
             is one 2D image"
        ));
    }
    if levels > 32 {
        return Err(format!("KTX2 image claims {levels} mip levels"));
    }
    let bytes = one_level_at_least(bytes, levels);
    let transcoder = Transcoder::new(&bytes)
        .map_err(|e| format!("is not a Basis Universal KTX2 file the transcoder reads: {e:?}"))?;
    let texels = transcoder
        .transcode(0, TargetFormat::Rgba32, DecodeFlags::NONE)
        .map_err(|e| format!("KTX2 level 0 does not transcode: {e:?}"))?;
    if texels.len() != width as usize * height as usize * 4 {
        return Err(format!(
            "KTX2 level 0 transcodes to {} bytes, not {width}x{height} RGBA8",
            texels.len()
        ));
    }
    Ok((width, height, texels))
}

/// `bytes` as the transcoder reads them: a `levelCount` of 0 (KTX2 § 3.7: "generate the mip
/// levels at load"; the file stores level 0 alone, with one level index entry) is read as 1,
/// which the transcoder otherwise refuses as invalid data. trisort generates the chain from
/// level 0 in any case.
fn one_level_at_least(bytes: &[u8], levels: u32) -> std::borrow::Cow<'_, [u8]> {
    if levels != 0 {
        return std::borrow::Cow::Borrowed(bytes);
    }
    let mut one = bytes.to_vec();
    one[40..44].copy_from_slice(&1u32.to_le_bytes());
    std::borrow::Cow::Owned(one)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_lies_are_errors() {
        assert!(decode(b"not a ktx2").unwrap_err().contains("identifier"));
        let mut header = IDENTIFIER.to_vec();
        assert!(decode(&header)
            .unwrap_err()
            .contains("cut inside its header"));
        header.resize(80, 0);
        let set =
            |h: &mut Vec<u8>, at: usize, v: u32| h[at..at + 4].copy_from_slice(&v.to_le_bytes());
        set(&mut header, 20, 1 << 20);
        set(&mut header, 24, 4);
        assert!(decode(&header).unwrap_err().contains("1048576x4"));
        set(&mut header, 20, 4);
        set(&mut header, 36, 6);
        assert!(decode(&header).unwrap_err().contains("6 faces"));
        set(&mut header, 36, 1);
        set(&mut header, 40, 1);
        assert!(decode(&header).unwrap_err().contains("transcoder"));
        set(&mut header, 40, 33);
        assert!(decode(&header).unwrap_err().contains("33 mip levels"));
    }

    #[test]
    fn a_level_count_of_zero_is_read_as_one() {
        let mut header = IDENTIFIER.to_vec();
        header.resize(80, 7);
        header[40..44].copy_from_slice(&0u32.to_le_bytes());
        let read = one_level_at_least(&header, 0);
        assert_eq!(read[40..44], 1u32.to_le_bytes());
        assert_eq!(read[..40], header[..40]);
        assert_eq!(read[44..], header[44..]);
        assert!(matches!(
            one_level_at_least(&header, 3),
            std::borrow::Cow::Borrowed(_)
        ));
    }
}
