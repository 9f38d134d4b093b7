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

/// A file's bytes as UTF-8: a UTF-16 file with a byte-order mark (some exporters write OBJ and
/// MTL that way) is decoded, with a warning naming the file and the encoding (unpaired
/// surrogates become U+FFFD); a UTF-8 byte-order mark is dropped; anything else is returned as
/// it is, for [`LossyLines`].
pub(crate) fn utf8_bytes<'a>(path: &Path, bytes: &'a [u8]) -> (Cow<'a, [u8]>, Option<String>) {
    let (big_endian, encoding) = match bytes {
        [0xFF, 0xFE, ..] => (false, "UTF-16 LE"),
        [0xFE, 0xFF, ..] => (true, "UTF-16 BE"),
        [0xEF, 0xBB, 0xBF, rest @ ..] => return (Cow::Borrowed(rest), None),
        _ => return (Cow::Borrowed(bytes), None),
    };
    let units = bytes.get(2..).unwrap_or_default().chunks(2).map(|pair| {
        let pair = [
            pair.first().copied().unwrap_or(0),
            pair.get(1).copied().unwrap_or(0),
        ];
        if big_endian {
            u16::from_be_bytes(pair)
        } else {
            u16::from_le_bytes(pair)
        }
    });
    let text: String = char::decode_utf16(units)
        .map(|c| c.unwrap_or(char::REPLACEMENT_CHARACTER))
        .collect();
    let warning = format!(
        "{}: {encoding} text (with a byte-order mark), decoded; OBJ and MTL files are usually \
         ASCII or UTF-8",
        path.display()
    );
    (Cow::Owned(text.into_bytes()), Some(warning))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn utf16(text: &str, big_endian: bool) -> Vec<u8> {
        let mut bytes = if big_endian {
            vec![0xFE, 0xFF]
        } else {
            vec![0xFF, 0xFE]
        };
        for unit in text.encode_utf16() {
            bytes.extend(if big_endian {
                unit.to_be_bytes()
            } else {
                unit.to_le_bytes()
            });
        }
        bytes
    }

    #[test]
    fn utf16_with_a_byte_order_mark_is_decoded_with_a_warning() {
        let path = Path::new("box.obj");
        for big_endian in [false, true] {
            let bytes = utf16("v 1 2 3\nf 1 2 3\n", big_endian);
            let (text, warning) = utf8_bytes(path, &bytes);
            assert_eq!(&*text, b"v 1 2 3\nf 1 2 3\n");
            let warning = warning.unwrap();
            assert!(
                warning.starts_with("box.obj: UTF-16") && warning.contains("decoded"),
                "{warning}"
            );
        }
    }

    #[test]
    fn utf8_passes_through_and_its_byte_order_mark_is_dropped() {
        let path = Path::new("a.obj");
        assert_eq!(&*utf8_bytes(path, b"v 1 2 3").0, b"v 1 2 3");
        assert_eq!(&*utf8_bytes(path, b"\xEF\xBB\xBFv 1").0, b"v 1");
        assert!(utf8_bytes(path, b"v 1").1.is_none());
    }
}
