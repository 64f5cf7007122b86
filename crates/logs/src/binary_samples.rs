//! The format-neutral half of the binary readers, below both decoders.
//!
//! [`BinarySamples`] drives a sans-I/O [`Decoder`] ([`crate::ulog::UlogDecoder`],
//! [`crate::dataflash::DataflashDecoder`]) over any [`Read`] through a bounded [`ByteWindow`],
//! and joins the decoded topics with the [`Joiner`]. [`BinarySummary`] is what a log holds
//! besides its samples, [`BinaryLog`] a whole log read into memory. `binary.rs` picks the decoder.

use std::collections::BTreeMap;
use std::io::Read;

use serde::Serialize;

use crate::bytes::ByteWindow;
use crate::error::Result;
use crate::join::{BatterySummary, Event, Joiner};
use crate::sample::{Log, Sample, TimeChecker, TimeReport};

/// Options of the binary readers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BinaryOptions {
    /// The battery instance to read (PX4 `battery_status` multi_id, ArduPilot `BAT` instance).
    pub battery_instance: u8,
    /// Longest interval of a topic across which values are interpolated, s.
    pub max_bracket_s: f64,
    /// Collect every battery record with its details (cells, resistance, counters), the
    /// battery parameters and the identities, for [`crate::battery_records`] (off: the samples
    /// only).
    pub battery_details: bool,
}

impl Default for BinaryOptions {
    fn default() -> Self {
        // PX4 logs battery_status at 2-10 Hz, ArduPilot BAT at 10 Hz: 1 s bridges a few dropped
        // records, not a gap (the PX4 CSV join's bracket).
        Self {
            battery_instance: 0,
            max_bracket_s: 1.0,
            battery_details: false,
        }
    }
}

/// A battery that covers less than this fraction of the flight (the span of the base topic)
/// does not count as power data.
pub const MIN_BATTERY_COVERAGE: f64 = 0.5;

/// Largest battery capacity a log's parameters may give (a larger or non-finite one is a
/// corrupt parameter and is not read); its home is [`crate::battery_records`].
pub use crate::battery_records::MAX_BATTERY_CAPACITY_MAH;

/// A capacity parameter in mA h as A h, when it is a pack's: from
/// [`crate::battery_records::MIN_BATTERY_CAPACITY_MAH`] (a `BAT1_CAPACITY` of 1e-38 is unset)
/// to [`MAX_BATTERY_CAPACITY_MAH`] (an infinite one made the answer of `log info` not finite).
pub(crate) fn capacity_ah(mah: f64) -> Option<f64> {
    crate::battery_records::plausible_capacity_mah(mah).map(|c| c / 1000.0)
}

/// After a record that cannot be valid at `from`: skip byte by byte to the next offset where a
/// record starts that `plausible` accepts (its length from its first `peek` bytes) and that is
/// followed by another plausible record or by the end of the input; `false` when the input ends
/// first. The skipped bytes go to `s` as corrupt `what` ("ULog record", "DataFlash data").
///
/// Both binary formats have a three-byte record header; `peek` may be longer when `plausible`
/// needs more (a ULog data record's message id).
pub(crate) fn resync<R: Read>(
    w: &mut ByteWindow<R>,
    s: &mut BinarySummary,
    from: u64,
    (what, peek): (&str, usize),
    plausible: impl Fn(&[u8]) -> Option<usize>,
) -> bool {
    w.consume(1);
    loop {
        let h = w.peek_max(peek);
        if h.len() < 3 {
            break;
        }
        if let Some(len) = plausible(h) {
            let next = w.peek_max(len + peek);
            if next.len() == len || next.get(len..).and_then(&plausible).is_some() {
                s.resynchronised(what, from, w.offset());
                return true;
            }
        }
        w.consume(1);
    }
    s.lost_to_end(what, from, w.offset() + w.remaining() as u64 - from);
    false
}

