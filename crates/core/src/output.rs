//! Writing an output file: the one way aloft writes a file.
//!
//! Every file aloft writes for its user (a plan's sorties, a pack or vehicle file, a converted
//! log, a time series, a chart) goes through this module, so that the same rules hold for all:
//!
//! 1. **The name is the caller's, never the input's content.** The folder and file name come
//!    from the command line (`-o`); a name derived from an input (the sorties of `aloft plan`)
//!    comes from the input's *file name* only, through [`safe_stem`]: path separators, control
//!    characters and anything outside the portable set `A-Z a-z 0-9 . _ -` replaced, never a
//!    leading dot or dash, never a name taken from inside a file.
//! 2. **A temporary file, then a rename.** The bytes go to a new file with a random name in the
//!    target's own folder, created exclusively (`O_CREAT | O_EXCL`: a link planted at its name is
//!    never followed, the creation fails instead), then renamed into place. A reader never sees
//!    a half-written file, and a failed write leaves the old file as it was.
//! 3. **Nothing is replaced unless asked.** Without `force`, the rename refuses an existing name
//!    (`renameat2(RENAME_NOREPLACE)` where the kernel has it; a link and a dangling link count as
//!    existing). With `force`, only a regular file or a link itself is replaced (the rename
//!    replaces the directory entry, never the link's target); a folder, FIFO, device or socket at
//!    the name is refused, even with `force`.
//! 4. **A set of files is all or nothing** ([`OutputSet`]): every file is written to its
//!    temporary name first; they are renamed into place one after the other, and an error at any
//!    of them removes the ones already placed and puts back the files they replaced.
//! 5. **An interrupted program leaves nothing.** A program that handles SIGINT and SIGTERM calls
//!    [`abandon_all`] before it exits: the temporary files of this process are removed, and a set
//!    being placed is finished first (placing holds the same lock), so a set is never left half
//!    placed. Only an uncatchable kill (SIGKILL, a power cut) can leave a `.aloft-*.tmp` file.
//!
//! The shapes are those of `tempfile::NamedTempFile::new_in` + `persist_noclobber` and
//! `std::fs::OpenOptions::create_new`.

use std::fs::File;
use std::io::{self, Seek, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

use tempfile::NamedTempFile;

/// The prefix of every temporary file aloft creates beside an output.
pub const TEMP_PREFIX: &str = ".aloft-";
/// The suffix of every temporary file aloft creates beside an output.
pub const TEMP_SUFFIX: &str = ".tmp";
/// The longest stem [`safe_stem`] gives, in bytes (file systems allow 255 for a whole name; the
/// rest is left for suffixes such as `-12-of-40.plan`).
pub const MAX_STEM_BYTES: usize = 100;

/// Why an output was not written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum OutputError {
    /// Something is already at the output's name, and `force` was not given.
    #[error("{} exists: aloft keeps it (--force replaces it)", shown(.path))]
    Exists {
        /// The output's path.
        path: PathBuf,
    },
    /// Something at the output's name that aloft never replaces, even with `force`.
    #[error("{} is {kind}: aloft replaces only a regular file or a link, even with --force", shown(.path))]
    NotReplaceable {
        /// The output's path.
        path: PathBuf,
        /// What is there, in words (`a FIFO (named pipe)`, `a device`, `a directory`).
        kind: &'static str,
    },
    /// The output's folder does not exist or is not a folder.
    #[error("cannot write {}: its folder {} does not exist", shown(.path), shown(.folder))]
    NoFolder {
        /// The output's path.
        path: PathBuf,
        /// Its folder.
        folder: PathBuf,
    },
    /// A set names the same output twice.
    #[error("{} is named twice in one set of outputs", shown(.path))]
    Duplicate {
        /// The output's path.
        path: PathBuf,
    },
    /// The file system refused a step.
    #[error("cannot write {}: {source}", shown(.path))]
    Io {
        /// The output's path.
        path: PathBuf,
        /// The system's error.
        source: io::Error,
    },
    /// The program was interrupted ([`abandon_all`]) before the output was placed.
    #[error("interrupted: {} was not written", shown(.path))]
    Interrupted {
        /// The output's path.
        path: PathBuf,
    },
}

