//! Paths in URLs: the review page's links to the check's files, percent-encoded where a URL
//! would read a character otherwise, and decoded back by the review server that serves them.

use std::path::Path;

/// `path` as a URL's path: each byte outside the unreserved characters and `/` as `%XX` (a
/// scene named `p%zz` or `a#b` names a folder; its link must reach it).
pub fn encoded(path: &Path) -> String {
    let mut out = String::new();
    for byte in path.to_string_lossy().bytes() {
        match byte {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'_' | b'.' | b'~' | b'/' => {
                out.push(char::from(byte));
            }
            other => out.push_str(&format!("%{other:02X}")),
        }
    }
    out
}

/// `text` (a URL's path) with its `%XX` escapes decoded, or None where one is malformed or the
/// result is not UTF-8.
pub fn decoded(text: &str) -> Option<String> {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}
