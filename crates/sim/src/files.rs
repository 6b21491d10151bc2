//! Reading a file the project is given (a task file, a URDF, a mesh, a hull cache entry): a
//! regular file under a size cap, checked on the opened file before a byte of it is read.
//!
//! A FIFO blocks its reader (and Ctrl-C with it) until someone writes, a device such as
//! `/dev/zero` never ends, a directory is no file: each is refused, naming what it is. The file
//! is opened without blocking (`O_NONBLOCK`: opening a FIFO that has no writer returns at once;
//! `O_NOCTTY`: a terminal does not become ours) and its kind and size are read from the open
//! descriptor, so a file swapped between a check and the open is caught too. Reading stops one
//! byte past the cap, so a file that grows while it is read is refused as well. The caps are
//! listed in docs/robustness.md ("Files: regular, and bounded").

use std::fs::{File, Metadata};
use std::io::Read;
use std::path::Path;

/// `n` bytes in the largest binary unit that divides it, for messages ("1 MiB").
fn human(n: u64) -> String {
    let units = [(1 << 30, "GiB"), (1 << 20, "MiB"), (1 << 10, "KiB")];
    match units.iter().find(|(size, _)| n >= *size && n.is_multiple_of(*size)) {
        Some((size, unit)) => format!("{} {unit}", n / size),
        None => format!("{n} bytes"),
    }
}

/// What a file that is not a regular file is, for messages ("a FIFO"), where known.
fn kind(meta: &Metadata) -> Option<&'static str> {
    let t = meta.file_type();
    if t.is_dir() {
        return Some("a directory");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return Some("a FIFO");
        }
        if t.is_char_device() {
            return Some("a character device");
        }
        if t.is_block_device() {
            return Some("a block device");
        }
        if t.is_socket() {
            return Some("a socket");
        }
    }
    None
}

/// The sentence refusing a file of `size` bytes over `cap` (`what`: "a task file").
pub fn too_large(size: u64, cap: u64, what: &str) -> String {
    format!(
        "is {size} bytes, more than the {cap} bytes ({}) {what} may have",
        human(cap)
    )
}

/// `path` opened for reading, with its metadata, if it is a regular file of at most `cap`
/// bytes; otherwise a sentence saying why not (the caller adds the path): "cannot read it:
/// …", "is not a regular file (a FIFO)", "is N bytes, more than the … `what` may
/// have".
pub fn open_regular(path: &Path, cap: u64, what: &str) -> Result<(File, Metadata), String> {
    let cannot = |e: std::io::Error| format!("cannot read it: {e}");
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY);
    }
    let file = options.open(path).map_err(cannot)?;
    let meta = file.metadata().map_err(cannot)?;
    if !meta.is_file() {
        return Err(match kind(&meta) {
            Some(what_it_is) => format!("is not a regular file ({what_it_is})"),
            None => "is not a regular file".to_string(),
        });
    }
    if meta.len() > cap {
        return Err(too_large(meta.len(), cap, what));
    }
    Ok((file, meta))
}

/// The bytes of `file` (opened by [`open_regular`] with `meta`), at most `cap` of them: one
/// more (the file grew since it was opened) is refused.
pub fn read_opened(file: File, meta: &Metadata, cap: u64, what: &str) -> Result<Vec<u8>, String> {
    let mut bytes = Vec::new();
    bytes
        .try_reserve_exact(usize::try_from(meta.len()).unwrap_or(usize::MAX))
        .map_err(|e| format!("cannot read it: {e}"))?;
    file.take(cap.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read it: {e}"))?;
    if bytes.len() as u64 > cap {
        return Err(too_large(bytes.len() as u64, cap, what));
    }
    Ok(bytes)
}

/// The bytes of the regular file `path`, at most `cap` of them ([`open_regular`],
/// [`read_opened`]); `what` names the kind of file in the refusal ("a URDF").
pub fn read_bounded(path: &Path, cap: u64, what: &str) -> Result<Vec<u8>, String> {
    let (file, meta) = open_regular(path, cap, what)?;
    read_opened(file, &meta, cap, what)
}

/// [`read_bounded`] as UTF-8 text; the refusal names the line and byte that are not (a Latin-1
/// comment), as an editor shows them, not a byte offset.
pub fn read_text(path: &Path, cap: u64, what: &str) -> Result<String, String> {
    String::from_utf8(read_bounded(path, cap, what)?).map_err(|e| {
        let (bytes, at) = (e.as_bytes(), e.utf8_error().valid_up_to());
        let line = bytes[..at].iter().filter(|&&b| b == b'\n').count() + 1;
        format!(
            "is not UTF-8 text (line {line} has byte {:#04x}); save it as UTF-8",
            bytes[at]
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("latentrl-files-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn issue38_a_regular_file_under_the_cap_is_read_whole() {
        let dir = scratch("regular");
        let path = dir.join("a.txt");
        std::fs::write(&path, "hello").unwrap();
        assert_eq!(read_text(&path, 5, "a test file").unwrap(), "hello");
        let err = read_text(&path, 4, "a test file").unwrap_err();
        assert_eq!(err, "is 5 bytes, more than the 4 bytes (4 bytes) a test file may have");
        assert_eq!(
            read_bounded(&path, 4 << 20, "x").map(|b| b.len()),
            Ok(5),
            "the cap is an upper bound"
        );
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn issue38_directories_devices_and_missing_files_are_refused_by_kind() {
        let dir = scratch("kinds");
        let err = read_bounded(&dir, 1 << 20, "a test file").unwrap_err();
        assert_eq!(err, "is not a regular file (a directory)");
        #[cfg(unix)]
        {
            let err = read_bounded(Path::new("/dev/zero"), 1 << 20, "a test file").unwrap_err();
            assert_eq!(err, "is not a regular file (a character device)");
        }
        let err = read_bounded(&dir.join("missing"), 1 << 20, "a test file").unwrap_err();
        assert!(err.starts_with("cannot read it: "), "{err}");
        assert_eq!(human(1 << 20), "1 MiB");
        assert_eq!(human(128 << 20), "128 MiB");
        assert_eq!(human(1000), "1000 bytes");
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn a_file_that_is_not_utf8_is_refused_naming_its_line_and_byte() {
        // A URDF with a Latin-1 comment said "invalid utf-8 sequence of 1 bytes from index 61".
        let dir = scratch("latin1");
        let path = dir.join("robot.urdf");
        std::fs::write(&path, b"<?xml version=\"1.0\"?>\n<!-- Bras articul\xe9 -->\n<robot/>\n").unwrap();
        let err = read_text(&path, 1 << 20, "a URDF").unwrap_err();
        assert_eq!(err, "is not UTF-8 text (line 2 has byte 0xe9); save it as UTF-8");
        std::fs::remove_dir_all(dir).unwrap();
    }
}