impl OutputError {
    fn io(path: &Path) -> impl FnOnce(io::Error) -> Self + '_ {
        move |source| Self::Io {
            path: path.to_path_buf(),
            source,
        }
    }
}

/// `text` with its control characters (a newline, an escape sequence) and the bidirectional
/// overrides (U+202A-U+202E, U+2066-U+2069, which reorder what follows them on a terminal)
/// written as Rust escapes (`\n`, `\u{1b}`), the rest as it is: a message, a table row or a
/// comment line of a written file that quotes a file name or a reason stays one line and shows
/// what is there.
///
/// ```
/// use aloft_core::output::escaped;
/// assert_eq!(escaped("flight 3.ulg"), "flight 3.ulg");
/// assert_eq!(escaped("x\nmass_kg = 99"), "x\\nmass_kg = 99");
/// ```
pub fn escaped(text: &str) -> std::borrow::Cow<'_, str> {
    let hidden = |c: char| {
        c.is_control()
            || ('\u{202a}'..='\u{202e}').contains(&c)
            || ('\u{2066}'..='\u{2069}').contains(&c)
    };
    if !text.chars().any(hidden) {
        return std::borrow::Cow::Borrowed(text);
    }
    std::borrow::Cow::Owned(
        text.chars()
            .map(|c| match c {
                c if hidden(c) => c.escape_default().to_string(),
                c => c.to_string(),
            })
            .collect(),
    )
}

/// A path as messages show it ([`escaped`]), so that a message stays on one line.
pub fn shown(path: &Path) -> String {
    escaped(&path.display().to_string()).into_owned()
}

/// The stem of an output name taken from an input's file name (`survey.plan` gives `survey`),
/// safe to join to any folder: only the last component of `input` is used, its extension is
/// dropped, and every character outside `A-Z a-z 0-9 . _ -` (a path separator, a control
/// character, a space, markup, any non-ASCII letter) becomes `_`, as does a leading `.` or `-`;
/// at most [`MAX_STEM_BYTES`]. `None` when nothing is left (an empty name, `..`, `/`).
///
/// ```
/// use aloft_core::output::safe_stem;
/// use std::path::Path;
/// assert_eq!(safe_stem(Path::new("missions/survey.plan")).as_deref(), Some("survey"));
/// assert_eq!(safe_stem(Path::new("<img src=x>.plan")).as_deref(), Some("_img_src_x_"));
/// assert_eq!(safe_stem(Path::new("../../etc/passwd")).as_deref(), Some("passwd"));
/// assert_eq!(safe_stem(Path::new("..")), None);
/// ```
pub fn safe_stem(input: &Path) -> Option<String> {
    let name = input.file_name()?;
    let stem = Path::new(name)
        .file_stem()
        .unwrap_or(name)
        .to_string_lossy();
    let mut out: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-') {
                c
            } else {
                '_'
            }
        })
        .collect();
    if out.starts_with(['.', '-']) {
        out.replace_range(..1, "_");
    }
    out.truncate(MAX_STEM_BYTES);
    (!out.is_empty() && out.chars().any(|c| c != '_')).then_some(out)
}

/// The temporary files of this process, and whether it was told to stop.
struct Journal {
    temps: Vec<PathBuf>,
    abandoned: bool,
}

static JOURNAL: Mutex<Journal> = Mutex::new(Journal {
    temps: Vec::new(),
    abandoned: false,
});

/// The journal, even if a thread panicked while holding it (its lists stay consistent: every
/// change is one push or one removal).
fn journal() -> MutexGuard<'static, Journal> {
    JOURNAL
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

impl Journal {
    fn forget(&mut self, temp: &Path) {
        self.temps.retain(|t| t != temp);
    }
}

