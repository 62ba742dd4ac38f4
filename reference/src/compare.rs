//! Comparing a frame with its reference: pure functions over 8-bit sRGB RGBA images.
//!
//! Only the colour channels are compared (every frame has alpha 255). A pixel is *ordered*
//! when none of its samples is unordered (see [`crate::UnorderedEdges`]); the `_ordered` figures
//! ignore the others.

use serde::Serialize;

/// How a frame differs from its reference.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Comparison {
    /// Pixels with any colour channel different.
    pub pixels_differing: u64,
    /// Ordered pixels with any colour channel different.
    pub pixels_differing_ordered: u64,
    /// Ordered pixels with a colour channel more than 1/255 off (the recorded-pattern gate of
    /// `blend` and `saturate`).
    pub pixels_over_tolerance_ordered: u64,
    /// Largest colour-channel difference anywhere, in 1/255 units.
    pub max_channel_diff: u8,
    /// Largest colour-channel difference on ordered pixels, in 1/255 units.
    pub max_channel_diff_ordered: u8,
    /// Peak signal-to-noise ratio over the colour channels in dB, `10·log10(255² / MSE)`;
    /// identical images report 100.
    pub psnr: f64,
    /// Mean of the LDR-FLIP error map (NVIDIA's FLIP, Andersson et al. 2020, through the
    /// `nv-flip` crate, at its default 67 pixels per degree): 0 identical, 1 worst.
    pub flip_mean: f64,
}

/// The PSNR reported for identical images.
pub const PSNR_IDENTICAL: f64 = 100.0;

/// Compares `test` with `reference` (both `width × height` RGBA8), `unordered` per pixel
/// (empty: every pixel ordered).
///
/// Panics when the lengths disagree.
pub fn compare(
    test: &[u8],
    reference: &[u8],
    width: u32,
    height: u32,
    unordered: &[bool],
) -> Comparison {
    let pixels = width as usize * height as usize;
    assert_eq!(test.len(), pixels * 4, "test image size");
    assert_eq!(reference.len(), pixels * 4, "reference image size");
    assert!(unordered.is_empty() || unordered.len() == pixels);
    let mut c = Comparison::default();
    let mut squared = 0u64;
    for p in 0..pixels {
        let a = &test[p * 4..p * 4 + 3];
        let b = &reference[p * 4..p * 4 + 3];
        let d = channel_diff(a, b);
        squared += a
            .iter()
            .zip(b)
            .map(|(x, y)| (x.abs_diff(*y) as u64).pow(2))
            .sum::<u64>();
        let ordered = !unordered.get(p).copied().unwrap_or(false);
        if d > 0 {
            c.pixels_differing += 1;
            c.max_channel_diff = c.max_channel_diff.max(d);
            if ordered {
                c.pixels_differing_ordered += 1;
                c.max_channel_diff_ordered = c.max_channel_diff_ordered.max(d);
                if d > 1 {
                    c.pixels_over_tolerance_ordered += 1;
                }
            }
        }
    }
    c.psnr = if squared == 0 {
        PSNR_IDENTICAL
    } else {
        let mse = squared as f64 / (pixels as f64 * 3.0);
        (10.0 * (255.0f64 * 255.0 / mse).log10()).min(PSNR_IDENTICAL)
    };
    c.flip_mean = if squared == 0 {
        0.0
    } else {
        flip_mean(test, reference, width, height)
    };
    c
}

/// The largest colour-channel difference of two pixels (RGB or RGBA; alpha ignored), in
/// 1/255 units.
fn channel_diff(a: &[u8], b: &[u8]) -> u8 {
    a[..3]
        .iter()
        .zip(&b[..3])
        .map(|(x, y)| x.abs_diff(*y))
        .max()
        .unwrap_or(0)
}

/// Pixels of `test` more than `tolerance` (1/255 units) off `reference` (both RGBA8), told
/// apart: those with a hole sample (`holes`, per pixel), and the ordered rest (not
/// `unordered`, per pixel; empty: every pixel ordered). Returns (hole pixels, order-error
/// pixels).
pub fn holes_and_order_errors(
    test: &[u8],
    reference: &[u8],
    unordered: &[bool],
    holes: &[bool],
    tolerance: u8,
) -> (u64, u64) {
    let (mut hole, mut order) = (0u64, 0u64);
    for (p, (a, b)) in test
        .chunks_exact(4)
        .zip(reference.chunks_exact(4))
        .enumerate()
    {
        if channel_diff(a, b) <= tolerance {
            continue;
        }
        if holes.get(p).copied().unwrap_or(false) {
            hole += 1;
        } else if !unordered.get(p).copied().unwrap_or(false) {
            order += 1;
        }
    }
    (hole, order)
}

fn rgb(rgba: &[u8]) -> Vec<u8> {
    rgba.chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect()
}

