//! The picture of a baked file's matrix of cells (`trisort inspect --matrix`), drawn like
//! paper 003's Figure 14, with its colour bar labelled in a small built-in digit font (no
//! system fonts on the machines that bake).

use crate::BenchError;

/// Margin around the matrix and the legend, in pixels.
pub const MARGIN: u32 = 8;
/// Largest side of the matrix area before frames are binned into pixels.
const MATRIX_PIXELS: u32 = 512;
/// Empty cells of the upper triangle.
const EMPTY: [u8; 3] = [228, 228, 228];
/// The lower triangle and the background.
const BACKGROUND: [u8; 3] = [255, 255, 255];
/// Legend text and ticks.
const INK: [u8; 3] = [0, 0, 0];

/// What [`draw_matrix`] drew.
#[derive(Clone, Debug, serde::Serialize)]
pub struct MatrixImage {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Side of one cell in pixels (1 when frames are binned).
    pub cell_pixels: u32,
    /// Frames per pixel row/column (1 unless the path has more than `MATRIX_PIXELS` frames).
    pub frames_per_pixel: u32,
    /// Non-empty cells of the file.
    pub cells: usize,
    /// Fewest triangles in a drawn (binned) cell.
    pub min_triangles: u64,
    /// Most triangles in a drawn (binned) cell.
    pub max_triangles: u64,
}

/// Draws the baked file's matrix like paper 003's Figure 14: an F×F grid whose cell (i, j),
/// row i (first frame) from the top and column j (last frame) from the left, is coloured by
/// its triangle count on a log scale (viridis, dark = few); empty cells of the upper triangle
/// are light grey, the lower triangle white. A colour bar with the counts at its ends and at
/// the powers of ten between stands to the right. Paths longer than `MATRIX_PIXELS` frames
/// are binned: a pixel then sums the cells of `frames_per_pixel`² frame pairs.
pub fn draw_matrix(
    baked: &trisort_format::Baked,
    png: &std::path::Path,
) -> Result<MatrixImage, BenchError> {
    let frames = (baked.frames.len() as u32).max(1);
    let (cell, bin) = if frames <= MATRIX_PIXELS {
        (MATRIX_PIXELS / frames, 1)
    } else {
        (1, frames.div_ceil(MATRIX_PIXELS))
    };
    let side = frames.div_ceil(bin); // grid cells per side
    let grid = side * cell;
    // Counts per grid cell (binned pairs summed).
    let mut counts = std::collections::HashMap::<(u32, u32), u64>::new();
    let cells = trisort_merger::cell_counts(baked);
    for &(i, j, n) in &cells {
        *counts.entry((i / bin, j / bin)).or_default() += n as u64;
    }
    let min = counts
        .values()
        .copied()
        .filter(|&n| n > 0)
        .min()
        .unwrap_or(1);
    let max = counts.values().copied().max().unwrap_or(1).max(min);
    let scale = |n: u64| -> f64 {
        if max == min {
            1.0
        } else {
            ((n as f64).ln() - (min as f64).ln()) / ((max as f64).ln() - (min as f64).ln())
        }
    };
    let bar_x = MARGIN + grid + 16;
    let bar_w = 16;
    let label_x = bar_x + bar_w + 6;
    let width = label_x + max.to_string().len() as u32 * DIGIT_ADVANCE + MARGIN;
    let bar_h = grid.max(120);
    let height = MARGIN + bar_h + MARGIN;
    let mut img = image::RgbImage::from_pixel(width, height, image::Rgb(BACKGROUND));
    for r in 0..side {
        for c in r..side {
            let colour = match counts.get(&(r, c)) {
                Some(&n) if n > 0 => viridis(scale(n)),
                _ => EMPTY,
            };
            fill(
                &mut img,
                MARGIN + c * cell,
                MARGIN + r * cell,
                cell,
                cell,
                colour,
            );
        }
    }
    // Colour bar: top = max, bottom = min.
    for y in 0..bar_h {
        let t = 1.0 - y as f64 / (bar_h - 1).max(1) as f64;
        fill(&mut img, bar_x, MARGIN + y, bar_w, 1, viridis(t));
    }
    let y_of = |n: u64| MARGIN + ((1.0 - scale(n)) * (bar_h - 1) as f64).round() as u32;
    let mut ticks = vec![max, min];
    let mut p = 10u64;
    while p < max {
        if p > min {
            ticks.push(p);
        }
        p = p.saturating_mul(10);
    }
    let mut taken: Vec<u32> = Vec::new();
    for (k, &n) in ticks.iter().enumerate() {
        let y = y_of(n);
        // Powers of ten that would overlap the end labels are ticked but not labelled.
        let free = taken.iter().all(|&t| t.abs_diff(y) >= DIGIT_HEIGHT + 2);
        fill(&mut img, bar_x + bar_w, y, 4, 1, INK);
        if k < 2 || free {
            let top = y
                .saturating_sub(DIGIT_HEIGHT / 2)
                .clamp(MARGIN, height - MARGIN - DIGIT_HEIGHT);
            draw_number(&mut img, label_x, top, n);
            taken.push(y);
        }
    }
    let mut bytes = std::io::Cursor::new(Vec::new());
    img.write_to(&mut bytes, image::ImageFormat::Png)
        .map_err(|e| BenchError::Invalid(format!("encoding {}: {e}", png.display())))?;
    trisort_format::container::write_bytes_atomic(png, bytes.get_ref())
        .map_err(|e| BenchError::Invalid(format!("writing {}: {e}", png.display())))?;
    Ok(MatrixImage {
        width,
        height,
        cell_pixels: cell,
        frames_per_pixel: bin,
        cells: cells.len(),
        min_triangles: min,
        max_triangles: max,
    })
}

