//! Tests of `harness::golden::suite`.

use harness::golden::suite::*;
use std::path::Path;

#[test]
fn bless_commands_quote_paths_a_shell_would_split() {
    assert_eq!(
        bless_command("chess"),
        "cargo run -p harness -- bless --scene chess"
    );
    assert_eq!(
        bless_command("my scenes/it's.toml"),
        "cargo run -p harness -- bless --scene 'my scenes/it'\\''s.toml'"
    );
}

#[test]
fn a_scene_outside_scenes_is_named_by_its_path() {
    let inside = harness::scenes_dir().join("arrow.toml");
    assert_eq!(scene_argument(&inside), "arrow");
    let outside = Path::new("/tmp/elsewhere/arrow.toml");
    assert_eq!(scene_argument(outside), "/tmp/elsewhere/arrow.toml");
}
