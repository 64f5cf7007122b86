//! Streaming CSV reader: one row in, one [`Sample`] out, through a [`ColumnMap`].
//!
//! Memory is bounded by one row: the reader holds a single `csv::ByteRecord` and parses only the
//! mapped columns, and a line longer than [`MAX_LINE_BYTES`] is refused
//! ([`LogError::LineTooLong`]) before the record grows with it. A header that names a column
//! twice is refused ([`LogError::DuplicateColumn`]): which of the two a map means is ambiguous. Empty fields and `nan`/`inf` in a mapped column leave that channel `None` for the
//! row (PX4 writes `nan` for unknown values); text that is not a number is an error naming the row
//! and column. Values outside physical ranges are reported as [`LogError::Implausible`], which is
//! how a wrong unit in a map shows up.

use std::collections::HashMap;
use std::f64::consts::{FRAC_PI_2, PI};
use std::fs::File;
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};

use crate::column_map::{
    AttitudeColumns, ColumnMap, Frame, PositionColumns, ScalarColumn, VectorColumns,
};
use crate::error::{LogError, Result};
use crate::frame::{
    attitude_from_enu_flu_quat, attitude_from_ned_frd_quat, geodetic_to_enu, ned_to_enu,
};
use crate::sample::{Attitude, DroppedValue, GeoOrigin, Sample, TimeChecker, TimeReport};

/// Longest accepted step between consecutive time stamps, s: a longer step means a wrong time unit.
const MAX_STEP_S: f64 = 86_400.0;

/// Longest CSV line accepted, bytes (a flight log's rows are a few hundred bytes; a header of
/// thousands of columns fits too).
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// The marker of the I/O error [`LineLimit`] returns, recognised in [`csv_error`].
#[derive(Debug)]
struct LineTooLong;

impl std::fmt::Display for LineTooLong {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "a line is longer than {MAX_LINE_BYTES} bytes")
    }
}

impl std::error::Error for LineTooLong {}

/// A reader that fails once more than `limit` bytes pass without a line break (`\n` or `\r`),
/// so a file without line breaks cannot make the CSV record grow with it. A line may exceed the
/// limit by at most one read before it is caught.
struct LineLimit<R> {
    inner: R,
    since_break: usize,
    limit: usize,
}

impl<R: Read> Read for LineLimit<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        match buf[..n].iter().rposition(|&b| b == b'\n' || b == b'\r') {
            Some(p) => self.since_break = n - p - 1,
            None => self.since_break += n,
        }
        if self.since_break > self.limit {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                LineTooLong,
            ));
        }
        Ok(n)
    }
}

/// The range a channel's value must lie in, after conversion to SI; a value outside it is
/// [`LogError::Implausible`] (usually a wrong unit in the column map).
struct Plausible {
    channel: &'static str,
    lo: f64,
    hi: f64,
    unit: &'static str,
    expected: &'static str,
}

const VOLTAGE: Plausible = Plausible {
    channel: "voltage",
    lo: 0.0,
    hi: 1000.0,
    unit: "V",
    expected: "0 to 1000 V",
};
const CURRENT: Plausible = Plausible {
    channel: "current",
    lo: -500.0,
    hi: 2000.0,
    unit: "A",
    expected: "-500 to 2000 A",
};
/// Electrical power: the products of the voltage and current ranges' ends (1000 V x 2000 A,
/// 1000 V x -500 A). A logged power outside it is dropped and counted like a glitch (a `power`
/// of 1e308 overflowed the energy and mean power of `log info`).
const POWER: Plausible = Plausible {
    channel: "power",
    lo: -500_000.0,
    hi: 2_000_000.0,
    unit: "W",
    expected: "-500 kW to 2 MW",
};
const CHARGE: Plausible = Plausible {
    channel: "charge",
    lo: -1000.0,
    hi: 10_000.0,
    unit: "Ah",
    expected: "-1000 to 10000 Ah",
};
/// Checked on the largest component of a local position.
const LOCAL_POSITION: Plausible = Plausible {
    channel: "position",
    lo: 0.0,
    hi: 1e6,
    unit: "m",
    expected: "within 1000 km",
};
const LATITUDE: Plausible = Plausible {
    channel: "latitude",
    lo: -FRAC_PI_2,
    hi: FRAC_PI_2,
    unit: "rad",
    expected: "-pi/2 to pi/2 rad",
};
const LONGITUDE: Plausible = Plausible {
    channel: "longitude",
    lo: -2.0 * PI,
    hi: 2.0 * PI,
    unit: "rad",
    expected: "-2 pi to 2 pi rad",
};
/// Checked on the norm of the vector, as are acceleration and wind.
const VELOCITY: Plausible = Plausible {
    channel: "velocity",
    lo: 0.0,
    hi: 150.0,
    unit: "m/s",
    expected: "below 150 m/s",
};
const ACCELERATION: Plausible = Plausible {
    channel: "acceleration",
    lo: 0.0,
    hi: 500.0,
    unit: "m/s^2",
    expected: "below 500 m/s^2",
};
const WIND: Plausible = Plausible {
    channel: "wind",
    lo: 0.0,
    hi: 100.0,
    unit: "m/s",
    expected: "below 100 m/s",
};
/// Logged unit quaternions are normalised to float precision; 10 % slack.
const QUATERNION_NORM: Plausible = Plausible {
    channel: "quaternion norm",
    lo: 0.9,
    hi: 1.1,
    unit: "",
    expected: "close to 1",
};