/// Mean LDR-FLIP error of `test` against `reference` (RGBA8, alpha ignored).
pub fn flip_mean(test: &[u8], reference: &[u8], width: u32, height: u32) -> f64 {
    let r = nv_flip::FlipImageRgb8::with_data(width, height, &rgb(reference));
    let t = nv_flip::FlipImageRgb8::with_data(width, height, &rgb(test));
    let map = nv_flip::flip(r, t, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    nv_flip::FlipPool::from_image(&map).mean() as f64
}

/// A difference image for people: the reference in grey at a third of its brightness, pixels
/// differing by 1/255 in blue, by more in red scaled by the difference (saturating at 16/255),
/// unordered pixels that differ in yellow.
pub fn difference_image(test: &[u8], reference: &[u8], unordered: &[bool]) -> Vec<u8> {
    let mut out = Vec::with_capacity(test.len());
    for (p, (a, b)) in test
        .chunks_exact(4)
        .zip(reference.chunks_exact(4))
        .enumerate()
    {
        let d = channel_diff(a, b);
        let grey = ((b[0] as u32 + b[1] as u32 + b[2] as u32) / 9) as u8;
        let px = if d == 0 {
            [grey, grey, grey, 255]
        } else if unordered.get(p).copied().unwrap_or(false) {
            [255, 220, 0, 255]
        } else if d == 1 {
            [40, 80, 255, 255]
        } else {
            [(128 + (d as u32).min(16) * 8).min(255) as u8, 0, 0, 255]
        };
        out.extend_from_slice(&px);
    }
    out
}

/// The unordered mask as an image: white where a pixel has an unordered sample, black
/// elsewhere.
pub fn mask_image(unordered: &[bool]) -> Vec<u8> {
    unordered
        .iter()
        .flat_map(|&u| {
            if u {
                [255, 255, 255, 255]
            } else {
                [0, 0, 0, 255]
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(px: &[[u8; 3]]) -> Vec<u8> {
        px.iter().flat_map(|p| [p[0], p[1], p[2], 255]).collect()
    }

    #[test]
    fn holes_and_order_errors_are_told_apart() {
        let reference = image(&[[10, 10, 10], [10, 10, 10], [10, 10, 10], [10, 10, 10]]);
        let test = image(&[[40, 10, 10], [10, 40, 10], [10, 10, 40], [11, 10, 10]]);
        // Pixel 0 has a hole sample, pixel 1 is unordered, pixel 2 is ordered and off, pixel 3
        // is within the tolerance.
        let unordered = [false, true, false, false];
        let holes = [true, false, false, false];
        let got = holes_and_order_errors(&test, &reference, &unordered, &holes, 1);
        assert_eq!(got, (1, 1));
        // Depth mode's tolerance is 0: pixel 3 counts too.
        assert_eq!(
            holes_and_order_errors(&test, &reference, &unordered, &holes, 0),
            (1, 2)
        );
    }

    #[test]
    fn identical_images() {
        let a = image(&[[10, 20, 30], [200, 100, 0]]);
        let c = compare(&a, &a, 2, 1, &[]);
        assert_eq!(c.pixels_differing, 0);
        assert_eq!(c.max_channel_diff, 0);
        assert_eq!(c.psnr, PSNR_IDENTICAL);
        assert_eq!(c.flip_mean, 0.0);
    }

    #[test]
    fn ordered_and_unordered_pixels_are_told_apart() {
        let reference = image(&[[10, 10, 10], [10, 10, 10], [10, 10, 10], [10, 10, 10]]);
        let test = image(&[[11, 10, 10], [10, 10, 40], [10, 13, 10], [10, 10, 10]]);
        // Pixel 1 is unordered.
        let c = compare(&test, &reference, 2, 2, &[false, true, false, false]);
        assert_eq!(c.pixels_differing, 3);
        assert_eq!(c.pixels_differing_ordered, 2);
        assert_eq!(c.pixels_over_tolerance_ordered, 1);
        assert_eq!(c.max_channel_diff, 30);
        assert_eq!(c.max_channel_diff_ordered, 3);
        // MSE = (1 + 900 + 9) / 12.
        let mse = 910.0 / 12.0;
        assert!((c.psnr - 10.0 * (65025.0f64 / mse).log10()).abs() < 1e-9);
        assert!(c.flip_mean > 0.0 && c.flip_mean < 1.0);
    }

    #[test]
    fn flip_grows_with_the_difference() {
        let w = 16u32;
        let reference = vec![128u8; (w * w * 4) as usize];
        let mut small = reference.clone();
        let mut large = reference.clone();
        for p in 0..(w * w) as usize {
            small[p * 4] = 131;
            large[p * 4] = 255;
        }
        let s = flip_mean(&small, &reference, w, w);
        let l = flip_mean(&large, &reference, w, w);
        assert!(s > 0.0 && l > s, "small {s}, large {l}");
    }

    #[test]
    fn difference_image_marks_each_kind() {
        let reference = image(&[[90, 90, 90], [10, 10, 10], [10, 10, 10], [10, 10, 10]]);
        let test = image(&[[90, 90, 90], [11, 10, 10], [10, 30, 10], [50, 10, 10]]);
        let d = difference_image(&test, &reference, &[false, false, false, true]);
        assert_eq!(&d[0..4], &[30, 30, 30, 255]);
        assert_eq!(&d[4..8], &[40, 80, 255, 255]);
        assert_eq!(&d[8..12], &[255, 0, 0, 255]);
        assert_eq!(&d[12..16], &[255, 220, 0, 255]);
        assert_eq!(
            mask_image(&[true, false]),
            vec![255, 255, 255, 255, 0, 0, 0, 255]
        );
    }
}
