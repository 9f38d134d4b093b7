//! `harness review`: serves the last check's page with Accept buttons (see
//! [`harness::review`]).

use std::io::Write as _;
use std::path::Path;
use std::process::ExitCode;

/// Binds 127.0.0.1:`port`, prints the page's address and serves until stopped.
pub(crate) fn run(out: &Path, port: u16) -> anyhow::Result<ExitCode> {
    let review = harness::review::Review::bind(out, port)?;
    println!("review page: {}", review.url());
    println!(
        "(accepting blesses what the last check kept under {}; Ctrl-C stops)",
        out.display()
    );
    std::io::stdout().flush()?;
    review.serve(&harness::golden::GoldenStore::workspace());
    Ok(ExitCode::SUCCESS)
}