#[derive(Debug, Clone, Copy)]
struct Col {
    index: usize,
    factor: f64,
}

#[derive(Debug, Clone, Copy)]
enum PosKind {
    Local(Frame),
    Geodetic { angle: f64 },
}

#[derive(Debug, Clone, Copy)]
enum AttKind {
    Euler,
    Quat(Frame),
}

#[derive(Debug, Clone)]
struct Compiled {
    time: Col,
    time_name: String,
    voltage: Option<Col>,
    current: Option<Col>,
    power: Option<Col>,
    charge: Option<Col>,
    position: Option<([Col; 3], PosKind)>,
    velocity: Option<([Col; 3], Frame)>,
    acceleration: Option<([Col; 3], Frame)>,
    attitude: Option<(Vec<Col>, AttKind)>,
    wind: Option<([Col; 3], Frame)>,
    names: Vec<String>,
}

/// Samples of one CSV file, read row by row.
pub struct CsvSamples<R: Read> {
    path: PathBuf,
    reader: csv::Reader<LineLimit<R>>,
    record: csv::ByteRecord,
    map: std::sync::Arc<Compiled>,
    checker: TimeChecker,
    origin: Option<GeoOrigin>,
    start_abs_s: Option<f64>,
    prev_abs_s: Option<f64>,
    row: u64,
    done: bool,
    columns: Vec<String>,
    power_checked: bool,
    dropped_count: u64,
    dropped: Vec<DroppedValue>,
}

impl CsvSamples<BufReader<File>> {
    /// Open a CSV file with a column map. Fails when a mapped column is missing from the header,
    /// or the path is not a regular file (a FIFO, device or directory is refused before it is
    /// opened).
    pub fn open(path: &Path, map: &ColumnMap) -> Result<Self> {
        let file = aloft_core::open_regular_file(path).map_err(LogError::reading(path))?;
        Self::from_reader(BufReader::with_capacity(1 << 16, file), path, map)
    }
}

impl<R: Read> CsvSamples<R> {
    /// Read from any reader; `path` names the source in errors.
    pub fn from_reader(reader: R, path: &Path, map: &ColumnMap) -> Result<Self> {
        let delimiter = u8::try_from(map.delimiter).map_err(|_| LogError::MapFile {
            path: PathBuf::from(&map.name),
            message: format!("delimiter '{}' must be a single ASCII byte", map.delimiter),
        })?;
        let mut reader = csv::ReaderBuilder::new()
            .delimiter(delimiter)
            .has_headers(true)
            .flexible(false)
            .from_reader(LineLimit {
                inner: reader,
                since_break: 0,
                limit: MAX_LINE_BYTES,
            });
        let header = reader
            .byte_headers()
            .map_err(|e| csv_error(path, &e, 0))?
            .clone();
        let columns: Vec<String> = header
            .iter()
            .map(|h| String::from_utf8_lossy(h).trim().to_string())
            .collect();
        if columns.len() <= 1 && columns.first().is_none_or(|c| c.is_empty()) {
            return Err(LogError::Empty {
                path: path.to_path_buf(),
                what: "no header line".into(),
            });
        }
        check_unique(&columns, path)?;
        let compiled = compile(map, &columns, path)?;
        Ok(Self {
            path: path.to_path_buf(),
            reader,
            record: csv::ByteRecord::new(),
            map: std::sync::Arc::new(compiled),
            checker: TimeChecker::new(),
            origin: None,
            start_abs_s: None,
            prev_abs_s: None,
            row: 1,
            done: false,
            columns,
            power_checked: false,
            dropped_count: 0,
            dropped: Vec::new(),
        })
    }

    /// The header's column names.
    pub fn columns(&self) -> &[String] {
        &self.columns
    }

    /// The columns the map uses.
    pub fn mapped_columns(&self) -> &[String] {
        &self.map.names
    }

    /// Origin of the ENU positions (first geodetic fix), once a row with a fix was read.
    pub fn origin(&self) -> Option<GeoOrigin> {
        self.origin
    }

    /// Absolute time of the first row in the file's clock, s.
    pub fn start_time_s(&self) -> Option<f64> {
        self.start_abs_s
    }

    /// Values dropped so far as isolated contradictions: total and the first few.
    pub fn dropped(&self) -> (u64, &[DroppedValue]) {
        (self.dropped_count, &self.dropped)
    }

    /// The time report of the rows read so far.
    pub fn time_report(&self) -> TimeReport {
        self.checker.clone().finish()
    }

