//! The exact pixel data the viewers draw: how each pass is displayed, its storage kind and
//! bytes, and the blobs that embed them (compressed, each once) at the end of the page.

use std::fmt::Write as _;

use base64::Engine as _;
use engine::plan::{TargetContent, TargetId};
use engine::{Image, ImageData};

/// How the page maps a pass's values to the screen, from what the plan says the target holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Display {
    /// 8-bit values as they are.
    Srgb8,
    /// Depth stretched over its range (the camera's depth, shadow maps).
    Depth,
    /// HDR radiance, tone-mapped for viewing.
    Hdr,
    /// Unit vectors, [-1, 1] mapped to [0, 1].
    Signed,
    /// Float values as they are.
    Linear,
}

/// How `image`, the output of `pass`, is shown.
pub(super) fn display(image: &Image, pass: TargetId) -> Display {
    if matches!(image.data, ImageData::U8(_)) {
        return Display::Srgb8;
    }
    match (pass.content(), pass) {
        (TargetContent::Depth, _) => Display::Depth,
        (TargetContent::Radiance, _) => Display::Hdr,
        (_, TargetId::GBuffer(g)) if g.holds_directions() => Display::Signed,
        _ => Display::Linear,
    }
}

/// The viewer's name of a pass's display mapping.
pub(super) fn display_mode(image: &Image, pass: TargetId) -> &'static str {
    match display(image, pass) {
        Display::Srgb8 => "srgb8",
        Display::Depth => "depth",
        Display::Hdr => "hdr",
        Display::Signed => "signed",
        Display::Linear => "linear",
    }
}

/// The exact pixel data of an image for the viewer: its storage kind (`u8`; `f16` for fp16
/// targets, whose values fp16 holds exactly; `f32` otherwise) and the bytes, little-endian.
/// `like` decides the kind, so that a golden read from an fp16 EXR is embedded like the fp16
/// output it is compared with.
pub(super) fn pixel_bytes(image: &Image, like: &Image) -> (&'static str, Vec<u8>) {
    match &image.data {
        ImageData::U8(data) => ("u8", data.clone()),
        ImageData::F32(data) if like.format == engine::backend::TextureFormat::Rgba16Float => (
            "f16",
            data.iter()
                .flat_map(|&v| half::f16::from_f32(v).to_le_bytes())
                .collect(),
        ),
        ImageData::F32(data) => ("f32", data.iter().flat_map(|v| v.to_le_bytes()).collect()),
    }
}

/// Pixel data embedded once each at the end of the page, zlib-compressed and base64-encoded in
/// `<script type="application/octet-stream" id="blob-N">` elements; identical data (backends
/// that render the same pixels) is embedded once, and compressed once.
#[derive(Default)]
pub(super) struct Blobs {
    /// Encoded blobs, in page order.
    encoded: Vec<String>,
    /// Hash and length of each blob's raw bytes, to find repeats before compressing.
    raw: Vec<(u64, usize)>,
}

impl Blobs {
    /// Adds `bytes` (unless the same bytes are there already) and returns its blob number.
    pub(super) fn add(&mut self, bytes: &[u8]) -> usize {
        use std::hash::{Hash as _, Hasher as _};
        let mut hasher = std::collections::hash_map::DefaultHasher::new();
        bytes.hash(&mut hasher);
        let id = (hasher.finish(), bytes.len());
        if let Some(same) = self.raw.iter().position(|r| *r == id) {
            return same;
        }
        use std::io::Write as _;
        // zlib's fastest level: the default level was about half of a failing `check`'s CPU
        // (arrow and chess on three backends: 6.2 -> 3.3 CPU-s) for a page 11% smaller.
        let mut encoder = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
        // Writing to a Vec cannot fail.
        let _ = encoder.write_all(bytes);
        let compressed = encoder.finish().unwrap_or_default();
        self.encoded
            .push(base64::engine::general_purpose::STANDARD.encode(compressed));
        self.raw.push(id);
        self.encoded.len() - 1
    }

    /// Base64 bytes embedded so far.
    pub(super) fn bytes(&self) -> usize {
        self.encoded.iter().map(String::len).sum()
    }

    /// The blobs as `<script>` elements.
    pub(super) fn html(&self) -> String {
        let mut out = String::new();
        for (i, blob) in self.encoded.iter().enumerate() {
            let _ = writeln!(
                out,
                "<script type=\"application/octet-stream\" id=\"blob-{i}\">{blob}</script>"
            );
        }
        out
    }
}
