//! Scene files: parsing, unknown keys, relative paths, texture sharing, canonical names, and
//! the canonical scenes themselves.

use std::path::{Path, PathBuf};

use engine::scene_file::{self, SceneFileError};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}

fn parse_err(text: &str) -> String {
    scene_file::parse(Path::new("dir/bad.toml"), text)
        .expect_err("must fail")
        .to_string()
}

const CAMERA: &str = "[camera]\nposition = [0, 0, 1]\ntarget = [0, 0, 0]\n";

#[test]
fn unknown_keys_name_the_key_the_file_and_the_line() {
    let e = parse_err(&format!("colour = 1\n{CAMERA}"));
    assert!(e.starts_with("dir/bad.toml:1:"), "{e}");
    assert!(e.contains("unknown field `colour`"), "{e}");
    let e = parse_err(&format!(
        "{CAMERA}\n[[objects]]\nmesh = \"a.obj\"\nroughnes = 0.5\n"
    ));
    assert!(e.contains("dir/bad.toml:7:"), "{e}");
    assert!(e.contains("`roughnes`"), "{e}");
    let e = parse_err(&format!(
        "{CAMERA}\n[[lights]]\ntype = \"spot\"\nposition = [0, 0, 0]\n"
    ));
    assert!(e.contains("spot"), "{e}");
    let e = parse_err("[camera]\nposition = [0, 0]\ntarget = [0, 0, 0]\n");
    assert!(e.contains("dir/bad.toml:2:"), "{e}");
}

/// A light's table is read whole before its `type` is known; its errors still point at the key
/// at fault, not at the `[[lights]]` header, for either type and for a nested shadow table.
#[test]
fn errors_in_a_light_name_the_line_of_the_key() {
    let light = |body: &str| {
        parse_err(&format!(
            "{CAMERA}\n[[lights]]\ntype = \"point\"\nposition = [0, 0, 0]\nradius = 1\n{body}\n\
             [[lights]]\ntype = \"directional\"\ndirection = [0, 1, 0]\n"
        ))
    };
    // CAMERA is 3 lines, then an empty line, the header (5), type, position, radius: line 9.
    let e = light("intensty = 3");
    assert!(e.starts_with("dir/bad.toml:9:1:"), "{e}");
    assert!(e.contains("unknown field `intensty`"), "{e}");
    let e = light("falloff = \"steep\"");
    assert!(e.starts_with("dir/bad.toml:9:"), "{e}");
    assert!(e.contains("expected f32"), "{e}");
    let e = light("shadow = { map_sise = 512 }");
    assert!(e.starts_with("dir/bad.toml:9:"), "{e}");
    assert!(e.contains("`map_sise`"), "{e}");
    // A key in a `[lights.shadow]` sub-table: its own line (9 is the sub-table's header).
    let e = light("[lights.shadow]\nfilter = \"pcf3\"\nmap_sise = 512");
    assert!(e.starts_with("dir/bad.toml:11:1:"), "{e}");
    assert!(e.contains("`map_sise`"), "{e}");
    // The second light, a directional one, with a key only point lights have.
    let e = parse_err(&format!(
        "{CAMERA}\n[[lights]]\ntype = \"directional\"\ndirection = [0, 1, 0]\nradius = 2\n"
    ));
    assert!(e.starts_with("dir/bad.toml:8:1:"), "{e}");
    assert!(e.contains("unknown field `radius`"), "{e}");
}

#[test]
fn paths_are_relative_to_the_scene_file_and_shared_textures_load_once() {
    let loaded = scene_file::load(&fixture("scenes/two_materials.toml")).unwrap();
    let scene = &loaded.scene;
    // Two OBJ meshes per OBJ object, loaded once and shared; plus the built-in sphere.
    assert_eq!(scene.objects.len(), 5);
    assert!(std::sync::Arc::ptr_eq(
        &scene.objects[0].mesh,
        &scene.objects[2].mesh
    ));
    // `brick` and `stone` both use checker.png: decoded once, one texture, same index.
    assert_eq!(loaded.textures_decoded, 3);
    assert_eq!(scene.textures.len(), 3);
    let brick = &scene.objects[0].material;
    let stone = &scene.objects[1].material;
    assert!(brick.base_color_map.is_some());
    assert_eq!(brick.base_color_map, stone.base_color_map);
    // Per-material override applies to `stone` of the second object only.
    assert_eq!(scene.objects[3].material.roughness, 0.9);
    assert_eq!(scene.objects[1].material.roughness, 0.5);
    assert_eq!(
        scene.objects[4].lighting,
        engine::scene::LightingModel::BlinnPhong
    );
    assert_eq!(scene.quality.width, 64);
}

