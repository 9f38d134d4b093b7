//! Scene-file values that load as numbers but would render wrong without a word: each is
//! refused when the scene loads, naming the object and the value. And a scene of scenes/ that
//! is no file, or a file that is not UTF-8: loading it says what it is, and where.

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
        ("rotated", "scale = [1, 1, 3e18]\nrotation = [90, 0, 0]\n"),
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

/// A scene file saved as Latin-1 (or UTF-16) is refused at the line and column of its first
/// byte that is not UTF-8, saying what to do.
#[test]
fn a_scene_file_that_is_not_utf8_is_refused_where_it_stops_being_so() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("latin1.toml");
    let mut bytes = CAMERA.as_bytes().to_vec();
    bytes.extend_from_slice(b"[[objects]]\nname = \"caf\xe9\"\nmesh = \"builtin:cube\"\n");
    std::fs::write(&path, bytes).unwrap();
    let e = scene_file::load(&path).err().unwrap().to_string();
    assert!(
        e.contains("latin1.toml:5:12: byte 0xe9 is not UTF-8") && e.contains("save it as UTF-8"),
        "{e}"
    );
}

/// A scene file in scenes/ whose name is not UTF-8 is not a canonical scene (no command line
/// names it), and is listed as such, for the harness to say so.
#[test]
fn a_scene_file_whose_name_is_not_utf8_is_listed_apart() {
    use std::os::unix::ffi::OsStrExt;
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("plain.toml"), CAMERA).unwrap();
    let odd = std::ffi::OsStr::from_bytes(b"caf\xe9.toml");
    std::fs::write(dir.path().join(odd), CAMERA).unwrap();
    assert_eq!(scene_file::canonical_scenes(dir.path()), ["plain"]);
    let unnamed = scene_file::unnamed_scene_files(dir.path());
    assert!(
        unnamed.len() == 1 && unnamed[0].ends_with("caf\u{fffd}.toml"),
        "{unnamed:?}"
    );
}