/// Remove every temporary file of this process's outputs and refuse to place any output from now
/// on; the number removed. For a program's SIGINT and SIGTERM handler, which exits right after:
/// a set being placed at that moment is finished first (placing holds the same lock), so the
/// folder holds the whole set or none of it.
///
/// ```
/// use aloft_core::output::{abandon_all, Output, OutputError};
/// use std::io::Write;
/// let dir = std::env::temp_dir().join(format!("aloft-abandon-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let mut out = Output::create(&dir.join("log.mcap"), false)?;
/// out.write_all(b"half of a log")?;
/// assert_eq!(abandon_all(), 1); // the temporary file is gone
/// assert!(matches!(out.commit(), Err(OutputError::Interrupted { .. })));
/// assert_eq!(std::fs::read_dir(&dir)?.count(), 0);
/// # std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn abandon_all() -> usize {
    let mut j = journal();
    j.abandoned = true;
    let temps = std::mem::take(&mut j.temps);
    temps
        .iter()
        .filter(|t| std::fs::remove_file(t).is_ok())
        .count()
}

/// What is at `path` (not following a link), in words, when it is something aloft never
/// replaces; `None` for nothing, a regular file or a link.
fn unreplaceable(path: &Path) -> io::Result<Option<&'static str>> {
    let meta = match std::fs::symlink_metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(e),
    };
    let ft = meta.file_type();
    if ft.is_file() || ft.is_symlink() {
        return Ok(None);
    }
    Ok(Some(crate::input::kind_in_words(&ft)))
}

/// Whether anything (a dangling link included) is at `path`.
fn occupied(path: &Path) -> bool {
    std::fs::symlink_metadata(path).is_ok()
}

/// Check that `target` may be written: nothing there, or (with `force`) a regular file or a link.
fn check_target(target: &Path, force: bool) -> Result<(), OutputError> {
    if let Some(kind) = unreplaceable(target).map_err(OutputError::io(target))? {
        return Err(OutputError::NotReplaceable {
            path: target.to_path_buf(),
            kind,
        });
    }
    if !force && occupied(target) {
        return Err(OutputError::Exists {
            path: target.to_path_buf(),
        });
    }
    Ok(())
}

/// Check, before long work, that `target` could be written: its folder exists, and nothing is
/// there (or, with `force`, a regular file or a link). [`Output::commit`] checks again.
///
/// # Errors
/// [`OutputError::Exists`], [`OutputError::NotReplaceable`], [`OutputError::NoFolder`].
pub fn check(target: &Path, force: bool) -> Result<(), OutputError> {
    check_target(target, force)?;
    folder_of(target).map(drop)
}

/// The folder of `target` (`.` for a bare name), which must exist.
fn folder_of(target: &Path) -> Result<PathBuf, OutputError> {
    let folder = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if target.file_name().is_none() || !folder.is_dir() {
        return Err(OutputError::NoFolder {
            path: target.to_path_buf(),
            folder,
        });
    }
    Ok(folder)
}

/// A new temporary file beside `target` (random name, created exclusively, mode 0666 less the
/// umask as `File::create` gives), recorded in the journal.
fn temp_beside(target: &Path) -> Result<NamedTempFile, OutputError> {
    let folder = folder_of(target)?;
    let mut builder = tempfile::Builder::new();
    builder.prefix(TEMP_PREFIX).suffix(TEMP_SUFFIX);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut j = journal();
    if j.abandoned {
        return Err(OutputError::Interrupted {
            path: target.to_path_buf(),
        });
    }
    let temp = builder
        .tempfile_in(&folder)
        .map_err(OutputError::io(target))?;
    j.temps.push(temp.path().to_path_buf());
    Ok(temp)
}

/// One output file being written: its bytes go to a temporary file beside the target
/// ([`Output::create`], then [`Write`]), and [`Output::commit`] puts it in place. Dropped without
/// a commit (an error on the way), the temporary file is removed and the target left as it was.
///
/// ```
/// use std::io::Write;
/// let dir = std::env::temp_dir().join(format!("aloft-output-doc-{}", std::process::id()));
/// std::fs::create_dir_all(&dir)?;
/// let path = dir.join("pack.toml");
/// let mut out = aloft_core::output::Output::create(&path, false)?;
/// out.write_all(b"name = \"pack\"\n")?;
/// out.commit()?;
/// assert!(aloft_core::output::Output::create(&path, false).is_err()); // kept without force
/// # std::fs::remove_dir_all(&dir)?;
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct Output {
    target: PathBuf,
    force: bool,
    temp: Option<NamedTempFile>,
}

impl std::fmt::Debug for Output {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Output")
            .field("target", &self.target)
            .field("force", &self.force)
            .finish_non_exhaustive()
    }
}

