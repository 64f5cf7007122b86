//! `aloft live --mcap FILE`: the updates recorded for Foxglove, one `/aloft/live` message each
//! (the JSON line as it is), streamed: memory is one chunk whatever the flight's length.

use std::path::{Path, PathBuf};

use aloft_logs::mcap_write::TOPIC_LIVE;
use aloft_logs::McapFile;

use super::LiveUpdate;
use crate::error::Error;

/// An MCAP file the updates go to.
pub struct LiveRecorder {
    path: PathBuf,
    writer: McapFile,
    written: usize,
}

impl LiveRecorder {
    /// Start the file `path`, in aloft's one way ([`McapFile`]): written beside it and placed by
    /// [`LiveRecorder::finish`]; an existing file is replaced only with `force`.
    ///
    /// # Errors
    /// A file that exists (without `force`) or cannot be created.
    pub fn create(path: &Path, force: bool) -> Result<Self, Error> {
        let writer = McapFile::create(path, force)?;
        Ok(Self {
            path: path.to_path_buf(),
            writer,
            written: 0,
        })
    }

    /// Record one update.
    ///
    /// # Errors
    /// A write that fails.
    pub fn record(&mut self, update: &LiveUpdate) -> Result<(), Error> {
        let value = serde_json::to_value(update).map_err(|e| Error::Io {
            origin: self.path.display().to_string(),
            source: e.into(),
        })?;
        let serde_json::Value::Object(map) = value else {
            return Ok(());
        };
        self.writer
            .write_object(
                TOPIC_LIVE,
                "aloft.LiveUpdate",
                update.time_s,
                self.written,
                map,
            )
            .map_err(|e| Error::LogFile(Box::new(e)))?;
        self.written += 1;
        Ok(())
    }

    /// Finish the file (its summary and index) and put it in place: the number of updates
    /// recorded.
    ///
    /// # Errors
    /// A write that fails, or a file that cannot be placed.
    pub fn finish(self) -> Result<usize, Error> {
        self.writer.commit()?;
        Ok(self.written)
    }
}
