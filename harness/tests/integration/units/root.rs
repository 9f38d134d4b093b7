//! Tests of the crate root's helpers (`harness::error_text`).

#[test]
fn error_text_says_each_cause_once() {
    let missing = std::path::Path::new("/nonexistent/albedo.png");
    let asset =
        engine::assets::load_texture(missing, engine::assets::ColorSpace::Srgb).unwrap_err();
    let error = anyhow::Error::new(asset).context("loading scene `x`");
    let text = harness::error_text(error.as_ref());
    assert_eq!(
        text,
        "loading scene `x`: /nonexistent/albedo.png: cannot read file: No such file or \
         directory (os error 2)"
    );
}