    /// [`LogError::ParseValue`] for `text` in `column` of the current row.
    fn parse_error(&self, column: &str, text: String) -> LogError {
        LogError::ParseValue {
            path: self.path.clone(),
            row: self.row,
            column: column.to_string(),
            text,
        }
    }

    fn field(&self, col: Col, name: &str) -> Result<Option<f64>> {
        let raw = self.record.get(col.index).unwrap_or(b"");
        let text = trim(raw);
        if text.is_empty() {
            return Ok(None);
        }
        let s = std::str::from_utf8(text)
            .map_err(|_| self.parse_error(name, String::from_utf8_lossy(text).into_owned()))?;
        match s.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(Some(v * col.factor)),
            Ok(_) => Ok(None),
            Err(_) => {
                if s.eq_ignore_ascii_case("true") || s.eq_ignore_ascii_case("false") {
                    return Ok(Some(if s.eq_ignore_ascii_case("true") {
                        1.0
                    } else {
                        0.0
                    }));
                }
                Err(self.parse_error(name, s.to_string()))
            }
        }
    }

    fn name_of(&self, col: Col) -> &str {
        self.columns.get(col.index).map_or("", |s| s.as_str())
    }

    fn vec3(&self, cols: &[Col; 3]) -> Result<Option<[f64; 3]>> {
        let mut out = [0.0; 3];
        for (o, c) in out.iter_mut().zip(cols) {
            match self.field(*c, self.name_of(*c))? {
                Some(v) => *o = v,
                None => return Ok(None),
            }
        }
        Ok(Some(out))
    }

    fn implausible(
        &self,
        channel: &'static str,
        value: f64,
        unit: &'static str,
        expected: &'static str,
    ) -> LogError {
        LogError::Implausible {
            path: self.path.clone(),
            row: self.row,
            channel,
            value,
            unit,
            expected,
        }
    }

    fn check_range(&self, value: f64, range: &Plausible) -> Result<()> {
        if value < range.lo || value > range.hi {
            return Err(self.implausible(range.channel, value, range.unit, range.expected));
        }
        Ok(())
    }

    fn frame_vec(&self, v: [f64; 3], frame: Frame) -> [f64; 3] {
        match frame {
            Frame::Enu => v,
            Frame::Ned => ned_to_enu(v),
        }
    }

    /// The current row as a sample: its time, then the battery, position, velocity,
    /// acceleration, wind and attitude channels, checked in that order (the first implausible
    /// value is the error).
    fn parse_row(&mut self) -> Result<Sample> {
        let m = std::sync::Arc::clone(&self.map);
        let mut s = Sample {
            time_s: self.row_time_s(&m)?,
            ..Sample::default()
        };
        self.read_battery(&m, &mut s)?;
        s.pos_enu_m = self.position_enu(m.position)?;
        s.vel_enu_mps = self.world_vector(m.velocity, &VELOCITY)?;
        s.acc_enu_mps2 = self.world_vector(m.acceleration, &ACCELERATION)?;
        s.wind_enu_mps = self.world_vector(m.wind, &WIND)?;
        s.attitude = self.attitude(m.attitude.as_ref())?;
        Ok(s)
    }

    /// Time of the row since the first row, s, after checking the step from the previous row.
    fn row_time_s(&mut self, m: &Compiled) -> Result<f64> {
        let t_abs = self.field(m.time, &m.time_name)?.ok_or_else(|| {
            let raw = self.record.get(m.time.index).unwrap_or(b"");
            self.parse_error(&m.time_name, String::from_utf8_lossy(raw).into_owned())
        })?;
        self.check_time_step(t_abs)?;
        self.prev_abs_s = Some(t_abs);
        let start = *self.start_abs_s.get_or_insert(t_abs);
        Ok(t_abs - start)
    }

    fn check_time_step(&self, t_abs: f64) -> Result<()> {
        if let Some(prev) = self.prev_abs_s {
            if (t_abs - prev).abs() > MAX_STEP_S {
                return Err(self.implausible(
                    "time",
                    t_abs - prev,
                    "s",
                    "consecutive time stamps less than one day apart",
                ));
            }
        }
        Ok(())
    }

    /// Voltage, current, power (checked against V x I) and charge.
    fn read_battery(&mut self, m: &Compiled, s: &mut Sample) -> Result<()> {
        s.voltage_v = self.scalar(m.voltage, &VOLTAGE)?;
        s.current_a = self.scalar(m.current, &CURRENT)?;
        if let Some(c) = m.power {
            s.power_w = self.power_w(c, s.voltage_v, s.current_a)?;
        }
        s.charge_ah = self.scalar(m.charge, &CHARGE)?;
        Ok(())
    }

    fn scalar(&self, col: Option<Col>, range: &Plausible) -> Result<Option<f64>> {
        let Some(c) = col else {
            return Ok(None);
        };
        let value = self.field(c, self.name_of(c))?;
        if let Some(v) = value {
            self.check_range(v, range)?;
        }
        Ok(value)
    }

    /// The logged power, when it lies in the plausible range ([`POWER`]; outside it, the value is
    /// dropped and reported) and agrees with V x I within 20 % (+5 W for noise at idle). On the
    /// first row that has all three, a mismatch is a wrong unit or scale (e.g. KAIST's 10 x V x I
    /// without scale = 0.1) and an error; later, an isolated mismatch is a sensor glitch (the
    /// KAIST logs have 10 rows with a 16-bit overflowed power): the power value is dropped and
    /// reported.
    fn power_w(
        &mut self,
        col: Col,
        voltage_v: Option<f64>,
        current_a: Option<f64>,
    ) -> Result<Option<f64>> {
        let power_w = self.field(col, self.name_of(col))?;
        if let Some(p) = power_w.filter(|p| !(POWER.lo..=POWER.hi).contains(p)) {
            self.record_dropped(POWER.channel, p);
            return Ok(None);
        }
        let (Some(p), Some(v), Some(i)) = (power_w, voltage_v, current_a) else {
            return Ok(power_w);
        };
        let mut kept = power_w;
        if (p - v * i).abs() > 0.2 * (v * i).abs() + 5.0 {
            if !self.power_checked {
                return Err(self.implausible("power", p, "W", "within 20 % of voltage x current"));
            }
            self.record_dropped("power", p);
            kept = None;
        }
        self.power_checked = true;
        Ok(kept)
    }

    fn record_dropped(&mut self, channel: &'static str, value: f64) {
        self.dropped_count += 1;
        if self.dropped.len() < TimeChecker::MAX_EVENTS {
            self.dropped.push(DroppedValue {
                row: self.row,
                channel,
                value,
            });
        }
    }

    fn position_enu(&mut self, mapped: Option<([Col; 3], PosKind)>) -> Result<Option<[f64; 3]>> {
        let Some((cols, kind)) = mapped else {
            return Ok(None);
        };
        let Some(p) = self.vec3(&cols)? else {
            return Ok(None);
        };
        match kind {
            PosKind::Local(frame) => self.local_position_enu(p, frame).map(Some),
            PosKind::Geodetic { angle } => self.geodetic_position_enu(p, angle).map(Some),
        }
    }

    fn local_position_enu(&self, p: [f64; 3], frame: Frame) -> Result<[f64; 3]> {
        let p = self.frame_vec(p, frame);
        let r = p.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        self.check_range(r, &LOCAL_POSITION)?;
        Ok(p)
    }

    /// ENU position relative to the first fix, which becomes the origin.
    fn geodetic_position_enu(&mut self, p: [f64; 3], angle: f64) -> Result<[f64; 3]> {
        let (lat, lon, alt) = (p[0] * angle, p[1] * angle, p[2]);
        self.check_range(lat, &LATITUDE)?;
        self.check_range(lon, &LONGITUDE)?;
        let o = *self.origin.get_or_insert(GeoOrigin {
            lat_rad: lat,
            lon_rad: lon,
            alt_m: alt,
        });
        Ok(geodetic_to_enu(&o, lat, lon, alt))
    }

    /// A velocity, acceleration or wind vector in ENU, its norm checked against `range`.
    fn world_vector(
        &self,
        mapped: Option<([Col; 3], Frame)>,
        range: &Plausible,
    ) -> Result<Option<[f64; 3]>> {
        let Some((cols, frame)) = mapped else {
            return Ok(None);
        };
        let Some(v) = self.vec3(&cols)? else {
            return Ok(None);
        };
        let v = self.frame_vec(v, frame);
        self.check_range(norm(v), range)?;
        Ok(Some(v))
    }

    fn attitude(&self, mapped: Option<&(Vec<Col>, AttKind)>) -> Result<Option<Attitude>> {
        match mapped {
            None => Ok(None),
            Some((cols, AttKind::Euler)) => self.euler_attitude(cols),
            Some((cols, AttKind::Quat(frame))) => self.quaternion_attitude(cols, *frame),
        }
    }

    fn euler_attitude(&self, cols: &[Col]) -> Result<Option<Attitude>> {
        let Some(a) = self.vec3(&[cols[0], cols[1], cols[2]])? else {
            return Ok(None);
        };
        // 1e-6 rad of slack for angles logged at exactly +-pi.
        for (ch, v, lim) in [
            ("roll", a[0], PI),
            ("pitch", a[1], PI / 2.0),
            ("yaw", a[2], 2.0 * PI),
        ] {
            if v.abs() > lim + 1e-6 {
                return Err(self.implausible(
                    ch,
                    v,
                    "rad",
                    "|roll| <= pi, |pitch| <= pi/2, |yaw| <= 2 pi",
                ));
            }
        }
        Ok(Some(Attitude {
            roll_rad: a[0],
            pitch_rad: a[1],
            yaw_rad: wrap_pi(a[2]),
        }))
    }

    /// Attitude from a unit quaternion (every component is read, so a bad one is reported even
    /// after an empty one).
    fn quaternion_attitude(&self, cols: &[Col], frame: Frame) -> Result<Option<Attitude>> {
        let mut q = [0.0; 4];
        let mut ok = true;
        for (o, c) in q.iter_mut().zip(cols.iter()) {
            match self.field(*c, self.name_of(*c))? {
                Some(v) => *o = v,
                None => ok = false,
            }
        }
        if !ok {
            return Ok(None);
        }
        let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        self.check_range(n, &QUATERNION_NORM)?;
        Ok(match frame {
            Frame::Ned => attitude_from_ned_frd_quat(q),
            Frame::Enu => attitude_from_enu_flu_quat(q),
        })
    }
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// Wrap an angle into (-pi, pi].
pub fn wrap_pi(a: f64) -> f64 {
    let pi = std::f64::consts::PI;
    let mut x = (a + pi).rem_euclid(2.0 * pi) - pi;
    if x <= -pi {
        x += 2.0 * pi;
    }
    x
}

