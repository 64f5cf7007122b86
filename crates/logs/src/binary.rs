//! Binary flight logs (PX4 ULog, ArduPilot DataFlash) as streams of joined [`Sample`]s.
//!
//! [`BinarySamples`] drives a sans-I/O decoder ([`crate::ulog::UlogDecoder`],
//! [`crate::dataflash::DataflashDecoder`]) over any [`Read`] through a bounded [`ByteWindow`],
//! and joins the decoded topics with the [`Joiner`] (the format-neutral part, `binary_samples.rs`,
//! below both decoders). [`read_ulog`] and [`read_dataflash`] read a whole log from bytes (the
//! entry points of the fuzz harness): a corrupt or truncated log yields its valid prefix and
//! warnings with byte offsets, never a panic.
//!
//! [`Sample`]: crate::sample::Sample
//! [`ByteWindow`]: crate::bytes::ByteWindow
//! [`Joiner`]: crate::join::Joiner

use std::io::Read;

use crate::binary_samples::read_all;
use crate::error::Result;

pub use crate::binary_samples::{
    BinaryLog, BinaryOptions, BinarySamples, BinarySummary, Decoder, MAX_BATTERY_CAPACITY_MAH,
    MIN_BATTERY_COVERAGE,
};

/// Read a whole PX4 ULog from `reader` (bytes in memory or a file). Never panics: a corrupt or
/// truncated log gives its valid prefix and warnings. Errors only when the input is not a ULog.
pub fn read_ulog<R: Read>(reader: R, options: &BinaryOptions) -> Result<BinaryLog> {
    let it = crate::ulog::ulog_samples(reader, options, std::path::Path::new("<bytes>"))?;
    Ok(read_all(it, "<bytes>"))
}

/// Read a whole ArduPilot DataFlash log from `reader`. Never panics: a corrupt or truncated log
/// gives its valid prefix and warnings. Errors only when the input is not a DataFlash log.
pub fn read_dataflash<R: Read>(reader: R, options: &BinaryOptions) -> Result<BinaryLog> {
    let it = crate::dataflash::dataflash_samples(reader, options, std::path::Path::new("<bytes>"))?;
    Ok(read_all(it, "<bytes>"))
}