/// Writes `text` to `dir/name` and loads it as a scene file, which must fail: the error.
fn load_error(dir: &Path, name: &str, text: &str) -> SceneFileError {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    scene_file::load(&path).err().unwrap()
}

/// A name that cannot be one folder (it names `golden/<name>/` and the failure images' folder),
/// a list of other than three numbers where three are read (TOML's lists would otherwise keep
/// the first three), a far / near ratio a 32-bit depth buffer cannot hold, a camera value that
/// is not finite and an environment that takes light away are refused, naming the file (and
/// the value).
#[test]
fn names_that_leave_their_folder_lists_of_four_and_depth_beyond_f32_are_refused() {
    let temp = tempfile::tempdir().unwrap();
    let dir = temp.path();
    for name in ["../../elsewhere", "", "..", "a/b"] {
        let e = load_error(dir, "named.toml", &format!("name = {name:?}\n{CAMERA}")).to_string();
        assert!(
            e.contains("named.toml") && e.contains("cannot name a folder"),
            "{name:?}: {e}"
        );
    }
    let four = "[camera]\nposition = [0, 1, 3, 4]\ntarget = [0, 0, 0]\n";
    let scale = format!("{CAMERA}[[objects]]\nmesh = \"cube\"\nscale = [1, 2]\n");
    let e = load_error(dir, "scale.toml", &scale).to_string();
    assert!(
        e.contains("scale.toml:6:9:")
            && e.ends_with("`scale` must be one number or a list of three"),
        "{e}"
    );
    let e = load_error(dir, "four.toml", four).to_string();
    assert!(
        e.contains("four.toml:2:") && e.contains("invalid length 4, expected 3 numbers"),
        "{e}"
    );
    let e = load_error(
        dir,
        "color.toml",
        &format!("{CAMERA}[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\ncolor = [1, 1]\n"),
    )
    .to_string();
    assert!(
        e.contains("color.toml") && e.contains("invalid length 2"),
        "{e}"
    );
    let e = load_error(
        dir,
        "depth.toml",
        "[camera]\nposition = [0, 1, 3]\ntarget = [0, 0, 0]\nnear = 1e-7\nfar = 100.0\n",
    )
    .to_string();
    assert!(e.contains("depth.toml") && e.contains("over 2^24"), "{e}");
    // A value out of range is named with what was read.
    let nan = "[camera]\nposition = [1.4, nan, 1.8]\ntarget = [0, 0, 0]\n";
    let e = load_error(dir, "nan.toml", nan).to_string();
    assert!(
        e.contains("nan.toml")
            && e.ends_with("[camera] position = [1.4, NaN, 1.8]: values must be finite"),
        "{e}"
    );
    std::fs::copy(fixture("sky.hdr"), dir.join("sky.hdr")).unwrap();
    let dark = format!("{CAMERA}[environment]\npath = \"sky.hdr\"\nintensity = -1.0\n");
    let e = load_error(dir, "dark.toml", &dark).to_string();
    assert!(
        e.contains("dark.toml")
            && e.contains("environment intensity -1 must be finite and at least 0"),
        "{e}"
    );
}