/// What a binary log holds besides its samples.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct BinarySummary {
    /// Bytes read.
    pub bytes: u64,
    /// Records decoded, by record type or topic name (only the kinds aloft reads).
    pub records: BTreeMap<String, u64>,
    /// Whether the log declares a battery topic (a ULog subscription, a DataFlash `FMT`).
    pub battery_declared: bool,
    /// Battery instances that have records.
    pub battery_instances: Vec<u8>,
    /// The chosen battery instance's records.
    pub battery: BatterySummary,
    /// Cells of the battery, from the parameters (`BAT1_N_CELLS`, `BAT_N_CELLS`).
    pub battery_cells: Option<u32>,
    /// Capacity of the battery, from the parameters (`BAT1_CAPACITY`, `BATT_CAPACITY`), A h.
    pub battery_capacity_ah: Option<f64>,
    /// Mean air density of the log: PX4 `vehicle_air_data.rho`, ArduPilot `BARO` pressure and
    /// temperature (dry air), kg/m^3.
    pub air_density_kg_m3: Option<f64>,
    /// Time the vehicle was not landed (`vehicle_land_detected`), s.
    pub in_air_s: Option<f64>,
    /// Bytes skipped to find the next valid record after corruption.
    pub bytes_skipped: u64,
    /// Span of the base (motion) topic, s.
    pub base_span_s: f64,
    /// What went wrong or was left out, with byte offsets.
    pub warnings: Vec<String>,
    /// The battery records in detail, when [`BinaryOptions::battery_details`] is set.
    #[serde(skip)]
    pub(crate) battery_details: Option<crate::battery_records::BatteryDetails>,
    #[serde(skip)]
    pub(crate) rho_sum: f64,
    #[serde(skip)]
    pub(crate) rho_n: u64,
}

impl BinarySummary {
    /// Count one decoded record of `kind`.
    pub(crate) fn count(&mut self, kind: &str) {
        match self.records.get_mut(kind) {
            Some(n) => *n += 1,
            None => {
                self.records.insert(kind.to_string(), 1);
            }
        }
    }

    /// Add a warning (at most [`TimeChecker::MAX_EVENTS`] are kept).
    pub(crate) fn warn(&mut self, w: String) {
        if self.warnings.len() < TimeChecker::MAX_EVENTS {
            self.warnings.push(w);
        }
    }

    /// The parameters read ([`crate::battery_records::is_kept_parameter`]: the battery's
    /// and the flight envelope's), by name, when [`BinaryOptions::battery_details`] is set.
    pub fn kept_parameters(&self) -> Option<&BTreeMap<String, f64>> {
        self.battery_details.as_ref().map(|d| &d.parameters)
    }

    /// A decoder resynchronised: the bytes from `from` to `at` were skipped (`what`: "ULog
    /// record", "DataFlash data").
    pub(crate) fn resynchronised(&mut self, what: &str, from: u64, at: u64) {
        let skipped = at - from;
        self.bytes_skipped += skipped;
        self.warn(format!(
            "corrupt {what} at byte {from}: skipped {skipped} bytes to the next valid record at byte {at}"
        ));
    }

    /// A decoder found no valid record in the `skipped` bytes from `from` to the end.
    pub(crate) fn lost_to_end(&mut self, what: &str, from: u64, skipped: u64) {
        self.bytes_skipped += skipped;
        self.warn(format!(
            "corrupt {what} at byte {from}: no valid record in the {skipped} bytes after it"
        ));
    }

    /// Energy of the battery records, W h, when there are at least two valid ones.
    pub fn energy_wh(&self) -> Option<f64> {
        (self.battery.valid > 1).then(|| self.battery.energy_j / aloft_core::SECONDS_PER_HOUR)
    }

    /// Whether the log has battery data that covers the flight: at least two valid records,
    /// spanning at least [`MIN_BATTERY_COVERAGE`] of the base topic's span.
    pub fn power_available(&self) -> bool {
        self.battery.valid > 1
            && (self.base_span_s <= 0.0
                || self.battery.span_s() >= MIN_BATTERY_COVERAGE * self.base_span_s)
    }

    /// Why there is no battery data, in words (`None` when there is).
    pub fn no_power_reason(&self) -> Option<String> {
        if self.power_available() {
            return None;
        }
        let b = &self.battery;
        Some(if !self.battery_declared {
            "the log has no battery data: no battery topic is logged".to_string()
        } else if b.records == 0 {
            "the log has no battery data: the battery topic is declared but never written"
                .to_string()
        } else if b.valid < 2 {
            format!(
                "the log has no battery data: none of the {} battery records is valid ({} without voltage, {} with unknown current)",
                b.records, b.no_voltage, b.unknown_current
            )
        } else {
            format!(
                "the log has no battery data for the flight: battery records cover {:.1} s of {:.1} s",
                b.span_s(),
                self.base_span_s
            )
        })
    }

