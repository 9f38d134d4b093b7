//! A model as people's files come (`scenes/models/crate.toml`: CRLF, Latin-1 comments in the
//! OBJ and the MTL, a nameless and an undefined `usemtl`, maps in JPEG, TGA, 16-bit PNG and BMP)
//! loads with a warning per untidy thing, each naming its file and line, and renders on every
//! available backend with its textures.

use crate::common;
use engine::assets::{srgb_to_linear, ColorSpace, TextureCache};
use engine::plan::{GBufferTarget, TargetId};
use engine::renderer::{self, Readback};

fn crate_scene() -> engine::scene_file::LoadedScene {
    harness::use_ibl_cache();
    harness::load_scene(
        harness::workspace_root()
            .join("scenes/models/crate.toml")
            .to_str()
            .unwrap(),
    )
    .unwrap()
}

#[test]
fn the_untidy_crate_loads_with_a_warning_per_untidy_thing() {
    let loaded = crate_scene();
    let expected = [
        "crate.obj:2: not UTF-8 at byte 21",
        "crate.mtl:1: not UTF-8 at byte 37",
        "crate.obj:30: `usemtl` without a name; the faces after it use the default material",
        "crate.obj:33: usemtl `shipping_label` names no material in the loaded MTL files",
    ];
    for needle in expected {
        assert_eq!(
            loaded
                .warnings
                .iter()
                .filter(|w| w.contains(needle))
                .count(),
            1,
            "`{needle}` once in {:#?}",
            loaded.warnings
        );
    }
    // The four maps, in four formats, each decoded once, the normal map at 16 bits.
    let mut textures = TextureCache::new();
    let model = engine::assets::load_obj(
        &harness::workspace_root().join("scenes/assets/crate.obj"),
        &mut textures,
    )
    .unwrap();
    let summary = model.summary(&textures);
    let described: Vec<(String, u32, u32, u8, ColorSpace)> = summary
        .textures
        .iter()
        .map(|t| {
            let file = t.path.rsplit('/').next().unwrap_or_default().to_owned();
            (file, t.width, t.height, t.bits, t.color_space)
        })
        .collect();
    assert_eq!(
        described,
        [
            ("crate_albedo.jpg".into(), 120, 75, 8, ColorSpace::Srgb),
            ("crate_roughness.tga".into(), 64, 64, 8, ColorSpace::Linear),
            ("crate_normal.png".into(), 64, 64, 16, ColorSpace::Linear),
            ("crate_specular.bmp".into(), 64, 64, 8, ColorSpace::Linear),
        ]
    );
    assert_eq!(loaded.textures_decoded, 4);
}

/// On every backend: finite light, and the crate's planks in the G-buffer albedo with the
/// JPEG's colour (the ratio of mean red to mean blue over the crate's pixels within 15% of the
/// texture's, in linear light).
#[test]
fn the_untidy_crate_renders_with_its_textures_on_every_backend() {
    let loaded = crate_scene();
    let texture = engine::assets::load_texture(
        &harness::workspace_root().join("scenes/assets/crate_albedo.jpg"),
        ColorSpace::Srgb,
    )
    .unwrap();
    let (mut red, mut blue) = (0.0, 0.0);
    for texel in texture.mips[0].chunks_exact(4) {
        red += srgb_to_linear(f64::from(texel[0]) / 255.0);
        blue += srgb_to_linear(f64::from(texel[2]) / 255.0);
    }
    let texture_ratio = red / blue;
    for kind in common::available_backends() {
        let mut backend = engine::backend::create(kind).unwrap();
        let frame = renderer::render(
            backend.as_mut(),
            &loaded.scene,
            Readback::Only(&[TargetId::GBuffer(GBufferTarget::Albedo), TargetId::Light]),
        )
        .unwrap_or_else(|e| panic!("{kind}: {e}"));
        let light = frame.output(TargetId::Light).unwrap().as_f32().unwrap();
        assert!(
            light.iter().all(|v| v.is_finite()),
            "{kind}: non-finite light"
        );
        let albedo = frame
            .output(TargetId::GBuffer(GBufferTarget::Albedo))
            .unwrap()
            .as_f32()
            .unwrap();
        // Wood: clearly redder than blue (the floor is gray, the label the default white).
        let wood: Vec<&[f32]> = albedo
            .chunks_exact(4)
            .filter(|p| p[0] > 1.5 * p[2] && p[0] > 0.02)
            .collect();
        let share = wood.len() as f64 / (albedo.len() / 4) as f64;
        assert!(
            share > 0.1,
            "{kind}: the crate covers {share:.3} of the frame"
        );
        let mut distinct: Vec<u32> = wood.iter().map(|p| p[0].to_bits()).collect();
        distinct.sort_unstable();
        distinct.dedup();
        assert!(
            distinct.len() > 100,
            "{kind}: {} shades of wood",
            distinct.len()
        );
        let (r, b) = wood.iter().fold((0.0, 0.0), |(r, b), p| {
            (r + f64::from(p[0]), b + f64::from(p[2]))
        });
        let ratio = r / b;
        assert!(
            (ratio / texture_ratio - 1.0).abs() < 0.15,
            "{kind}: red/blue {ratio:.3} in the G-buffer, {texture_ratio:.3} in the texture"
        );
    }
}

/// `check` of the crate, which has no goldens: its verdict says once, not per output, that
/// there is nothing to compare with, where the outputs are and the one bless command; and
/// before that, that it loaded with warnings, which a bless would make part of its golden.
#[test]
fn checking_the_crate_says_its_warnings_before_it_says_bless() {
    if !common::gl_available() {
        return;
    }
    let out = tempfile::tempdir().unwrap();
    let scene = harness::workspace_root().join("scenes/models/crate.toml");
    let output = common::harness_command()
        .args(["check", "--no-speed", "--no-verify", "--backend", "gl"])
        .args(["--scene", scene.to_str().unwrap()])
        .args(["--out", out.path().to_str().unwrap()])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(output.status.code(), Some(1), "{stdout}");
    let why: Vec<&str> = stdout
        .split("\nwhy: where each change starts, and what to do\n")
        .nth(1)
        .unwrap_or_default()
        .lines()
        .take_while(|l| l.starts_with("  "))
        .collect();
    let warnings = crate_scene().warnings;
    let [heading, quoted @ .., uncompared] = &why[..] else {
        panic!("lines expected under why:\n{stdout}");
    };
    assert!(
        heading.starts_with(&format!(
            "  crate: loaded with {} warning(s);",
            warnings.len()
        )) && heading.ends_with("is a change to fix before blessing:"),
        "{heading}"
    );
    let expected: Vec<String> = warnings.iter().map(|w| format!("    {w}")).collect();
    assert_eq!(quoted, &expected[..], "{stdout}");
    let folder = out.path().join("failures/crate/gl");
    assert!(
        uncompared.starts_with("  crate: nothing to compare with for ")
            && uncompared.contains(&format!("look at them in {};", folder.display()))
            && uncompared.ends_with(&format!(" bless --scene {}`", scene.display())),
        "{uncompared}"
    );
}