/// A scene file may light its scene with a Radiance `.hdr` environment as well as an EXR: its
/// size is read from the header for the limits, then it loads; above the limits it is refused
/// naming the file, and a file of neither format is an error naming it.
#[test]
fn radiance_hdr_environments_load_from_scene_files() {
    let temp = tempfile::tempdir().unwrap();
    let dir = temp.path();
    std::fs::copy(fixture("sky.hdr"), dir.join("sky.hdr")).unwrap();
    let path = dir.join("hdr.toml");
    std::fs::write(
        &path,
        format!("{CAMERA}[environment]\npath = \"sky.hdr\"\n"),
    )
    .unwrap();
    let scene = scene_file::load(&path).unwrap().scene;
    let image = &scene.environment.expect("an environment").image;
    assert_eq!((image.width, image.height), (8, 4));
    let small = engine::assets::Limits {
        max_texture_side: 4,
        ..engine::assets::Limits::DEFAULT
    };
    let e = scene_file::load_with_limits(&path, small)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("sky.hdr") && e.contains('8'), "{e}");
    std::fs::write(dir.join("sky.hdr"), "P3\n1 1\n255\n0 0 0\n").unwrap();
    let e = scene_file::load(&path).err().unwrap().to_string();
    assert!(
        e.contains("sky.hdr") && e.contains("not an OpenEXR or Radiance .hdr file"),
        "{e}"
    );
}

/// An override for an MTL material the object's meshes do not use (a misspelt name) is an error
/// naming the file, the object and the key, with the names it could have meant.
#[test]
fn materials_overrides_must_name_a_material_the_mesh_uses() {
    let temp = tempfile::tempdir().unwrap();
    let mesh = fixture("textured.obj");
    let object = |key: &str| {
        format!(
            "{CAMERA}[[objects]]\nname = \"box\"\nmesh = {:?}\nmaterials.{key} = {{ roughness = 0.9 }}\n",
            mesh.to_str().unwrap()
        )
    };
    let e = load_error(temp.path(), "misspelt.toml", &object("ston")).to_string();
    assert!(
        e.contains("misspelt.toml")
            && e.contains("object `box`")
            && e.contains("`materials.ston`")
            && e.contains("it uses brick, stone"),
        "{e}"
    );
    let path = temp.path().join("right.toml");
    std::fs::write(&path, object("stone")).unwrap();
    let scene = scene_file::load(&path).unwrap().scene;
    // Only the stone part takes the override.
    let roughness: Vec<f32> = scene.objects.iter().map(|o| o.material.roughness).collect();
    assert_eq!(
        roughness.iter().filter(|&&r| r == 0.9).count(),
        1,
        "{roughness:?}"
    );
}

/// A point light with a VSM shadow filter, which only directional lights have.
const POINT_LIGHT_WITH_VSM: &str = concat!(
    "[[lights]]\ntype = \"point\"\nposition = [0, 1, 0]\nradius = 5\n",
    "shadow = { filter = \"vsm\" }\n",
);

