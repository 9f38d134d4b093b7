//! The command lines the harness prints for a user to paste (a bless after a failing check),
//! quoted for a POSIX shell and naming the workspace they were made in.

/// The `harness bless` command line that rewrites the goldens of a scene's changed or missing
/// passes (`scene` as [`Case::argument`] gives it), quoted for a POSIX shell where needed. In a
/// workspace named by `HARNESS_ROOT`, the command names it too: pasted without it, it would
/// bless the checkout the shell stands in.
pub fn bless_command(scene: &str) -> String {
    let root = std::env::var_os("HARNESS_ROOT")
        .filter(|r| !r.is_empty())
        .map(|r| format!("HARNESS_ROOT={} ", shell_quote(&r.to_string_lossy())))
        .unwrap_or_default();
    format!(
        "{root}cargo run -p harness -- bless --scene {}",
        shell_quote(scene)
    )
}

/// `word` as one word of a POSIX shell: as it is when it needs no quoting, else single-quoted.
fn shell_quote(word: &str) -> String {
    let plain = !word.is_empty()
        && word
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "_-./".contains(c));
    if plain {
        word.to_owned()
    } else {
        format!("'{}'", word.replace('\'', "'\\''"))
    }
}
