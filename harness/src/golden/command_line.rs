//! The command lines the harness prints for a user to paste (a bless or an accept after a
//! failing check), quoted for a POSIX shell and naming the workspace they were made in.

/// The `harness bless` command line that rewrites the goldens of a scene's changed or missing
/// passes (`scene` as [`crate::golden::suite::Case::argument`] gives it), quoted for a POSIX
/// shell where needed. In a workspace named by `HARNESS_ROOT`, the command names it too:
/// pasted without it, it would bless the checkout the shell stands in.
pub fn bless_command(scene: &str) -> String {
    format!(
        "{}cargo run -p harness -- bless --scene {}",
        workspace(),
        shell_quote(scene)
    )
}

/// The command that accepts what the last check rendered and verified, without rendering
/// again (`bless --from-last-check`), naming the check's `--out` folder when it was not the
/// default (`None`), and the workspace as [`bless_command`] does.
pub fn accept_command(out: Option<&std::path::Path>) -> String {
    let out = out.map_or(String::new(), |dir| {
        format!(" --out {}", shell_quote(&dir.to_string_lossy()))
    });
    format!(
        "{}cargo run -p harness -- bless --from-last-check{out}",
        workspace()
    )
}

/// `HARNESS_ROOT=<root> ` when the workspace is named by `HARNESS_ROOT`, else nothing.
fn workspace() -> String {
    std::env::var_os("HARNESS_ROOT")
        .filter(|r| !r.is_empty())
        .map(|r| format!("HARNESS_ROOT={} ", shell_quote(&r.to_string_lossy())))
        .unwrap_or_default()
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