#[test]
fn bad_values_and_missing_assets_are_errors_naming_the_file() {
    let temp = tempfile::tempdir().unwrap();
    let dir = temp.path();
    let e = load_error(
        dir,
        "radius.toml",
        &format!("{CAMERA}[[lights]]\ntype = \"point\"\nposition = [0, 0, 0]\nradius = -1\n"),
    );
    assert!(matches!(e, SceneFileError::Invalid { .. }), "{e}");
    assert!(e.to_string().contains("radius.toml"), "{e}");
    let e = load_error(
        dir,
        "missing.toml",
        &format!("{CAMERA}[[objects]]\nmesh = \"nowhere.obj\"\n"),
    )
    .to_string();
    assert!(
        e.contains("missing.toml") && e.contains("nowhere.obj"),
        "{e}"
    );
    let e = load_error(
        dir,
        "env.toml",
        &format!("{CAMERA}[environment]\npath = \"sky.exr\"\n"),
    )
    .to_string();
    assert!(e.contains("sky.exr"), "{e}");
    let e = load_error(
        dir,
        "nan.toml",
        "[camera]\nposition = [nan, 0, 1]\ntarget = [0, 0, 0]\n",
    )
    .to_string();
    assert!(e.contains("nan.toml") && e.contains("finite"), "{e}");
    // A light's value out of range is named, with the value read (1e39 is beyond f32's range;
    // a color is listed as written).
    for (body, problem) in [
        (
            "type = \"directional\"\ndirection = [0, 1, 0]\nintensity = nan",
            "light 0: intensity must be a finite number, not NaN",
        ),
        (
            "type = \"directional\"\ndirection = [0, 1, 0]\nintensity = 1e39",
            "light 0: intensity must be a finite number, not inf (a number beyond f32's range",
        ),
        (
            "type = \"directional\"\ndirection = [0, 0, 0]",
            "light 0: direction must not be zero, not [0.0, 0.0, 0.0]",
        ),
        (
            "type = \"point\"\nposition = [0, 0, 0]\nradius = 0",
            "light 0: radius must be positive, not 0",
        ),
        (
            "type = \"point\"\nposition = [0, 0, 0]\nradius = 1\ncolor = [0.1, nan, 1]",
            "light 0: color must be a finite number, not NaN in [0.1, NaN, 1.0]",
        ),
        (
            "type = \"point\"\nposition = [0, inf, 0]\nradius = 1",
            "light 0: position must be finite numbers, not [0.0, inf, 0.0]",
        ),
    ] {
        let text = format!("{CAMERA}[[lights]]\n{body}\n");
        let e = load_error(dir, "light.toml", &text).to_string();
        assert!(e.contains("light.toml") && e.contains(problem), "{e}");
    }
    let bias =
        "[[lights]]\ntype = \"directional\"\ndirection = [0, 1, 0]\nshadow = { bias = -1.0 }\n";
    let e = load_error(dir, "bias.toml", &format!("{CAMERA}{bias}")).to_string();
    assert!(
        e.contains("bias.toml") && e.contains("shadow bias -1 must be finite and not negative"),
        "{e}"
    );
    let e = load_error(dir, "vsm.toml", &format!("{CAMERA}{POINT_LIGHT_WITH_VSM}")).to_string();
    assert!(
        e.contains("vsm.toml") && e.contains("light 0") && e.contains("directional"),
        "{e}"
    );
    let e = scene_file::load(&dir.join("absent.toml"))
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("absent.toml"), "{e}");
}

#[test]
fn canonical_names_resolve_and_unknown_names_list_the_scenes() {
    let dir = scenes_dir();
    assert_eq!(
        scene_file::resolve("chess", &dir).unwrap(),
        dir.join("chess.toml")
    );
    let e = scene_file::resolve("chesss", &dir)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("arrow, chess, corner, ibl"), "{e}");
}

/// Every canonical scene loads, renders at 512x512 (corner, the ambient occlusion's scene, at
/// 256x256), and every vertex of every mesh
/// it uses has a finite unit normal and a unit tangent orthogonal to it with w = +1 or -1.
#[test]
fn canonical_scenes_load_with_valid_tangent_frames() {
    let names = scene_file::canonical_scenes(&scenes_dir());
    assert_eq!(names, ["arrow", "chess", "corner", "ibl"]);
    for name in names {
        let loaded = scene_file::load(&scenes_dir().join(format!("{name}.toml")))
            .unwrap_or_else(|e| panic!("{e}"));
        let scene = &loaded.scene;
        let size = if name == "corner" { 256 } else { 512 };
        assert_eq!((scene.quality.width, scene.quality.height), (size, size));
        assert!(!scene.objects.is_empty());
        for object in &scene.objects {
            for (i, v) in object.mesh.vertices.iter().enumerate() {
                let n = glam::Vec3::from(v.normal);
                let t = glam::Vec3::new(v.tangent[0], v.tangent[1], v.tangent[2]);
                let what = format!("{name}/{} vertex {i}", object.name);
                assert!(n.is_finite() && t.is_finite(), "{what}: not finite");
                assert!(
                    (n.length() - 1.0).abs() <= 1e-3,
                    "{what}: |n| = {}",
                    n.length()
                );
                assert!(
                    (t.length() - 1.0).abs() <= 1e-3,
                    "{what}: |t| = {}",
                    t.length()
                );
                assert!(n.dot(t).abs() <= 1e-3, "{what}: n.t = {}", n.dot(t));
                assert!(
                    v.tangent[3] == 1.0 || v.tangent[3] == -1.0,
                    "{what}: w = {}",
                    v.tangent[3]
                );
            }
        }
    }
    // The chess board's two materials share one albedo texture, decoded once.
    let chess = scene_file::load(&scenes_dir().join("chess.toml")).unwrap();
    let board: Vec<_> = chess
        .scene
        .objects
        .iter()
        .filter(|o| o.name.starts_with("board/"))
        .collect();
    assert_eq!(board.len(), 2);
    assert_eq!(
        board[0].material.base_color_map,
        board[1].material.base_color_map
    );
    assert_eq!(
        chess.textures_decoded, 4,
        "albedo, roughness, normal, clearcoat"
    );
    // Every file the load read, once each, the material libraries and textures included.
    let names: Vec<String> = chess
        .files
        .iter()
        .map(|f| f.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        [
            "chess.toml",
            "sunset.exr",
            "board.obj",
            "board.mtl",
            "checker.obj",
            "checker.mtl",
            "board_albedo.png",
            "board_roughness.png",
            "board_normal.png",
            "board_clearcoat.png",
        ]
    );
}