fn trim(b: &[u8]) -> &[u8] {
    let start = b
        .iter()
        .position(|c| !c.is_ascii_whitespace())
        .unwrap_or(b.len());
    let end = b
        .iter()
        .rposition(|c| !c.is_ascii_whitespace())
        .map_or(start, |e| e + 1);
    &b[start..end]
}

/// Every column name once: a name that appears twice is [`LogError::DuplicateColumn`].
fn check_unique(columns: &[String], path: &Path) -> Result<()> {
    let mut seen: HashMap<&str, usize> = HashMap::with_capacity(columns.len());
    for (i, c) in columns.iter().enumerate() {
        if let Some(first) = seen.insert(c.as_str(), i) {
            return Err(LogError::DuplicateColumn {
                path: path.to_path_buf(),
                column: c.clone(),
                first: first + 1,
                second: i + 1,
            });
        }
    }
    Ok(())
}

/// The [`LogError`] of a CSV error, `last_line` being the last line read completely.
fn csv_error(path: &Path, e: &csv::Error, last_line: u64) -> LogError {
    let row = e.position().map_or(0, |p| p.line());
    match e.kind() {
        csv::ErrorKind::Io(io) if io.get_ref().is_some_and(|c| c.is::<LineTooLong>()) => {
            LogError::LineTooLong {
                path: path.to_path_buf(),
                line: last_line + 1,
                limit_bytes: MAX_LINE_BYTES,
            }
        }
        csv::ErrorKind::Io(io) => LogError::Io {
            path: path.to_path_buf(),
            cause: std::io::Error::new(io.kind(), io.to_string()),
        },
        _ => LogError::CsvRow {
            path: path.to_path_buf(),
            row,
            message: e.to_string(),
        },
    }
}

