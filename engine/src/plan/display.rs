//! The plan as text: the `Display` of [`RenderPlan`] (what the insta snapshots hold) and of
//! [`LightingVariant`] (one line per lighting draw).

use std::fmt;

use crate::backend::TextureFormat;
use crate::scene::ShadowFilter;

use super::{LightingVariant, PassId, RenderPlan, ShadowKind, TargetId};

fn format_name(format: TextureFormat) -> &'static str {
    match format {
        TextureFormat::Rgba8Unorm => "rgba8",
        TextureFormat::Rgba8UnormSrgb => "rgba8-srgb",
        TextureFormat::Rgba16Float => "rgba16f",
        TextureFormat::Rgba32Float => "rgba32f",
        TextureFormat::R32Float => "r32f",
        TextureFormat::Depth32Float => "depth32f",
    }
}

impl RenderPlan {
    /// What pass `id` writes, as text: each target's name, size and format, comma-separated
    /// (`shadow_0 1536x1024 depth32f`). A speed floor writes the same targets, so a pass's
    /// ratio to its floor compares only between frames where this is the same.
    pub fn written_targets(&self, id: PassId) -> Option<String> {
        let pass = self.pass(id)?;
        let written: Vec<String> = pass
            .writes
            .iter()
            .filter_map(|&t| self.target(t))
            .map(|t| {
                format!(
                    "{} {}x{} {}",
                    t.id,
                    t.width,
                    t.height,
                    format_name(t.format)
                )
            })
            .collect();
        Some(written.join(", "))
    }
}

/// Targets' names, comma-separated.
fn names(targets: &[TargetId]) -> String {
    let names: Vec<String> = targets.iter().map(ToString::to_string).collect();
    names.join(", ")
}

impl fmt::Display for RenderPlan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "scene {} at {}x{}", self.scene, self.width, self.height)?;
        writeln!(f, "targets:")?;
        for t in &self.targets {
            writeln!(
                f,
                "  {:<17} {:<10} {:<9} {}",
                t.id.to_string(),
                format_name(t.format),
                format!("{}x{}", t.width, t.height),
                t.contents
            )?;
        }
        writeln!(f, "passes:")?;
        for (i, p) in self.passes.iter().enumerate() {
            writeln!(f, "  {}. {:<21} {}", i + 1, p.id.to_string(), p.detail)?;
            if let PassId::Lighting(model) = p.id {
                if let Some(r) = self
                    .lighting
                    .iter()
                    .find(|l| l.model == model)
                    .and_then(|l| l.rect)
                {
                    writeln!(
                        f,
                        "       pixels {}..{} x {}..{} (its objects' screen bounds)",
                        r.x,
                        r.x + r.width,
                        r.y,
                        r.y + r.height
                    )?;
                }
                for (d, draw) in self.lighting_draws(model).iter().enumerate() {
                    writeln!(f, "       draw {}: {}", d + 1, draw.variant)?;
                }
            }
            if !p.reads.is_empty() {
                writeln!(f, "       reads  {}", names(&p.reads))?;
            }
            if !p.writes.is_empty() {
                writeln!(f, "       writes {}", names(&p.writes))?;
            }
        }
        Ok(())
    }
}

impl fmt::Display for LightingVariant {
    /// e.g. `1 directional, shadow directional pcf3, clearcoat, gbuffer camera-relative/fp16`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let types = match (self.directional, self.point) {
            (true, true) => " directional+point",
            (true, false) => " directional",
            (false, true) => " point",
            (false, false) => "",
        };
        write!(f, "{}{types} light(s)", self.lights)?;
        if let Some((kind, filter)) = self.shadow {
            let kind = match kind {
                ShadowKind::Directional => "directional",
                ShadowKind::Point => "point",
            };
            write!(f, ", shadow {kind} {}", filter.name())?;
            if self.vogel_samples > 0 && filter == ShadowFilter::Vogel {
                write!(f, " ({} samples)", self.vogel_samples)?;
            }
        }
        if self.ibl && self.ibl_samples > 0 {
            write!(
                f,
                ", ibl ({} samples, footprint {})",
                self.ibl_samples, self.ibl_footprint
            )?;
        }
        if self.ibl && self.ibl_dominant == crate::scene::DominantDirection::Frostbite {
            write!(f, ", ibl frostbite dominant direction")?;
        }
        if self.ibl && self.ibl_anisotropic_taps {
            write!(f, ", ibl anisotropic taps")?;
        }
        if self.ibl && self.ibl_anisotropic_samples > 0 {
            write!(
                f,
                ", ibl ({} samples on anisotropic pixels, footprint {})",
                self.ibl_anisotropic_samples, self.ibl_footprint
            )?;
        }
        for (on, name) in [
            (self.sun_disc, "sun disc"),
            (self.ibl && self.ibl_samples == 0, "ibl"),
            (self.clearcoat, "clearcoat"),
            (self.anisotropy, "anisotropy"),
            (self.ambient_occlusion, "ambient occlusion"),
            (self.input_floor, "input floor"),
            (self.keep_inputs, "keep inputs"),
        ] {
            if on {
                write!(f, ", {name}")?;
            }
        }
        write!(f, ", gbuffer {}", self.gbuffer.name())
    }
}
