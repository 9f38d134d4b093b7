//! Scene-file values that load as numbers but would render wrong without a word: each is
//! refused when the scene loads, naming the object and the value. And a scene of scenes/ that
//! is no file: loading it says what it is.

use engine::scene_file;

const CAMERA: &str = "[camera]\nposition = [0, 1, 3]\ntarget = [0, 0, 0]\n";

/// Loads `text` as a scene file in a temporary folder: the error, as text.
fn refusal(text: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("values.toml");
    std::fs::write(&path, text).unwrap();
    scene_file::load(&path).err().unwrap().to_string()
}

/// A material value that is not a finite number is named: which value, and what it read.
#[test]
fn a_material_value_that_is_not_finite_is_named() {
    let e = refusal(&format!(
        "{CAMERA}[[objects]]\nname = \"ball\"\nmesh = \"builtin:sphere\"\n\
         material = {{ roughness = nan }}\n"
    ));
    assert!(
        e.contains("values.toml") && e.contains("object `ball`: material roughness is NaN"),
        "{e}"
    );
}

/// An object that reaches beyond 1e18 from the camera (by its scale, its position or its
/// mesh) would overflow the lighting's 32-bit arithmetic and vanish: refused, with how far.
#[test]
fn an_object_beyond_what_32_bit_lighting_reaches_is_refused() {
    for (how, object) in [
        ("scale", "scale = 1e20\n"),
        ("position", "position = [0, 0, -2e18]\n"),
    ] {
        let e = refusal(&format!(
            "{CAMERA}[[objects]]\nname = \"far\"\nmesh = \"builtin:sphere\"\n{object}"
        ));
        assert!(
            e.contains("values.toml")
                && e.contains("object `far` reaches ")
                && e.contains("beyond 1e18"),
            "{how}: {e}"
        );
    }
    // A kilometre scene, as the hard cases move chess, loads.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("near.toml");
    let text = format!("{CAMERA}[[objects]]\nmesh = \"builtin:sphere\"\nposition = [0, 0, -1e5]\n");
    std::fs::write(&path, text).unwrap();
    assert!(scene_file::load(&path).is_ok());
}

/// A folder in scenes/ named like a scene resolves as that scene, and loading it says it is not
/// a file (where "no scene `x`", beside a list of the scenes that names x, contradicted itself).
#[test]
fn a_folder_named_like_a_scene_says_it_is_no_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("folder.toml")).unwrap();
    assert_eq!(scene_file::canonical_scenes(dir.path()), ["folder"]);
    let path = scene_file::resolve("folder", dir.path()).unwrap();
    let e = scene_file::load(&path).err().unwrap().to_string();
    assert!(
        e.contains("folder.toml: cannot read scene file") && e.contains("directory"),
        "{e}"
    );
}
