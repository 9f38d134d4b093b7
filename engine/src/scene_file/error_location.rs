//! Where a parse error is: the line and column of a byte offset, and the key at fault inside a
//! `[[lights]]` table (serde reports those at the table's header).

use super::schema::{DirectionalLightSpec, PointLightSpec};

/// The 1-based line and column (in bytes) of byte `offset` in `text`.
pub(super) fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    (line, column)
}

/// How a sub-table of the last `[[lights]]` entry starts (`[lights.shadow]`).
const SUB_TABLE: &str = "[lights.";

/// serde reads a `[[lights]]` table whole before it knows the light's `type`, so an error in one
/// of its keys is reported at the table's header. When `start` is such a header, this reads the
/// table again on its own, as the struct of its type, and returns where the key at fault is and
/// the error.
pub(super) fn light_error(text: &str, start: usize) -> Option<(usize, String)> {
    let rest = &text[start..];
    if !rest.starts_with("[[lights]]") {
        return None;
    }
    // The table's body: from the line after the header to the next header that is not one of
    // its own sub-tables (`[lights.shadow]`).
    let body_start = start + rest.find('\n')? + 1;
    let body_len = text[body_start..]
        .match_indices('\n')
        .map(|(i, _)| i + 1)
        .find(|&i| {
            let line = text[body_start + i..].trim_start();
            line.starts_with('[') && !line.starts_with(SUB_TABLE)
        })
        .unwrap_or(text.len() - body_start);
    let body = &text[body_start..body_start + body_len];
    let kind = toml::from_str::<toml::Table>(body)
        .ok()?
        .get("type")?
        .as_str()?
        .to_owned();
    // The same text without its `type` line (kept as an empty line), and its sub-table headers
    // made the struct's own (`[lights.shadow]` read as `[       shadow]`), so offsets still
    // match.
    let untyped: String = body
        .split_inclusive('\n')
        .map(|line| {
            let key = line.trim_start();
            let is_type = key
                .strip_prefix("type")
                .is_some_and(|after| after.trim_start().starts_with('='));
            if is_type {
                " ".repeat(line.trim_end_matches('\n').len())
                    + if line.ends_with('\n') { "\n" } else { "" }
            } else if key.starts_with(SUB_TABLE) {
                line.replacen(
                    SUB_TABLE,
                    &format!("[{}", " ".repeat(SUB_TABLE.len() - 1)),
                    1,
                )
            } else {
                line.to_owned()
            }
        })
        .collect();
    let error = match kind.as_str() {
        "directional" => toml::from_str::<DirectionalLightSpec>(&untyped).err()?,
        "point" => toml::from_str::<PointLightSpec>(&untyped).err()?,
        _ => return None,
    };
    Some((
        body_start + error.span()?.start,
        error.message().trim().to_owned(),
    ))
}
