//! How a baked file is played: mode, target formats, size, glass opacity, draw path, shading; and the
//! warnings for playing it away from its recorded sample pattern.

use trisort_format::{Baked, DeviceInfo, Mode};
use trisort_gpu::{Shading, ToneMap};

/// How draws are issued.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DrawPath {
    /// One `multi_draw_indexed_indirect` per frame (needs `DownlevelFlags::INDIRECT_EXECUTION`).
    #[default]
    MultiDrawIndirect,
    /// The same ranges one `draw_indexed` at a time, read from the CPU copy of the commands.
    Direct,
}

impl DrawPath {
    /// The multi-draw where the adapter executes indirect draws, the direct fallback elsewhere.
    pub fn for_adapter(adapter: &wgpu::Adapter) -> DrawPath {
        let flags = adapter.get_downlevel_capabilities().flags;
        if flags.contains(wgpu::DownlevelFlags::INDIRECT_EXECUTION) {
            DrawPath::MultiDrawIndirect
        } else {
            DrawPath::Direct
        }
    }

    /// [`DrawPath::for_adapter`] for a device opened on `adapter`: the direct path also where
    /// the device has WebGL2-class limits (the data-texture tier, [`trisort_gpu::Bindings`]),
    /// as a browser's WebGL2 has no indirect execution, so the path is testable on any adapter.
    pub fn for_device(adapter: &wgpu::Adapter, device: &wgpu::Device) -> DrawPath {
        match trisort_gpu::Bindings::for_limits(&device.limits()) {
            trisort_gpu::Bindings::Textures => DrawPath::Direct,
            trisort_gpu::Bindings::Storage => DrawPath::for_adapter(adapter),
        }
    }

    /// A short name (`multi-draw-indirect`, `direct`).
    pub fn name(self) -> &'static str {
        match self {
            DrawPath::MultiDrawIndirect => "multi-draw-indirect",
            DrawPath::Direct => "direct",
        }
    }
}

/// Everything [`crate::Player::new`] needs besides the file: the caller's target and how to
/// play.
#[derive(Clone, Debug, PartialEq)]
pub struct PlayerConfig {
    /// Format of the colour attachment the player draws into.
    pub color_format: wgpu::TextureFormat,
    /// Format of the pass's depth attachment, if it has one. Required by [`Mode::Depth`]; in
    /// the other modes the pipeline neither tests nor writes depth.
    pub depth_format: Option<wgpu::TextureFormat>,
    /// MSAA sample count of the attachments.
    pub sample_count: u32,
    /// Target size in pixels (width, height): sets the projection's aspect ratio.
    pub size: (u32, u32),
    /// Compositing mode.
    pub mode: Mode,
    /// Opacity of transmissive glass; `None` plays the recorded opacity.
    pub glass_opacity: Option<f32>,
    /// How draws are issued ([`DrawPath::for_adapter`] picks the right one).
    pub draw_path: DrawPath,
    /// The device it is played on, as a file records it
    /// (`trisort_gpu::device_info`), to warn when it is not the recording device.
    /// `None` skips that check.
    pub device: Option<DeviceInfo>,
    /// Surface model: [`Shading::Pbr`] lit by the file's environment (the default), or
    /// [`Shading::Basic`]: one view-space light plus ambient, ignoring every map (cheap, and
    /// independent of the environment).
    pub shading: Shading,
    /// Tone map of [`Shading::Pbr`].
    pub tone_map: ToneMap,
    /// Upload block-compressed textures as their decoded RGBA8 texels even where the device
    /// samples their blocks ([`crate::Player::texture_uploads`]; `play --decode-textures`):
    /// what a device without the compression feature draws, for comparison and tests.
    pub decode_textures: bool,
}

impl PlayerConfig {
    /// Plays `baked` as recorded (size, sample count, glass opacity) in `blend` mode into a
    /// `color_format` target without depth, with one multi-draw per frame.
    pub fn recorded(baked: &Baked, color_format: wgpu::TextureFormat) -> PlayerConfig {
        PlayerConfig {
            color_format,
            depth_format: None,
            sample_count: baked.settings.samples.max(1),
            size: (baked.settings.width, baked.settings.height),
            mode: Mode::Blend,
            glass_opacity: None,
            draw_path: DrawPath::MultiDrawIndirect,
            device: None,
            shading: Shading::Pbr,
            tone_map: ToneMap::Neutral,
            decode_textures: false,
        }
    }

    /// [`PlayerConfig::recorded`] with the draw path and device taken from `adapter`.
    pub fn for_adapter(
        baked: &Baked,
        adapter: &wgpu::Adapter,
        color_format: wgpu::TextureFormat,
    ) -> PlayerConfig {
        PlayerConfig {
            draw_path: DrawPath::for_adapter(adapter),
            device: Some(trisort_gpu::device_info(&adapter.get_info())),
            ..PlayerConfig::recorded(baked, color_format)
        }
    }

    /// The glass opacity that will be played.
    pub fn glass_opacity_for(&self, baked: &Baked) -> f32 {
        self.glass_opacity.unwrap_or(baked.settings.glass_opacity)
    }
}

/// The warnings for playing `baked` with `config`: another size, sample count or device than
/// recorded (visibility and order are exact only at the recorded sample pattern), glass more
/// transparent than recorded (surfaces hidden behind it at recording time were left out: holes),
/// or a depth-only bake played without the depth test.
pub fn playback_warnings(baked: &Baked, config: &PlayerConfig) -> Vec<String> {
    let rec = &baked.settings;
    let mut out = Vec::new();
    if config.size != (rec.width, rec.height) {
        out.push(format!(
            "played at {}x{}, recorded at {}x{}: the sorted order is exact only at the recorded size",
            config.size.0, config.size.1, rec.width, rec.height
        ));
    }
    if config.sample_count != rec.samples {
        out.push(format!(
            "played with {} sample(s) per pixel, recorded with {}: the sorted order is exact only at the recorded sample pattern",
            config.sample_count, rec.samples
        ));
    }
    if let Some(dev) = &config.device {
        if dev.adapter != baked.device.adapter
            || dev.backend != baked.device.backend
            || dev.driver != baked.device.driver
        {
            out.push(format!(
                "played on {} ({}, {}), recorded on {} ({}, {}): rasterization may differ slightly",
                dev.adapter,
                dev.backend,
                dev.driver,
                baked.device.adapter,
                baked.device.backend,
                baked.device.driver
            ));
        }
    }
    let glass = config.glass_opacity_for(baked);
    let has_glass = baked
        .geometry
        .materials
        .iter()
        .any(|m| m.transmission > 0.0);
    if has_glass && glass < rec.glass_opacity {
        out.push(format!(
            "glass opacity {glass} is below the recorded {}: surfaces that the glass hid when recording were left out of the file and can show as holes",
            rec.glass_opacity
        ));
    }
    if baked.merge.depth_only && config.mode != Mode::Depth {
        out.push(format!(
            "a depth-only bake is ordered only where depth mode needs it (ties, and behind translucent fragments); played in {} mode it is not sorted",
            config.mode
        ));
    }
    out
}
