//! Tests of `harness::url`.

use harness::url::{decoded, encoded};
use std::path::Path;

/// A path with the characters a URL reads otherwise (a scene may be named `p%zz`, `a#b`,
/// `x?y`, with spaces or accents) encodes to a URL path that decodes back to it; plain paths
/// stay as they are, and a malformed escape decodes to nothing.
#[test]
fn paths_encode_and_decode_back() {
    assert_eq!(
        encoded(Path::new("failures/arrow/gl/light_actual.exr")),
        "failures/arrow/gl/light_actual.exr"
    );
    for path in [
        "failures/p%zz/gl/a.png",
        "failures/a#b?c d/gl/é.png",
        "x%41",
    ] {
        let url = encoded(Path::new(path));
        assert!(!url.contains(['#', '?', ' ']), "{url}");
        assert_eq!(decoded(&url).as_deref(), Some(path), "{url}");
    }
    assert_eq!(encoded(Path::new("x%41")), "x%2541");
    assert_eq!(decoded("bad%zz"), None);
    assert_eq!(decoded("cut%4"), None);
}