    pub(crate) fn finish(&mut self) {
        if self.rho_n > 0 {
            self.air_density_kg_m3 = Some(self.rho_sum / self.rho_n as f64);
        }
        if let Some(r) = self.no_power_reason() {
            self.warn(r);
        }
    }
}

/// A decoder of one binary format: the next kept record from a byte window.
pub trait Decoder {
    /// The next event, `None` at the end (a decoding problem ends nothing: it is a warning).
    fn next_event<R: Read>(
        &mut self,
        w: &mut ByteWindow<R>,
        s: &mut BinarySummary,
    ) -> Option<Event>;

    /// The origin of geodetic positions, when the log has them.
    fn origin(&self) -> Option<crate::sample::GeoOrigin> {
        None
    }
}

/// Joined samples of a binary log.
pub struct BinarySamples<R, D> {
    pub(crate) window: ByteWindow<R>,
    decoder: D,
    joiner: Joiner,
    summary: BinarySummary,
    checker: TimeChecker,
    first_s: Option<f64>,
    base_first_s: Option<f64>,
    base_last_s: f64,
    done: bool,
}

impl<R: Read, D: Decoder> BinarySamples<R, D> {
    pub(crate) fn with_decoder(reader: R, decoder: D, options: &BinaryOptions) -> Self {
        let summary = BinarySummary {
            battery_details: options.battery_details.then(Default::default),
            ..BinarySummary::default()
        };
        Self {
            window: ByteWindow::new(reader),
            decoder,
            joiner: Joiner::new(options.max_bracket_s),
            summary,
            checker: TimeChecker::new(),
            first_s: None,
            base_first_s: None,
            base_last_s: f64::NEG_INFINITY,
            done: false,
        }
    }

    /// What the log holds (complete once the iterator has ended).
    pub fn summary(&self) -> &BinarySummary {
        &self.summary
    }

    /// The origin of the ENU positions (geodetic logs).
    pub fn origin(&self) -> Option<crate::sample::GeoOrigin> {
        self.decoder.origin()
    }

    /// Absolute time of the first sample, s (boot time).
    pub fn start_time_s(&self) -> Option<f64> {
        self.first_s
    }

    /// Time report of the samples so far.
    pub fn time_report(&self) -> TimeReport {
        self.checker.clone().finish()
    }

    fn feed(&mut self) -> bool {
        match self.decoder.next_event(&mut self.window, &mut self.summary) {
            Some(e) => {
                if e.stream == crate::join::Stream::Base {
                    self.base_first_s.get_or_insert(e.time_s);
                    self.base_last_s = self.base_last_s.max(e.time_s);
                }
                self.joiner.push(e);
                true
            }
            None => {
                self.joiner.finish();
                self.summary.bytes = self.window.offset() + self.window.remaining() as u64;
                if let Some(e) = self.window.take_error() {
                    let at = self.window.offset();
                    self.summary
                        .warn(format!("reading stopped at byte {at}: {e}"));
                }
                if let Some(a) = self.base_first_s {
                    self.summary.base_span_s = self.base_last_s - a;
                }
                self.summary.finish();
                self.done = true;
                false
            }
        }
    }
}

impl<R: Read, D: Decoder> Iterator for BinarySamples<R, D> {
    type Item = Result<Sample>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some((t, mut s)) = self.joiner.pop() {
                let t0 = *self.first_s.get_or_insert(t);
                s.time_s = t - t0;
                self.checker.push(s.time_s);
                return Some(Ok(s));
            }
            if self.done || !self.feed() {
                return self.joiner.pop().map(|(t, mut s)| {
                    let t0 = *self.first_s.get_or_insert(t);
                    s.time_s = t - t0;
                    self.checker.push(s.time_s);
                    Ok(s)
                });
            }
        }
    }
}

/// A whole binary log read into memory.
#[derive(Debug, Clone, PartialEq)]
pub struct BinaryLog {
    /// The joined samples.
    pub log: Log,
    /// What else the log holds.
    pub summary: BinarySummary,
}

pub(crate) fn read_all<R: Read, D: Decoder>(
    mut it: BinarySamples<R, D>,
    source: &str,
) -> BinaryLog {
    let samples: Vec<Sample> = it.by_ref().filter_map(|s| s.ok()).collect();
    BinaryLog {
        log: Log {
            source: source.to_string(),
            samples,
            origin: it.origin(),
            start_time_s: it.start_time_s().unwrap_or(0.0),
            time: it.time_report(),
            dropped_count: 0,
            dropped: Vec::new(),
        },
        summary: it.summary,
    }
}