/// A negative light intensity, absolute asset paths and material values outside their ranges
/// load, each with a warning naming the scene file and what is at fault; the canonical scenes
/// have none of them.
#[test]
fn negative_intensities_absolute_paths_and_materials_out_of_range_are_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let cube = fixture("cube.obj");
    let sunset = scenes_dir()
        .join("assets/sunset.exr")
        .canonicalize()
        .unwrap();
    let scene = dir.path().join("untidy.toml");
    std::fs::write(
        &scene,
        format!(
            "{CAMERA}[environment]\npath = \"{}\"\n[[objects]]\nname = \"cube\"\nmesh = \"{}\"\n\
             material = {{ roughness = 2.0, anisotropy = -3.0, base_color = [-1, 0, 0] }}\n\
             [[lights]]\ntype = \"directional\"\ndirection = [0, 1, 0]\nintensity = -2.0\n",
            sunset.display(),
            cube.display()
        ),
    )
    .unwrap();
    let loaded = scene_file::load(&scene).unwrap();
    let expected = [
        "untidy.toml: light 0: negative intensity -2".to_owned(),
        format!(
            "untidy.toml: object `cube`: mesh `{}` is an absolute path",
            cube.display()
        ),
        format!(
            "untidy.toml: [environment] path `{}` is an absolute path",
            sunset.display()
        ),
        "roughness 2 is outside 0..1".to_owned(),
        "anisotropy -3 is outside -1..1".to_owned(),
        "base colour [-1.0, 0.0, 0.0] is negative".to_owned(),
    ];
    for needle in &expected {
        assert!(
            loaded.warnings.iter().any(|w| w.contains(needle.as_str())),
            "no `{needle}` in {:#?}",
            loaded.warnings
        );
    }
    for name in scene_file::canonical_scenes(&scenes_dir()) {
        let path = scene_file::resolve(&name, &scenes_dir()).unwrap();
        assert_eq!(
            scene_file::load(&path).unwrap().warnings,
            Vec::<String>::new(),
            "{name}"
        );
    }
}

/// `[quality.ibl] runtime_footprint` reads as a number, a power of two from 1/16 to 64, and
/// anything else is an error naming the file, the line and the value.
#[test]
fn the_ibl_footprint_is_a_power_of_two_read_as_a_number() {
    let with = |footprint: &str| {
        format!("{CAMERA}\n[quality.ibl]\nruntime_samples = 64\nruntime_footprint = {footprint}\n")
    };
    for (text, factor) in [("0.25", 0.25), ("1", 1.0), ("4.0", 4.0), ("64", 64.0)] {
        let scene = scene_file::parse(Path::new("dir/ok.toml"), &with(text))
            .unwrap_or_else(|e| panic!("{text}: {e}"));
        let ibl = scene.quality.ibl.expect("[quality.ibl]");
        assert_eq!(ibl.runtime_footprint.factor(), factor, "{text}");
    }
    for bad in ["0.3", "3", "128", "0", "-1", "0.03125"] {
        let e = parse_err(&with(bad));
        assert!(e.starts_with("dir/bad.toml:7:"), "{bad}: {e}");
        assert!(
            e.contains("runtime_footprint") && e.contains("power of two"),
            "{e}"
        );
    }
    // The default reads a sample's own solid angle.
    let default = engine::scene::IblSettings::default();
    assert_eq!(default.runtime_footprint.factor(), 1.0);
}

