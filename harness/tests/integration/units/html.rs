//! Tests of `harness::html`.

#[test]
fn escapes_what_html_reads_as_markup() {
    assert_eq!(
        harness::html::escape(r#"a < b && c > "d""#),
        "a &lt; b &amp;&amp; c &gt; &quot;d&quot;"
    );
}
