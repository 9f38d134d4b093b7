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

#[cfg(test)]
mod tests {
    #[test]
    fn escapes_what_html_reads_as_markup() {
        assert_eq!(
            super::escape(r#"a < b && c > "d""#),
            "a &lt; b &amp;&amp; c &gt; &quot;d&quot;"
        );
    }
}
