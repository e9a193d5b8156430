//! Reading an input file as text, as every reader of scenes, fabrics and meshes does: only a
//! regular file (a FIFO or a device would block the run or never end), a UTF-8 byte-order mark
//! dropped (Windows editors write one; left in, it turns the first line into garbage), and bytes
//! that are not UTF-8 either named by their line (TOML) or read as replacement characters where
//! they can only sit in comments and names (OBJ).

use std::path::Path;

/// Whether `path` is a regular file (following links); why not otherwise.
pub fn check_regular_file(path: &Path) -> Result<(), String> {
    let meta = std::fs::metadata(path).map_err(|e| format!("cannot read: {e}"))?;
    if meta.is_file() {
        Ok(())
    } else if meta.is_dir() {
        Err("is a directory, not a file: name the file inside it".into())
    } else {
        Err("is not a regular file (a pipe, socket or device): copy it into a file first".into())
    }
}

/// How bytes that are not UTF-8 are taken.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NonUtf8 {
    /// Refused, naming the line (formats whose values are text: TOML, JSON).
    Refuse,
    /// Read as U+FFFD (formats whose text outside numbers is comments and names: OBJ).
    Replace,
}

/// The text of the regular file `path`, its byte-order mark dropped; errors say why in words
/// (the caller names the file and key).
pub fn read_text(path: &Path, non_utf8: NonUtf8) -> Result<String, String> {
    check_regular_file(path)?;
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read: {e}"))?;
    let body = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&bytes);
    match std::str::from_utf8(body) {
        Ok(s) => Ok(s.to_string()),
        Err(_) if non_utf8 == NonUtf8::Replace => Ok(String::from_utf8_lossy(body).into_owned()),
        Err(e) => {
            let at = e.valid_up_to();
            let line = body[..at].iter().filter(|&&b| b == b'\n').count() + 1;
            Err(format!(
                "line {line}: byte 0x{:02x} is not UTF-8: save the file as UTF-8",
                body[at]
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bom_is_dropped_and_a_latin1_byte_is_named_by_its_line() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("a.txt");
        std::fs::write(&f, b"\xEF\xBB\xBFv 1 2 3\n# caf\xE9\nv 4 5 6\n").unwrap();
        let e = read_text(&f, NonUtf8::Refuse).unwrap_err();
        assert!(e.starts_with("line 2:"), "{e}");
        let t = read_text(&f, NonUtf8::Replace).unwrap();
        assert!(t.starts_with("v 1 2 3\n"), "{t:?}");
        assert_eq!(t.lines().count(), 3);
        assert!(check_regular_file(dir.path()).is_err());
    }
}