impl Output {
    /// Start writing `target`: checked first (nothing there, or with `force` a regular file or a
    /// link; its folder exists), then a temporary file beside it.
    ///
    /// # Errors
    /// [`OutputError::Exists`], [`OutputError::NotReplaceable`], [`OutputError::NoFolder`],
    /// [`OutputError::Io`], [`OutputError::Interrupted`].
    pub fn create(target: &Path, force: bool) -> Result<Self, OutputError> {
        check_target(target, force)?;
        let temp = temp_beside(target)?;
        Ok(Self {
            target: target.to_path_buf(),
            force,
            temp: Some(temp),
        })
    }

    /// Where the output goes.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// The temporary file the bytes go to (for writers that need a `File`, such as one that
    /// seeks).
    pub fn file(&mut self) -> &mut File {
        // `temp` is `Some` from creation until `commit` or drop consume the value.
        self.temp
            .as_mut()
            .map(NamedTempFile::as_file_mut)
            .expect("an output's temporary file lives until it is committed")
    }

    /// Put the output in place: its bytes flushed to disk, then renamed to the target (without
    /// `force` only if nothing is there; with `force` over a regular file or a link only).
    ///
    /// # Errors
    /// As [`Output::create`], checked again at this moment; the temporary file is removed.
    pub fn commit(mut self) -> Result<(), OutputError> {
        let temp = self.take_temp();
        temp.as_file()
            .sync_data()
            .map_err(OutputError::io(&self.target))?;
        place(temp, &self.target, self.force, &mut journal())
    }

    fn take_temp(&mut self) -> NamedTempFile {
        self.temp
            .take()
            .expect("an output's temporary file lives until it is committed")
    }
}

impl Write for Output {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.file().write(buf)
    }
    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        self.file().write_all(buf)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.file().flush()
    }
}

impl Seek for Output {
    fn seek(&mut self, pos: io::SeekFrom) -> io::Result<u64> {
        self.file().seek(pos)
    }
}

impl Drop for Output {
    fn drop(&mut self) {
        if let Some(temp) = self.temp.take() {
            journal().forget(temp.path());
            drop(temp); // removes the file
        }
    }
}

/// Rename `temp` to `target`, holding the journal's lock `j`: without `force` only if nothing is
/// there, with `force` over a regular file or a link only (checked again now). The journal
/// forgets the temporary file either way: it is placed, or removed with `temp`.
fn place(
    temp: NamedTempFile,
    target: &Path,
    force: bool,
    j: &mut Journal,
) -> Result<(), OutputError> {
    j.forget(temp.path());
    if j.abandoned {
        return Err(OutputError::Interrupted {
            path: target.to_path_buf(),
        });
    }
    check_target(target, force)?;
    let persisted = if force {
        temp.persist(target).map(drop)
    } else {
        temp.persist_noclobber(target).map(drop)
    };
    persisted.map_err(|e| match e.error.kind() {
        io::ErrorKind::AlreadyExists => OutputError::Exists {
            path: target.to_path_buf(),
        },
        _ => OutputError::Io {
            path: target.to_path_buf(),
            source: e.error,
        },
    })
}

/// Write `bytes` to `target` as one [`Output`].
///
/// # Errors
/// As [`Output::create`] and [`Output::commit`].
pub fn write_file(target: &Path, bytes: &[u8], force: bool) -> Result<(), OutputError> {
    let mut out = Output::create(target, force)?;
    out.write_all(bytes).map_err(OutputError::io(target))?;
    out.commit()
}

/// A set of files written all or nothing (the sorties of a plan): each is written to its
/// temporary file by [`OutputSet::add`]; [`OutputSet::commit`] places them all, or none.
#[derive(Debug, Default)]
pub struct OutputSet {
    outputs: Vec<Output>,
}

impl OutputSet {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Write `bytes` for `target` to a temporary file (nothing is placed yet).
    ///
    /// # Errors
    /// As [`Output::create`]; a target already in the set.
    pub fn add(&mut self, target: &Path, bytes: &[u8], force: bool) -> Result<(), OutputError> {
        if self.outputs.iter().any(|o| o.target == target) {
            return Err(OutputError::Duplicate {
                path: target.to_path_buf(),
            });
        }
        let mut out = Output::create(target, force)?;
        out.write_all(bytes).map_err(OutputError::io(target))?;
        self.outputs.push(out);
        Ok(())
    }

