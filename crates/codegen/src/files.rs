//! Writing generated files: the one helper the `motorgen` CLI and the build scripts
//! share (the design path itself does no file I/O).

use std::path::Path;

/// Writes `bytes` to `path` unless it already holds exactly them (so an unchanged
/// output keeps its timestamp and nothing downstream rebuilds); returns whether it wrote.
pub fn write_if_changed(path: &Path, bytes: &[u8]) -> std::io::Result<bool> {
    if std::fs::read(path).is_ok_and(|old| old == bytes) {
        return Ok(false);
    }
    std::fs::write(path, bytes).map(|()| true)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_only_changes() {
        let dir = std::env::temp_dir().join(format!("codegen-files-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("out.rs");
        let _ = std::fs::remove_file(&path);
        assert!(write_if_changed(&path, b"a").unwrap());
        assert!(!write_if_changed(&path, b"a").unwrap());
        assert!(write_if_changed(&path, b"b").unwrap());
        assert_eq!(std::fs::read(&path).unwrap(), b"b");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