/// Finds the columns of a map in the header, channel by channel (the first missing column is
/// the error), and keeps the names of those found.
struct ColumnFinder<'a> {
    columns: &'a [String],
    path: &'a Path,
    names: Vec<String>,
}

impl ColumnFinder<'_> {
    fn find(&mut self, name: &str, channel: &'static str, factor: f64) -> Result<Col> {
        match self.columns.iter().position(|c| c == name) {
            Some(index) => {
                self.names.push(name.to_string());
                Ok(Col { index, factor })
            }
            None => Err(LogError::ColumnMissing {
                path: self.path.to_path_buf(),
                column: name.to_string(),
                channel,
                columns: self.columns.len(),
            }),
        }
    }

    /// Three columns in order, each with its channel name and factor.
    fn three(
        &mut self,
        names: &[String; 3],
        channels: [&'static str; 3],
        factors: [f64; 3],
    ) -> Result<[Col; 3]> {
        Ok([
            self.find(&names[0], channels[0], factors[0])?,
            self.find(&names[1], channels[1], factors[1])?,
            self.find(&names[2], channels[2], factors[2])?,
        ])
    }

    fn scalar(&mut self, c: &Option<ScalarColumn>, channel: &'static str) -> Result<Option<Col>> {
        c.as_ref()
            .map(|c| self.find(&c.column, channel, ColumnMap::scalar_factor(c)))
            .transpose()
    }

    fn vector(
        &mut self,
        v: &Option<VectorColumns>,
        channel: &'static str,
    ) -> Result<Option<([Col; 3], Frame)>> {
        let Some(v) = v else {
            return Ok(None);
        };
        let f = v.unit.factor();
        Ok(Some((
            self.three(&v.columns, [channel; 3], [f; 3])?,
            v.frame,
        )))
    }

    fn position(&mut self, p: &Option<PositionColumns>) -> Result<Option<([Col; 3], PosKind)>> {
        Ok(match p {
            None => None,
            Some(PositionColumns::Local {
                columns,
                frame,
                unit,
            }) => {
                let f = unit.factor();
                Some((
                    self.three(columns, ["position"; 3], [f; 3])?,
                    PosKind::Local(*frame),
                ))
            }
            Some(PositionColumns::Geodetic {
                columns,
                angle_unit,
                unit,
            }) => Some((
                self.three(
                    columns,
                    ["latitude", "longitude", "altitude"],
                    [1.0, 1.0, unit.factor()],
                )?,
                PosKind::Geodetic {
                    angle: angle_unit.factor(),
                },
            )),
        })
    }

    fn attitude(&mut self, a: &Option<AttitudeColumns>) -> Result<Option<(Vec<Col>, AttKind)>> {
        Ok(match a {
            None => None,
            Some(AttitudeColumns::Euler { columns, unit }) => {
                let f = unit.factor();
                Some((
                    self.three(columns, ["roll", "pitch", "yaw"], [f; 3])?
                        .to_vec(),
                    AttKind::Euler,
                ))
            }
            Some(AttitudeColumns::Quaternion { columns, frame }) => Some((
                columns
                    .iter()
                    .map(|n| self.find(n, "attitude", 1.0))
                    .collect::<Result<Vec<_>>>()?,
                AttKind::Quat(*frame),
            )),
        })
    }
}

