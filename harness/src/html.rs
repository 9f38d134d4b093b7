//! Small HTML helpers shared by the pages the harness writes (the review page and the sections
//! bench, sweep and hard cases add to it).

/// `text` with the characters HTML gives meaning to (`& < > "`) escaped, for element content
/// and double-quoted attribute values.
pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