    /// Add an output already written (a stream such as a time series); nothing is placed yet.
    ///
    /// # Errors
    /// A target already in the set.
    pub fn push(&mut self, out: Output) -> Result<(), OutputError> {
        if self.outputs.iter().any(|o| o.target == out.target) {
            return Err(OutputError::Duplicate {
                path: out.target.clone(),
            });
        }
        self.outputs.push(out);
        Ok(())
    }

    /// Place every file of the set, or none: each target is checked again first; a file that
    /// `force` replaces is moved aside until the whole set is in place; an error at any file
    /// removes those already placed and puts the replaced ones back.
    ///
    /// # Errors
    /// As [`Output::commit`], for the first file that cannot be placed.
    pub fn commit(self) -> Result<(), OutputError> {
        self.commit_with(|_| Ok(()))
    }

    /// [`OutputSet::commit`] with `between(k)` called after the `k`th file is placed (a fault
    /// injected there by the tests).
    fn commit_with(
        mut self,
        mut between: impl FnMut(usize) -> io::Result<()>,
    ) -> Result<(), OutputError> {
        for out in &mut self.outputs {
            let target = out.target.clone();
            out.file().sync_data().map_err(OutputError::io(&target))?;
        }
        let mut j = journal();
        for out in &self.outputs {
            check_target(&out.target, out.force)?;
        }
        let mut placed = Placed::default();
        for (k, out) in self.outputs.iter_mut().enumerate() {
            let step = placed
                .place_one(out, &mut j)
                .and_then(|()| between(k).map_err(OutputError::io(&out.target)));
            if let Err(e) = step {
                placed.undo();
                return Err(e);
            }
        }
        placed.finish();
        Ok(())
    }
}

/// The files of a set placed so far, and the ones they replaced (moved aside until the set is
/// whole). The journal's lock is held from the first to the last, so an interrupted program
/// waits for the set.
#[derive(Default)]
struct Placed {
    targets: Vec<PathBuf>,
    /// (where a replaced file waits, its own name)
    aside: Vec<(PathBuf, PathBuf)>,
}

impl Placed {
    /// Place one output of the set: a file at its name (which `force` allows) moved aside first.
    fn place_one(&mut self, out: &mut Output, j: &mut Journal) -> Result<(), OutputError> {
        let target = out.target.clone();
        if out.force && occupied(&target) {
            let aside = move_aside(&target)?;
            self.aside.push((aside, target.clone()));
        }
        place(out.take_temp(), &target, false, j)?;
        self.targets.push(target);
        Ok(())
    }

    /// Remove what was placed, put back what was moved aside.
    fn undo(self) {
        for t in &self.targets {
            let _ = std::fs::remove_file(t);
        }
        for (aside, name) in &self.aside {
            let _ = std::fs::rename(aside, name);
        }
    }

    /// The whole set is in place: the files it replaced go.
    fn finish(self) {
        for (aside, _) in &self.aside {
            let _ = std::fs::remove_file(aside);
        }
    }
}