/// Fills the `w` × `h` rectangle at (`x`, `y`) with `c`, clipped to the image.
fn fill(img: &mut image::RgbImage, x: u32, y: u32, w: u32, h: u32, c: [u8; 3]) {
    for yy in y..(y + h).min(img.height()) {
        for xx in x..(x + w).min(img.width()) {
            img.put_pixel(xx, yy, image::Rgb(c));
        }
    }
}

/// The viridis colour map at `t` in [0, 1], interpolated between five of its colours.
fn viridis(t: f64) -> [u8; 3] {
    const STOPS: [[f64; 3]; 5] = [
        [68.0, 1.0, 84.0],
        [59.0, 82.0, 139.0],
        [33.0, 145.0, 140.0],
        [94.0, 201.0, 98.0],
        [253.0, 231.0, 37.0],
    ];
    let x = t.clamp(0.0, 1.0) * (STOPS.len() - 1) as f64;
    let k = (x.floor() as usize).min(STOPS.len() - 2);
    let f = x - k as f64;
    let mut out = [0u8; 3];
    for (c, o) in out.iter_mut().enumerate() {
        *o = (STOPS[k][c] + (STOPS[k + 1][c] - STOPS[k][c]) * f).round() as u8;
    }
    out
}

/// Pixel scale of the 3×5 digit glyphs.
const DIGIT_SCALE: u32 = 2;
/// Height of a digit in pixels.
const DIGIT_HEIGHT: u32 = 5 * DIGIT_SCALE;
/// Horizontal step from one digit to the next.
const DIGIT_ADVANCE: u32 = 4 * DIGIT_SCALE;

/// Writes `n` in 3×5 pixel digits (scaled) with its top-left corner at (x, y).
fn draw_number(img: &mut image::RgbImage, x: u32, y: u32, n: u64) {
    // Rows of each digit, three bits each (most significant = left column).
    const GLYPHS: [[u8; 5]; 10] = [
        [7, 5, 5, 5, 7],
        [2, 6, 2, 2, 7],
        [7, 1, 7, 4, 7],
        [7, 1, 7, 1, 7],
        [5, 5, 7, 1, 1],
        [7, 4, 7, 1, 7],
        [7, 4, 7, 5, 7],
        [7, 1, 2, 2, 2],
        [7, 5, 7, 5, 7],
        [7, 5, 7, 1, 7],
    ];
    for (k, d) in n.to_string().bytes().enumerate() {
        let glyph = GLYPHS[(d - b'0') as usize];
        let x0 = x + k as u32 * DIGIT_ADVANCE;
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..3u32 {
                if bits >> (2 - col) & 1 == 1 {
                    fill(
                        img,
                        x0 + col * DIGIT_SCALE,
                        y + row as u32 * DIGIT_SCALE,
                        DIGIT_SCALE,
                        DIGIT_SCALE,
                        INK,
                    );
                }
            }
        }
    }
}
