//! `harness check`'s speed section on the console: a line per scene, pass and backend against
//! its timing golden, the probes that failed, the passes that got faster, and what the speed
//! checks can catch on this host.

use harness::golden::check::CheckRun;

/// The speed section of the table: a line per scene, pass and backend (the value against the
/// limit, or why it is untimed), the probes that failed, and the passes that got faster.
pub(super) fn print_speed(run: &CheckRun) {
    use harness::golden::speed::SpeedOutcome;
    if run.speed.checks.is_empty() && run.speed.errors.is_empty() {
        return;
    }
    println!(
        "\nspeed: each pass alone over its floor, against its timing golden \
         (golden/<scene>/timing.toml; limits from golden/timing-noise.toml), or on a recorded \
         host against its own recording (golden/evidence/<host>/timing.toml); \"0.52 of it\" after \
         the limit places the ratio on the way to it, ln(ratio / golden) / ln(limit): 0 \
         unchanged, 1 at the limit (fails above), negative faster"
    );
    println!(
        "{:<8} {:<22} {:<12} {:<8} value",
        "scene", "pass", "backend", "result"
    );
    for c in &run.speed.checks {
        let label = c.outcome.label();
        println!(
            "{:<8} {:<22} {:<12} {label:<8} {}",
            c.scene,
            c.pass,
            c.backend,
            c.measurement()
        );
    }
    for e in &run.speed.errors {
        println!("speed probe FAILED: {e}");
    }
    let faster = |same_host: bool| -> Vec<String> {
        run.speed
            .checks
            .iter()
            .filter(|c| {
                c.outcome == SpeedOutcome::Faster && c.tier.bless_writes_here() == same_host
            })
            .map(|c| format!("{}/{} on {}", c.scene, c.pass, c.backend))
            .collect()
    };
    let (here, elsewhere) = (faster(true), faster(false));
    if !here.is_empty() {
        println!(
            "note: faster than their timing goldens beyond the limit (bless if intended, `{}`): \
             {}",
            harness::golden::command_line::harness_command("bless --scene S --speed-only"),
            here.join(", ")
        );
    }
    if !elsewhere.is_empty() {
        println!(
            "note: faster beyond the limit, read at the limits for any host, where ratios \
             differ between hosts, so not yet a speed-up to bless: record this host (see the \
             note under the coverage below), check again, and bless with `--speed-only` what is \
             still faster; or move the timing goldens here whole with `harness bless --scene S \
             --speed-only --every-pass`: {}",
            elsewhere.join(", ")
        );
    }
    let coverage = harness::golden::speed::coverage(&run.speed.checks);
    if !coverage.is_empty() {
        println!(
            "what the speed checks catch here (a pass slower than its golden by more than its \
             limit fails):"
        );
        for c in &coverage {
            println!("  {:<12} {}", c.backend.name(), c.describe());
        }
    }
    if let Some(advice) =
        harness::golden::speed::verdict::record_advice(&coverage, &run.speed.recorded_as)
    {
        println!("note: {advice}");
    }
    for note in &run.speed.host_notes {
        println!("note: {note}");
    }
}
