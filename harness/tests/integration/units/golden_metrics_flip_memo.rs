//! Tests of `harness::golden::metrics::flip_memo`.

use harness::golden::metrics::flip_memo::*;

#[test]
fn a_kept_map_is_read_back_whole_or_not_at_all() {
    let dir = tempfile::tempdir().unwrap();
    let key = key(&[1, 2, 3], &[4, 5, 6], 1, 1, 67.0);
    let other = key_of_other();
    assert_ne!(key, other, "the key covers the images");
    write(dir.path(), &key, &[0.25]).unwrap();
    assert_eq!(read(dir.path(), &key, 1), Some(vec![0.25]));
    assert_eq!(read(dir.path(), &other, 1), None);
    // A file of another length (cut short, another size) is not a map of this one.
    assert_eq!(read(dir.path(), &key, 2), None);
    std::fs::write(file(dir.path(), &key), [0u8; 3]).unwrap();
    assert_eq!(read(dir.path(), &key, 1), None);
}

fn key_of_other() -> Key {
    key(&[1, 2, 3], &[4, 5, 7], 1, 1, 67.0)
}
