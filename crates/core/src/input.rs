//! Opening an input file that aloft reads: regular files only.
//!
//! A FIFO, a device or a directory given where a file is expected would block in `open()` (a
//! FIFO with no writer) or read for ever (a device), so it is refused before it is opened, with an
//! error that says what it is. Reading standard input is a separate, explicit choice of the caller.

use std::fs::File;
use std::io;
use std::path::Path;

/// What kind of file system object `path` is, in words (`a directory`, `a FIFO`, ...), or `None`
/// for a regular file (links are followed).
///
/// # Errors
/// The path cannot be examined (it does not exist, no permission).
pub fn non_regular_kind(path: &Path) -> io::Result<Option<&'static str>> {
    let ft = std::fs::metadata(path)?.file_type();
    Ok((!ft.is_file()).then(|| kind_in_words(&ft)))
}

/// What a file system object of type `ft` is, in words: `a regular file`, `a directory`,
/// `a FIFO (named pipe)`, `a socket`, `a device`, `a link`.
pub fn kind_in_words(ft: &std::fs::FileType) -> &'static str {
    if ft.is_file() {
        return "a regular file";
    }
    if ft.is_dir() {
        return "a directory";
    }
    if ft.is_symlink() {
        return "a link";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if ft.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if ft.is_socket() {
            return "a socket";
        }
        if ft.is_char_device() || ft.is_block_device() {
            return "a device";
        }
    }
    "not a regular file"
}

/// Open `path` for reading if it is a regular file; anything else is refused before it is opened
/// (an [`io::ErrorKind::InvalidInput`] error whose message says what it is).
///
/// # Errors
/// The path cannot be examined or opened, or it is not a regular file.
pub fn open_regular_file(path: &Path) -> io::Result<File> {
    if let Some(kind) = non_regular_kind(path)? {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{kind}, not a regular file: aloft reads inputs from regular files"),
        ));
    }
    File::open(path)
}

/// The text of the regular file at `path`, refusing files larger than `max_bytes` before reading
/// them (whole-file inputs such as vehicle and mission files are small; a huge one is a mistake,
/// and reading it would make memory grow with it).
///
/// # Errors
/// As [`open_regular_file`]; a file over the limit ([`io::ErrorKind::InvalidData`], the message
/// gives both sizes); text that is not UTF-8.
pub fn read_regular_text(path: &Path, max_bytes: u64) -> io::Result<String> {
    use std::io::Read;
    let file = open_regular_file(path)?;
    let len = file.metadata()?.len();
    if len > max_bytes {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!("{len} bytes, more than the {max_bytes} bytes aloft reads from such a file"),
        ));
    }
    let mut text = String::new();
    // `take` also bounds a file that grows while it is read.
    file.take(max_bytes + 1).read_to_string(&mut text)?;
    if text.len() as u64 > max_bytes {
        return Err(io::Error::new(
            io::ErrorKind::InvalidData,
            format!("more than the {max_bytes} bytes aloft reads from such a file"),
        ));
    }
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn directories_are_refused_and_files_read() {
        let dir = std::env::temp_dir();
        let e = open_regular_file(&dir).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::InvalidInput);
        assert!(e.to_string().contains("directory"), "{e}");
        let p = dir.join(format!("aloft-core-input-{}.txt", std::process::id()));
        std::fs::write(&p, "hello").unwrap();
        assert_eq!(read_regular_text(&p, 5).unwrap(), "hello");
        let e = read_regular_text(&p, 4).unwrap_err();
        assert!(e.to_string().contains("5 bytes"), "{e}");
        std::fs::remove_file(&p).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_is_refused_without_blocking() {
        let p = std::env::temp_dir().join(format!("aloft-core-fifo-{}", std::process::id()));
        let made = std::process::Command::new("mkfifo").arg(&p).status();
        if !made.is_ok_and(|s| s.success()) {
            return; // no mkfifo on this system: nothing to test
        }
        let e = open_regular_file(&p).unwrap_err();
        assert!(e.to_string().contains("FIFO"), "{e}");
        std::fs::remove_file(&p).unwrap();
    }
}
