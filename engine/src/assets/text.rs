//! OBJ and MTL text, read line by line and lenient about encoding: bytes that are not UTF-8
//! (Latin-1 comments and names are common in real files) are decoded with U+FFFD in their
//! place, and the file gets one warning naming the first such line and byte.

use std::borrow::Cow;
use std::path::Path;

/// Decodes a file's lines and remembers which were not UTF-8.
#[derive(Debug, Default)]
pub(super) struct LossyLines {
    /// Lines that were not UTF-8.
    count: usize,
    /// The first of them and the byte (1-based) where it stops being UTF-8.
    first: Option<(usize, usize)>,
}

impl LossyLines {
    /// Line `lineno` (1-based) as text, lossily where it is not UTF-8.
    pub(super) fn decode<'a>(&mut self, lineno: usize, raw: &'a [u8]) -> Cow<'a, str> {
        if let Err(e) = std::str::from_utf8(raw) {
            self.count += 1;
            self.first.get_or_insert((lineno, e.valid_up_to() + 1));
        }
        String::from_utf8_lossy(raw)
    }

    /// The file's warning, if any line was not UTF-8.
    pub(super) fn warning(&self, path: &Path) -> Option<String> {
        let (line, byte) = self.first?;
        Some(format!(
            "{}:{line}: not UTF-8 at byte {byte} ({} lines in all); read with U+FFFD in place \
             of the bad bytes",
            path.display(),
            self.count
        ))
    }
}