/// The map's columns located in the header, in the order time, battery, velocity,
/// acceleration, wind, position, attitude.
fn compile(map: &ColumnMap, columns: &[String], path: &Path) -> Result<Compiled> {
    let mut finder = ColumnFinder {
        columns,
        path,
        names: Vec::new(),
    };
    let time = finder.find(&map.time.column, "time", map.time.unit.factor())?;
    let voltage = finder.scalar(&map.voltage, "voltage")?;
    let current = finder.scalar(&map.current, "current")?;
    let power = finder.scalar(&map.power, "power")?;
    let charge = finder.scalar(&map.charge, "charge")?;
    let velocity = finder.vector(&map.velocity, "velocity")?;
    let acceleration = finder.vector(&map.acceleration, "acceleration")?;
    let wind = finder.vector(&map.wind, "wind")?;
    let position = finder.position(&map.position)?;
    let attitude = finder.attitude(&map.attitude)?;
    Ok(Compiled {
        time,
        time_name: map.time.column.clone(),
        voltage,
        current,
        power,
        charge,
        position,
        velocity,
        acceleration,
        attitude,
        wind,
        names: finder.names,
    })
}

impl<R: Read> Iterator for CsvSamples<R> {
    type Item = Result<Sample>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        match self.reader.read_byte_record(&mut self.record) {
            Ok(false) => {
                self.done = true;
                if self.start_abs_s.is_none() {
                    return Some(Err(LogError::Empty {
                        path: self.path.clone(),
                        what: "no data rows after the header".into(),
                    }));
                }
                None
            }
            Ok(true) => {
                self.row = self.record.position().map_or(self.row + 1, |p| p.line());
                match self.parse_row() {
                    Ok(s) => {
                        self.checker.push(s.time_s);
                        Some(Ok(s))
                    }
                    Err(e) => {
                        self.done = true;
                        Some(Err(e))
                    }
                }
            }
            Err(e) => {
                self.done = true;
                Some(Err(csv_error(&self.path, &e, self.row)))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::column_map::ColumnMap;

    const KAIST_HEADER: &str = "timestamp,lat,log,alt,roll,pitch,yaw,vel_x,vel_y,vel_z,acc_x,acc_y,acc_z,act_vx,act_vy,act_yr,capacity,vol,cur,power\n";

    fn read(text: &str, map: &ColumnMap) -> Result<Vec<Sample>> {
        CsvSamples::from_reader(text.as_bytes(), Path::new("t.csv"), map)?.collect()
    }

    #[test]
    fn kaist_row_converts_to_si_enu() {
        let text = format!(
            "{KAIST_HEADER}1000000,0.634769,2.223,89.0,0.1,-0.2,0.5,1.0,2.0,-0.5,0,0,0,0,0,0,12150,48.0,25.0,12000\n1100000,0.634769,2.223,89.5,0.1,-0.2,0.5,1.0,2.0,-0.5,0,0,0,0,0,0,12150,48.0,25.0,12000\n"
        );
        let s = read(&text, &ColumnMap::kaist()).unwrap();
        assert_eq!(s.len(), 2);
        // Exact decimal inputs: 1e-9 covers the us -> s conversion rounding.
        assert!((s[1].time_s - 0.1).abs() < 1e-9);
        assert_eq!(s[0].vel_enu_mps, Some([2.0, 1.0, 0.5]));
        assert!((s[0].power_w.unwrap() - 1200.0).abs() < 1e-9);
        assert!((s[0].electrical_power_w().unwrap() - 1200.0).abs() < 1e-9);
        assert!((s[1].pos_enu_m.unwrap()[2] - 0.5).abs() < 1e-9);
        assert!((s[0].charge_ah.unwrap() - 12.15).abs() < 1e-9);
    }

    #[test]
    fn missing_column_names_column_channel_and_file() {
        let map = ColumnMap::kaist();
        let text = "timestamp,lat,log,alt\n1,0,0,0\n";
        let e = read(text, &map).unwrap_err();
        let msg = e.to_string();
        assert!(matches!(e, LogError::ColumnMissing { .. }), "{msg}");
        assert!(
            msg.contains("t.csv") && msg.contains("'vol'") && msg.contains("voltage"),
            "{msg}"
        );
    }

    #[test]
    fn bad_number_names_row_and_column() {
        let map = ColumnMap::kaist();
        let text = format!(
            "{KAIST_HEADER}1000000,0.634769,2.223,89.0,0.1,-0.2,0.5,1.0,2.0,-0.5,0,0,0,0,0,0,12150,48.0,25.0,12000\n1100000,0.634769,2.223,89.5,0.1,-0.2,0.5,1.0,2.0,-0.5,0,0,0,0,0,0,12150,4x8.0,25.0,12000\n"
        );
        match read(&text, &map).unwrap_err() {
            LogError::ParseValue { row, column, .. } => {
                assert_eq!(row, 3);
                assert_eq!(column, "vol");
            }
            e => panic!("{e}"),
        }
    }

    /// `e` is [`LogError::Implausible`] for `channel`.
    fn assert_implausible(e: &LogError, channel: &str) {
        assert!(
            matches!(e, LogError::Implausible { channel: c, .. } if *c == channel),
            "{e}"
        );
    }

    #[test]
    fn wrong_units_are_implausible() {
        // Voltage in mV declared as V.
        let mut map = ColumnMap::new("m", "t", crate::column_map::TimeUnit::S);
        map.voltage = Some(crate::column_map::ScalarColumn {
            column: "v".into(),
            unit: crate::column_map::ScalarUnit::V,
            scale: 1.0,
        });
        let e = read("t,v\n0,12000\n", &map).unwrap_err();
        assert!(
            matches!(
                e,
                LogError::Implausible {
                    channel: "voltage",
                    row: 2,
                    ..
                }
            ),
            "{e}"
        );
        // Time in us declared as s.
        let e = read("t,v\n0,12\n100000,12\n", &map).unwrap_err();
        assert_implausible(&e, "time");
        // KAIST power without the 0.1 scale.
        let mut k = ColumnMap::kaist();
        k.power.as_mut().unwrap().scale = 1.0;
        let text = format!(
            "{KAIST_HEADER}1000000,0.634769,2.223,89.0,0.1,-0.2,0.5,1.0,2.0,-0.5,0,0,0,0,0,0,12150,48.0,25.0,12000\n"
        );
        let e = read(&text, &k).unwrap_err();
        assert_implausible(&e, "power");
        // Degrees declared as radians.
        let mut m = ColumnMap::new("m", "t", crate::column_map::TimeUnit::S);
        m.attitude = Some(AttitudeColumns::Euler {
            columns: ["r".into(), "p".into(), "y".into()],
            unit: crate::column_map::AngleUnit::Rad,
        });
        let e = read("t,r,p,y\n0,10,5,90\n", &m).unwrap_err();
        assert_implausible(&e, "roll");
    }

    /// Fuzz findings `fixtures/fuzz/log-csv/*.bin`: a power of 1e308 (with the voltage missing,
    /// so no V x I check) overflowed the energy and mean power of `log info`.
    #[test]
    fn power_outside_its_plausible_range_is_dropped_and_counted() {
        let row = |t: u32, v: &str, p: &str| {
            format!("{t},0.634769,2.223,89.0,0.1,-0.2,0.5,1.0,2.0,-0.5,0,0,0,0,0,0,12150,{v},25.0,{p}\n")
        };
        let text = format!(
            "{KAIST_HEADER}{}{}{}{}",
            row(1_000_000, "", "1e308"),
            row(1_100_000, "", "-1e308"),
            row(1_200_000, "", "30000000"),
            row(1_300_000, "", "12000")
        );
        let mut r =
            CsvSamples::from_reader(text.as_bytes(), Path::new("g.csv"), &ColumnMap::kaist())
                .unwrap();
        let s: Vec<Sample> = r.by_ref().collect::<Result<_>>().unwrap();
        assert_eq!(s.len(), 4);
        assert!(s[..3].iter().all(|s| s.power_w.is_none()));
        // KAIST's power column is 10 x W (scale 0.1).
        assert_eq!(s[3].power_w, Some(1200.0));
        let (n, d) = r.dropped();
        assert_eq!(n, 3);
        assert_eq!((d[0].row, d[0].channel), (2, "power"));
        assert!(d[0].value > 1e300);
    }

    #[test]
    fn isolated_power_glitch_is_dropped_and_reported() {
        let row = |t: u32, p: &str| {
            format!("{t},0.634769,2.223,89.0,0.1,-0.2,0.5,1.0,2.0,-0.5,0,0,0,0,0,0,12150,48.0,25.0,{p}\n")
        };
        let text = format!(
            "{KAIST_HEADER}{}{}{}",
            row(1_000_000, "12000"),
            row(1_100_000, "-20523"),
            row(1_200_000, "12000")
        );
        let mut r =
            CsvSamples::from_reader(text.as_bytes(), Path::new("g.csv"), &ColumnMap::kaist())
                .unwrap();
        let s: Vec<Sample> = r.by_ref().collect::<Result<_>>().unwrap();
        assert_eq!(s.len(), 3);
        assert_eq!(s[1].power_w, None);
        assert!(s[2].power_w.is_some());
        let (n, d) = r.dropped();
        assert_eq!(n, 1);
        assert_eq!(d[0].row, 3);
        assert_eq!(d[0].channel, "power");
    }

    #[test]
    fn empty_logs_are_errors() {
        let map = ColumnMap::kaist();
        let e = read(KAIST_HEADER, &map).unwrap_err();
        assert!(matches!(e, LogError::Empty { .. }), "{e}");
        let e = read("", &map).unwrap_err();
        assert!(matches!(e, LogError::Empty { .. }), "{e}");
    }

    #[test]
    fn ragged_row_is_a_csv_error_with_row() {
        let map = ColumnMap::new("m", "t", crate::column_map::TimeUnit::S);
        let e = read("t,v\n0,1\n1,2\n2\n", &map).unwrap_err();
        match e {
            LogError::CsvRow { row, .. } => assert_eq!(row, 4),
            e => panic!("{e}"),
        }
    }

    #[test]
    fn nan_leaves_channel_empty() {
        let map = ColumnMap::px4_battery();
        let s = read("timestamp,voltage_v,current_a\n1,12.0,nan\n", &map).unwrap();
        assert_eq!(s[0].voltage_v, Some(12.0));
        assert_eq!(s[0].current_a, None);
    }

    #[test]
    fn duplicated_column_names_are_refused_naming_column_and_file() {
        let row = "1000000,0.634769,2.223,89.0,0.1,-0.2,0.5,1.0,2.0,-0.5,0,0,0,0,0,0,12150,48.0,25.0,12000";
        // A mapped column twice (which one is the voltage?), an unmapped one twice, a name
        // that differs only by spaces, and two empty names.
        for (header, column, first, second) in [
            (KAIST_HEADER.replace(",cur,", ",vol,"), "vol", 18, 19),
            (KAIST_HEADER.replace("act_vy", "act_vx"), "act_vx", 14, 15),
            (KAIST_HEADER.replace(",cur,", ", vol ,"), "vol", 18, 19),
            (KAIST_HEADER.replace(",act_vx,act_vy,", ",,,"), "", 14, 15),
        ] {
            let e = read(&format!("{header}{row}\n"), &ColumnMap::kaist()).unwrap_err();
            match &e {
                LogError::DuplicateColumn {
                    column: c,
                    first: f,
                    second: s,
                    ..
                } => assert_eq!((c.as_str(), *f, *s), (column, first, second), "{e}"),
                e => panic!("{header}: {e}"),
            }
            let msg = e.to_string();
            assert!(
                msg.contains("t.csv") && msg.contains(&format!("'{column}'")),
                "{msg}"
            );
        }
        // Through a user map too.
        let map = ColumnMap::new("m", "t", crate::column_map::TimeUnit::S);
        let e = read("t,v,t\n0,1,2\n", &map).unwrap_err();
        assert!(matches!(e, LogError::DuplicateColumn { .. }), "{e}");
    }

    /// An endless line (a device, a file with no line breaks) is refused after about
    /// `MAX_LINE_BYTES`, whether it is the header or a row.
    #[test]
    fn a_line_without_breaks_is_refused_before_it_grows() {
        use std::io::Read as _;
        let map = ColumnMap::new("m", "t", crate::column_map::TimeUnit::S);
        let endless = std::io::repeat(b'7');
        match CsvSamples::from_reader(endless, Path::new("z.csv"), &map) {
            Err(LogError::LineTooLong { line: 1, path, .. }) => {
                assert_eq!(path, Path::new("z.csv"))
            }
            Err(e) => panic!("{e}"),
            Ok(_) => panic!("an endless header was read"),
        }
        let text = b"t,v\n0,1\n".chain(std::io::repeat(b'8'));
        let r = CsvSamples::from_reader(text, Path::new("z.csv"), &map).unwrap();
        let e = r.collect::<Result<Vec<_>>>().unwrap_err();
        assert!(matches!(e, LogError::LineTooLong { line: 3, .. }), "{e}");
        assert!(e.to_string().contains("z.csv"), "{e}");
        // Line breaks of any kind (\n, \r\n, \r) keep long files readable.
        for eol in ["\n", "\r\n", "\r"] {
            let mut text = format!("t,v{eol}");
            let rows = 2 * MAX_LINE_BYTES / 8;
            for i in 0..rows {
                text.push_str(&format!("{i},1{eol}"));
            }
            assert_eq!(read(&text, &map).unwrap().len(), rows, "{eol:?}");
        }
    }

    #[test]
    fn wrap_pi_range() {
        // Results of one rem_euclid: 1e-12.
        assert!((wrap_pi(3.0 * std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-12);
        assert!((wrap_pi(-0.5) + 0.5).abs() < 1e-12);
    }
}