/// Move the file (or link) at `target` to a new random name beside it: a name first created
/// exclusively, then renamed over (it is ours).
fn move_aside(target: &Path) -> Result<PathBuf, OutputError> {
    let folder = folder_of(target)?;
    let holder = tempfile::Builder::new()
        .prefix(TEMP_PREFIX)
        .suffix(TEMP_SUFFIX)
        .tempfile_in(&folder)
        .map_err(OutputError::io(target))?;
    let (_, aside) = holder.keep().map_err(|e| OutputError::Io {
        path: target.to_path_buf(),
        source: e.error,
    })?;
    if let Err(source) = std::fs::rename(target, &aside) {
        let _ = std::fs::remove_file(&aside);
        return Err(OutputError::Io {
            path: target.to_path_buf(),
            source,
        });
    }
    Ok(aside)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A new empty folder of this test's own.
    fn folder(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("aloft-output-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// The names in `dir`, sorted.
    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    fn temps_in(dir: &Path) -> Vec<String> {
        names(dir)
            .into_iter()
            .filter(|n| n.starts_with(TEMP_PREFIX))
            .collect()
    }

    #[test]
    fn a_new_file_is_written_and_kept_without_force() {
        let d = folder("new");
        let p = d.join("a.toml");
        write_file(&p, b"one", false).unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"one");
        let e = write_file(&p, b"two", false).unwrap_err();
        assert!(matches!(e, OutputError::Exists { .. }), "{e}");
        assert!(e.to_string().contains("--force"), "{e}");
        assert_eq!(std::fs::read(&p).unwrap(), b"one");
        write_file(&p, b"two", true).unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"two");
        assert_eq!(names(&d), ["a.toml"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_planted_link_is_never_written_through() {
        let d = folder("link");
        let victim = d.join("victim.txt");
        std::fs::write(&victim, b"precious").unwrap();
        let p = d.join("out.plan");
        std::os::unix::fs::symlink(&victim, &p).unwrap();
        // Without force: the link counts as an existing output.
        let e = write_file(&p, b"evil", false).unwrap_err();
        assert!(matches!(e, OutputError::Exists { .. }), "{e}");
        assert_eq!(std::fs::read(&victim).unwrap(), b"precious");
        // With force: the link itself is replaced by a regular file, its target untouched.
        write_file(&p, b"plan", true).unwrap();
        assert!(std::fs::symlink_metadata(&p).unwrap().file_type().is_file());
        assert_eq!(std::fs::read(&p).unwrap(), b"plan");
        assert_eq!(std::fs::read(&victim).unwrap(), b"precious");
        // A dangling link: nothing is created where it points.
        let q = d.join("dangling.toml");
        let nowhere = d.join("created-through-link");
        std::os::unix::fs::symlink(&nowhere, &q).unwrap();
        assert!(write_file(&q, b"x", false).is_err());
        assert!(!nowhere.exists());
        assert!(temps_in(&d).is_empty());
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_or_a_folder_is_never_replaced_even_with_force() {
        let d = folder("fifo");
        let fifo = d.join("pipe.toml");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            for force in [false, true] {
                let e = write_file(&fifo, b"x", force).unwrap_err();
                assert!(matches!(e, OutputError::NotReplaceable { .. }), "{e}");
                assert!(e.to_string().contains("FIFO"), "{e}");
            }
            use std::os::unix::fs::FileTypeExt;
            assert!(std::fs::symlink_metadata(&fifo)
                .unwrap()
                .file_type()
                .is_fifo());
        }
        let sub = d.join("sub.toml");
        std::fs::create_dir(&sub).unwrap();
        let e = write_file(&sub, b"x", true).unwrap_err();
        assert!(e.to_string().contains("a directory"), "{e}");
        assert!(sub.is_dir());
        assert!(temps_in(&d).is_empty());
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_missing_folder_is_named() {
        let d = folder("nofolder");
        let p = d.join("missing").join("a.toml");
        let e = write_file(&p, b"x", false).unwrap_err();
        assert!(matches!(e, OutputError::NoFolder { .. }), "{e}");
        assert!(e.to_string().contains("missing"), "{e}");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn an_output_dropped_before_its_commit_leaves_nothing() {
        let d = folder("dropped");
        let p = d.join("big.mcap");
        let mut out = Output::create(&p, false).unwrap();
        out.write_all(&[0u8; 4096]).unwrap();
        assert_eq!(temps_in(&d).len(), 1);
        drop(out);
        assert!(names(&d).is_empty());
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_set_is_placed_whole() {
        let d = folder("set");
        let mut set = OutputSet::new();
        for k in 1..=3 {
            set.add(&d.join(format!("s-{k}-of-3.plan")), b"x", false)
                .unwrap();
        }
        assert_eq!(temps_in(&d).len(), 3);
        set.commit().unwrap();
        assert_eq!(
            names(&d),
            ["s-1-of-3.plan", "s-2-of-3.plan", "s-3-of-3.plan"]
        );
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_set_that_fails_at_its_second_file_leaves_no_file_of_it() {
        let d = folder("set-fail");
        let mut set = OutputSet::new();
        for k in 1..=3 {
            set.add(&d.join(format!("s-{k}.plan")), b"new", false)
                .unwrap();
        }
        let e = set
            .commit_with(|k| {
                if k == 1 {
                    Err(io::Error::other("disk full"))
                } else {
                    Ok(())
                }
            })
            .unwrap_err();
        assert!(e.to_string().contains("disk full"), "{e}");
        assert!(names(&d).is_empty(), "{:?}", names(&d));
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_forced_set_that_fails_puts_back_the_files_it_replaced() {
        let d = folder("set-force");
        let old: Vec<PathBuf> = (1..=3).map(|k| d.join(format!("s-{k}.plan"))).collect();
        for (k, p) in old.iter().enumerate() {
            std::fs::write(p, format!("old {k}")).unwrap();
        }
        let mut set = OutputSet::new();
        for p in &old {
            set.add(p, b"new", true).unwrap();
        }
        let e = set.commit_with(|k| {
            if k == 2 {
                Err(io::Error::other("interrupted"))
            } else {
                Ok(())
            }
        });
        assert!(e.is_err());
        for (k, p) in old.iter().enumerate() {
            assert_eq!(std::fs::read_to_string(p).unwrap(), format!("old {k}"));
        }
        assert_eq!(names(&d).len(), 3, "{:?}", names(&d));
        // Committed whole, the new files replace the old ones and nothing else is left.
        let mut set = OutputSet::new();
        for p in &old {
            set.add(p, b"new", true).unwrap();
        }
        set.commit().unwrap();
        for p in &old {
            assert_eq!(std::fs::read(p).unwrap(), b"new");
        }
        assert_eq!(names(&d).len(), 3, "{:?}", names(&d));
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_set_with_an_existing_name_is_refused_before_anything_is_written() {
        let d = folder("set-exists");
        std::fs::write(d.join("s-2.plan"), b"keep").unwrap();
        let mut set = OutputSet::new();
        set.add(&d.join("s-1.plan"), b"new", false).unwrap();
        let e = set.add(&d.join("s-2.plan"), b"new", false).unwrap_err();
        assert!(matches!(e, OutputError::Exists { .. }), "{e}");
        drop(set);
        assert_eq!(names(&d), ["s-2.plan"]);
        let mut set = OutputSet::new();
        set.add(&d.join("a.plan"), b"x", false).unwrap();
        let e = set.add(&d.join("a.plan"), b"x", false).unwrap_err();
        assert!(matches!(e, OutputError::Duplicate { .. }), "{e}");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn stems_keep_the_portable_set_only() {
        let s = |p: &str| safe_stem(Path::new(p));
        assert_eq!(s("survey.plan").as_deref(), Some("survey"));
        assert_eq!(
            s("/abs/dir/Hill survey v2.waypoints").as_deref(),
            Some("Hill_survey_v2")
        );
        assert_eq!(s("a\nb\tc.toml").as_deref(), Some("a_b_c"));
        assert_eq!(s(".hidden").as_deref(), Some("_hidden"));
        assert_eq!(s("-rf.toml").as_deref(), Some("_rf"));
        assert_eq!(s("Höhe\u{202E}lp.plan").as_deref(), Some("H_he_lp"));
        assert_eq!(s("a\\..\\b.plan").as_deref(), Some("a_.._b"));
        assert_eq!(s(""), None);
        assert_eq!(s("/"), None);
        assert_eq!(s(".."), None);
        assert_eq!(s("\u{200B}.plan"), None);
        let long = "x".repeat(300) + ".plan";
        assert_eq!(s(&long).map(|t| t.len()), Some(MAX_STEM_BYTES));
        for odd in [
            "<img src=x onerror=alert(1)>.plan",
            "../escaped",
            "C:\\evil\\x.plan",
        ] {
            let stem = s(odd).unwrap();
            assert!(stem
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || "._-".contains(c)));
            assert!(!stem.starts_with('.'), "{stem}");
        }
    }

    #[test]
    fn paths_in_messages_stay_on_one_line() {
        let e = OutputError::Exists {
            path: PathBuf::from("a\nb.plan"),
        };
        assert!(!e.to_string().contains('\n'), "{e}");
        assert!(e.to_string().contains("a\\nb.plan"), "{e}");
    }
}