/// `[quality.ibl] dominant_direction` names one of the two rules, and another name is an error
/// naming the line and the choices.
#[test]
fn the_ibl_dominant_direction_is_one_of_two_rules() {
    let with = |rule: &str| format!("{CAMERA}\n[quality.ibl]\ndominant_direction = \"{rule}\"\n");
    for (name, rule) in [
        ("filament", engine::scene::DominantDirection::Filament),
        ("frostbite", engine::scene::DominantDirection::Frostbite),
    ] {
        let scene = scene_file::parse(Path::new("dir/ok.toml"), &with(name)).unwrap();
        assert_eq!(scene.quality.ibl.unwrap().dominant_direction, rule);
    }
    let e = parse_err(&with("unreal"));
    assert!(e.starts_with("dir/bad.toml:6:"), "{e}");
    assert!(e.contains("filament") && e.contains("frostbite"), "{e}");
}

/// `[quality.ibl] anisotropic_lookup` names one of the two ways, the bent normal by default, and
/// another name is an error naming the line and the choices.
#[test]
fn the_ibl_anisotropic_lookup_is_one_of_two_ways() {
    let with = |way: &str| format!("{CAMERA}\n[quality.ibl]\nanisotropic_lookup = \"{way}\"\n");
    for (name, way) in [
        ("bent-normal", engine::scene::AnisotropicLookup::BentNormal),
        ("taps", engine::scene::AnisotropicLookup::Taps),
    ] {
        let scene = scene_file::parse(Path::new("dir/ok.toml"), &with(name)).unwrap();
        assert_eq!(scene.quality.ibl.unwrap().anisotropic_lookup, way);
    }
    assert_eq!(
        engine::scene::IblSettings::default().anisotropic_lookup,
        engine::scene::AnisotropicLookup::BentNormal
    );
    let e = parse_err(&with("bent"));
    assert!(e.starts_with("dir/bad.toml:6:"), "{e}");
    assert!(e.contains("bent-normal") && e.contains("taps"), "{e}");
}

/// `[quality.ibl] extracted_lights` reads as a count, 1 by default (the sun alone), and a count
/// outside 1..8 is a problem naming the key (reported with the scene file's name when the scene
/// has an environment to light).
#[test]
fn the_ibl_extracted_lights_are_a_count_from_one_to_eight() {
    let with = |count: &str| {
        format!("{CAMERA}\n[quality.ibl]\nextract_sun = true\nextracted_lights = {count}\n")
    };
    for count in [1, 3, 8] {
        let scene = scene_file::parse(Path::new("dir/ok.toml"), &with(&count.to_string()))
            .unwrap_or_else(|e| panic!("{count}: {e}"));
        assert_eq!(scene.quality.ibl.unwrap().extracted_lights, count);
    }
    assert_eq!(engine::scene::IblSettings::default().extracted_lights, 1);
    for bad in [0, 9] {
        let settings = engine::scene::IblSettings {
            extract_sun: true,
            extracted_lights: bad,
            ..Default::default()
        };
        let problem = settings.problem().expect("out of range");
        assert!(
            problem.contains("extracted_lights") && problem.contains(&bad.to_string()),
            "{problem}"
        );
    }
}

/// An environment that is not twice as wide as tall loads (stretched over the sphere) with a
/// warning naming the scene file, the image and its size.
#[test]
fn an_environment_not_twice_as_wide_as_tall_is_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    exr::prelude::write_rgba_file(dir.path().join("square.exr"), 16, 16, |_, _| {
        (0.5f32, 0.5f32, 0.5f32, 1.0f32)
    })
    .unwrap();
    let scene = dir.path().join("square.toml");
    std::fs::write(
        &scene,
        format!("{CAMERA}[environment]\npath = \"square.exr\"\n"),
    )
    .unwrap();
    let warnings = scene_file::load(&scene).unwrap().warnings;
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("square.toml: environment")
                && w.contains("square.exr is 16x16, not twice as wide as tall")),
        "{warnings:#?}"
    );
}
