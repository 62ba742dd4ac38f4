//! Reading frames and buffers back from the GPU, and the one conversion from the linear
//! `Rgba16Float` frame to 8-bit sRGB that the player and the exact reference share.

#[cfg(not(target_arch = "wasm32"))]
use std::sync::mpsc;

#[cfg(not(target_arch = "wasm32"))]
use crate::GpuError;

#[cfg(not(target_arch = "wasm32"))]
/// Maps `MAP_READ` buffers after the queue is done with them and returns their bytes, waiting
/// once for all of them.
pub fn map_read_all(
    device: &wgpu::Device,
    buffers: &[&wgpu::Buffer],
) -> Result<Vec<Vec<u8>>, GpuError> {
    let (tx, rx) = mpsc::channel();
    for (k, b) in buffers.iter().enumerate() {
        let tx = tx.clone();
        b.slice(..).map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send((k, r));
        });
    }
    drop(tx);
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| GpuError::Readback(e.to_string()))?;
    for (_, r) in rx.iter() {
        r.map_err(|e| GpuError::Readback(e.to_string()))?;
    }
    let mut out = Vec::with_capacity(buffers.len());
    for b in buffers {
        let bytes = b
            .slice(..)
            .get_mapped_range()
            .map_err(|e| GpuError::Readback(e.to_string()))?
            .to_vec();
        b.unmap();
        out.push(bytes);
    }
    Ok(out)
}

/// Polls a future that native wgpu resolves immediately (error-scope pops), yielding between
/// polls. A future still pending after a bounded number of polls gives `None`, which callers
/// take to carry no error. On wasm32 it polls once and never waits (a browser resolves the
/// future only after control returns to it; errors not caught then reach the device's
/// uncaptured-error handler).
pub fn poll_ready<F: std::future::Future>(fut: F) -> Option<F::Output> {
    let mut fut = std::pin::pin!(fut);
    let mut cx = std::task::Context::from_waker(std::task::Waker::noop());
    let polls = if cfg!(target_arch = "wasm32") {
        1
    } else {
        1000
    };
    for _ in 0..polls {
        if let std::task::Poll::Ready(v) = fut.as_mut().poll(&mut cx) {
            return Some(v);
        }
        std::thread::yield_now();
    }
    None
}

/// Little-endian halves from `Rgba16Float` bytes.
pub fn halves(bytes: &[u8]) -> Vec<u16> {
    bytes
        .chunks_exact(2)
        .map(|b| u16::from_le_bytes([b[0], b[1]]))
        .collect()
}

/// An IEEE 754 half (binary16) as f32.
pub fn f16_to_f32(h: u16) -> f32 {
    let negative = h & 0x8000 != 0;
    let exp = ((h >> 10) & 0x1f) as u32;
    let man = (h & 0x3ff) as u32;
    let magnitude = match exp {
        0 => man as f32 * (1.0 / 16_777_216.0), // subnormal: man × 2⁻²⁴
        31 => f32::from_bits(0x7f80_0000 | (man << 13)),
        _ => f32::from_bits(((exp + 112) << 23) | (man << 13)),
    };
    if negative {
        -magnitude
    } else {
        magnitude
    }
}

/// Linear to sRGB transfer function (IEC 61966-2-1) on [0, 1].
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// Converts linear `Rgba16Float` texels (4 halves each) to 8-bit sRGB RGBA with alpha 255,
/// quantizing once: the one conversion the player and the exact reference share.
///
/// With `under = None` the texels are final colours (`blend`, `depth`: already composited over
/// an opaque background). With `Some(background)` they hold premultiplied colour and coverage
/// alpha (`saturate`'s accumulation) and the background goes under them first:
/// `rgb + (1 − a)·background`.
pub fn quantize_rgba16f(halves: &[u16], under: Option<[f32; 3]>) -> Vec<u8> {
    debug_assert!(halves.len().is_multiple_of(4));
    let mut out = Vec::with_capacity(halves.len());
    for px in halves.chunks_exact(4) {
        let a = f16_to_f32(px[3]).clamp(0.0, 1.0);
        for (c, &h) in px[..3].iter().enumerate() {
            let mut v = f16_to_f32(h);
            if let Some(bg) = under {
                v += (1.0 - a) * bg[c];
            }
            out.push((linear_to_srgb(v) * 255.0).round() as u8);
        }
        out.push(255);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halves_decode() {
        assert_eq!(f16_to_f32(0x0000), 0.0);
        assert_eq!(f16_to_f32(0x3c00), 1.0);
        assert_eq!(f16_to_f32(0xc000), -2.0);
        assert_eq!(f16_to_f32(0x3800), 0.5);
        assert_eq!(f16_to_f32(0x7bff), 65504.0);
        assert_eq!(f16_to_f32(0x0001), 2f32.powi(-24));
        assert_eq!(f16_to_f32(0x7c00), f32::INFINITY);
        assert!(f16_to_f32(0x7e00).is_nan());
    }

    #[test]
    fn quantize_once_with_and_without_background() {
        // 1.0 and 0.5 linear; alpha 1.
        let px = [0x3c00, 0x3800, 0x0000, 0x3c00];
        assert_eq!(quantize_rgba16f(&px, None), vec![255, 188, 0, 255]);
        // Premultiplied nothing (alpha 0) over a background of 0.5 gives the background.
        let empty = [0, 0, 0, 0];
        assert_eq!(
            quantize_rgba16f(&empty, Some([0.5, 0.5, 1.0])),
            vec![188, 188, 255, 255]
        );
        // Alpha 1 hides the background entirely.
        assert_eq!(
            quantize_rgba16f(&px, Some([1.0; 3])),
            vec![255, 188, 0, 255]
        );
    }
}
