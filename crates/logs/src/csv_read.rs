//! Streaming CSV reader: one row in, one [`Sample`] out, through a [`ColumnMap`].
//!
//! Memory is bounded by one row: the reader holds a single `csv::ByteRecord` and parses only the
//! mapped columns. Empty fields and `nan`/`inf` in a mapped column leave that channel `None` for the
//! row (PX4 writes `nan` for unknown values); text that is not a number is an error naming the row
//! and column. Values outside physical ranges are reported as [`LogError::Implausible`], which is
//! how a wrong unit in a map shows up.

use std::fs::File;
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};

use crate::column_map::{AttitudeColumns, ColumnMap, Frame, PositionColumns, VectorColumns};
use crate::error::{LogError, Result};
use crate::frame::{
    attitude_from_enu_flu_quat, attitude_from_ned_frd_quat, geodetic_to_enu, ned_to_enu,
};
use crate::sample::{Attitude, DroppedValue, GeoOrigin, Sample, TimeChecker, TimeReport};

/// Longest accepted step between consecutive time stamps, s: a longer step means a wrong time unit.
const MAX_STEP_S: f64 = 86_400.0;

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
    reader: csv::Reader<R>,
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
    /// Open a CSV file with a column map. Fails when a mapped column is missing from the header.
    pub fn open(path: &Path, map: &ColumnMap) -> Result<Self> {
        let file = File::open(path).map_err(|cause| LogError::Io {
            path: path.to_path_buf(),
            cause,
        })?;
        Self::from_reader(BufReader::with_capacity(1 << 16, file), path, map)
    }
}

fn header_list(h: &[String]) -> String {
    let mut s = h.iter().take(40).cloned().collect::<Vec<_>>().join(",");
    if h.len() > 40 {
        s.push_str(",...");
    }
    s
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
            .from_reader(reader);
        let header = reader
            .byte_headers()
            .map_err(|e| csv_error(path, &e))?
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

    fn field(&self, col: Col, name: &str) -> Result<Option<f64>> {
        let raw = self.record.get(col.index).unwrap_or(b"");
        let text = trim(raw);
        if text.is_empty() {
            return Ok(None);
        }
        let s = std::str::from_utf8(text).map_err(|_| LogError::ParseValue {
            path: self.path.clone(),
            row: self.row,
            column: name.to_string(),
            text: String::from_utf8_lossy(text).into_owned(),
        })?;
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
                Err(LogError::ParseValue {
                    path: self.path.clone(),
                    row: self.row,
                    column: name.to_string(),
                    text: s.to_string(),
                })
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

    fn check_range(
        &self,
        channel: &'static str,
        value: f64,
        lo: f64,
        hi: f64,
        unit: &'static str,
        expected: &'static str,
    ) -> Result<()> {
        if value < lo || value > hi {
            return Err(self.implausible(channel, value, unit, expected));
        }
        Ok(())
    }

    fn frame_vec(&self, v: [f64; 3], frame: Frame) -> [f64; 3] {
        match frame {
            Frame::Enu => v,
            Frame::Ned => ned_to_enu(v),
        }
    }

    fn parse_row(&mut self) -> Result<Sample> {
        let m = std::sync::Arc::clone(&self.map);
        let t_abs = self
            .field(m.time, &m.time_name)?
            .ok_or_else(|| LogError::ParseValue {
                path: self.path.clone(),
                row: self.row,
                column: m.time_name.clone(),
                text: String::from_utf8_lossy(self.record.get(m.time.index).unwrap_or(b""))
                    .into_owned(),
            })?;
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
        self.prev_abs_s = Some(t_abs);
        let start = *self.start_abs_s.get_or_insert(t_abs);
        let mut s = Sample {
            time_s: t_abs - start,
            ..Sample::default()
        };
        if let Some(c) = m.voltage {
            s.voltage_v = self.field(c, self.name_of(c))?;
            if let Some(v) = s.voltage_v {
                self.check_range("voltage", v, 0.0, 1000.0, "V", "0 to 1000 V")?;
            }
        }
        if let Some(c) = m.current {
            s.current_a = self.field(c, self.name_of(c))?;
            if let Some(v) = s.current_a {
                self.check_range("current", v, -500.0, 2000.0, "A", "-500 to 2000 A")?;
            }
        }
        if let Some(c) = m.power {
            s.power_w = self.field(c, self.name_of(c))?;
            if let (Some(p), Some(v), Some(i)) = (s.power_w, s.voltage_v, s.current_a) {
                // A logged power within 20 % (+5 W for noise at idle) of V x I. On the first row
                // that has all three, a mismatch is a wrong unit or scale (e.g. KAIST's 10 x V x I
                // without scale = 0.1) and an error; later, an isolated mismatch is a sensor
                // glitch (the KAIST logs have 10 rows with a 16-bit overflowed power): the power
                // value is dropped and reported.
                if (p - v * i).abs() > 0.2 * (v * i).abs() + 5.0 {
                    if !self.power_checked {
                        return Err(self.implausible(
                            "power",
                            p,
                            "W",
                            "within 20 % of voltage x current",
                        ));
                    }
                    self.dropped_count += 1;
                    if self.dropped.len() < TimeChecker::MAX_EVENTS {
                        self.dropped.push(DroppedValue {
                            row: self.row,
                            channel: "power",
                            value: p,
                        });
                    }
                    s.power_w = None;
                }
                self.power_checked = true;
            }
        }
        if let Some(c) = m.charge {
            s.charge_ah = self.field(c, self.name_of(c))?;
            if let Some(v) = s.charge_ah {
                self.check_range("charge", v, -1000.0, 10_000.0, "Ah", "-1000 to 10000 Ah")?;
            }
        }
        if let Some((cols, kind)) = m.position {
            if let Some(p) = self.vec3(&cols)? {
                match kind {
                    PosKind::Local(frame) => {
                        let p = self.frame_vec(p, frame);
                        let r = p.iter().fold(0.0f64, |a, x| a.max(x.abs()));
                        self.check_range("position", r, 0.0, 1e6, "m", "within 1000 km")?;
                        s.pos_enu_m = Some(p);
                    }
                    PosKind::Geodetic { angle } => {
                        let (lat, lon, alt) = (p[0] * angle, p[1] * angle, p[2]);
                        self.check_range(
                            "latitude",
                            lat,
                            -std::f64::consts::FRAC_PI_2,
                            std::f64::consts::FRAC_PI_2,
                            "rad",
                            "-pi/2 to pi/2 rad",
                        )?;
                        self.check_range(
                            "longitude",
                            lon,
                            -2.0 * std::f64::consts::PI,
                            2.0 * std::f64::consts::PI,
                            "rad",
                            "-2 pi to 2 pi rad",
                        )?;
                        let o = *self.origin.get_or_insert(GeoOrigin {
                            lat_rad: lat,
                            lon_rad: lon,
                            alt_m: alt,
                        });
                        s.pos_enu_m = Some(geodetic_to_enu(&o, lat, lon, alt));
                    }
                }
            }
        }
        if let Some((cols, frame)) = m.velocity {
            if let Some(v) = self.vec3(&cols)? {
                let v = self.frame_vec(v, frame);
                self.check_range("velocity", norm(v), 0.0, 150.0, "m/s", "below 150 m/s")?;
                s.vel_enu_mps = Some(v);
            }
        }
        if let Some((cols, frame)) = m.acceleration {
            if let Some(v) = self.vec3(&cols)? {
                let v = self.frame_vec(v, frame);
                self.check_range(
                    "acceleration",
                    norm(v),
                    0.0,
                    500.0,
                    "m/s^2",
                    "below 500 m/s^2",
                )?;
                s.acc_enu_mps2 = Some(v);
            }
        }
        if let Some((cols, frame)) = m.wind {
            if let Some(v) = self.vec3(&cols)? {
                let v = self.frame_vec(v, frame);
                self.check_range("wind", norm(v), 0.0, 100.0, "m/s", "below 100 m/s")?;
                s.wind_enu_mps = Some(v);
            }
        }
        if let Some((cols, kind)) = &m.attitude {
            match kind {
                AttKind::Euler => {
                    let c3 = [cols[0], cols[1], cols[2]];
                    if let Some(a) = self.vec3(&c3)? {
                        let pi = std::f64::consts::PI;
                        // 1e-6 rad of slack for angles logged at exactly +-pi.
                        for (ch, v, lim) in [
                            ("roll", a[0], pi),
                            ("pitch", a[1], pi / 2.0),
                            ("yaw", a[2], 2.0 * pi),
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
                        s.attitude = Some(Attitude {
                            roll_rad: a[0],
                            pitch_rad: a[1],
                            yaw_rad: wrap_pi(a[2]),
                        });
                    }
                }
                AttKind::Quat(frame) => {
                    let mut q = [0.0; 4];
                    let mut ok = true;
                    for (o, c) in q.iter_mut().zip(cols.iter()) {
                        match self.field(*c, self.name_of(*c))? {
                            Some(v) => *o = v,
                            None => ok = false,
                        }
                    }
                    if ok {
                        let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
                        // Logged unit quaternions are normalised to float precision; 10 % slack.
                        self.check_range("quaternion norm", n, 0.9, 1.1, "", "close to 1")?;
                        s.attitude = match frame {
                            Frame::Ned => attitude_from_ned_frd_quat(q),
                            Frame::Enu => attitude_from_enu_flu_quat(q),
                        };
                    }
                }
            }
        }
        Ok(s)
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

fn csv_error(path: &Path, e: &csv::Error) -> LogError {
    let row = e.position().map_or(0, |p| p.line());
    match e.kind() {
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

fn compile(map: &ColumnMap, columns: &[String], path: &Path) -> Result<Compiled> {
    let mut names = Vec::new();
    let mut find = |name: &str, channel: &'static str, factor: f64| -> Result<Col> {
        match columns.iter().position(|c| c == name) {
            Some(index) => {
                names.push(name.to_string());
                Ok(Col { index, factor })
            }
            None => Err(LogError::ColumnMissing {
                path: path.to_path_buf(),
                column: name.to_string(),
                channel,
                header: header_list(columns),
            }),
        }
    };
    let time = find(&map.time.column, "time", map.time.unit.factor())?;
    let mut scalar = |c: &Option<crate::column_map::ScalarColumn>, ch: &'static str| {
        c.as_ref()
            .map(|c| find(&c.column, ch, ColumnMap::scalar_factor(c)))
            .transpose()
    };
    let voltage = scalar(&map.voltage, "voltage")?;
    let current = scalar(&map.current, "current")?;
    let power = scalar(&map.power, "power")?;
    let charge = scalar(&map.charge, "charge")?;
    let mut vector =
        |v: &Option<VectorColumns>, ch: &'static str| -> Result<Option<([Col; 3], Frame)>> {
            match v {
                None => Ok(None),
                Some(v) => {
                    let f = v.unit.factor();
                    Ok(Some((
                        [
                            find(&v.columns[0], ch, f)?,
                            find(&v.columns[1], ch, f)?,
                            find(&v.columns[2], ch, f)?,
                        ],
                        v.frame,
                    )))
                }
            }
        };
    let velocity = vector(&map.velocity, "velocity")?;
    let acceleration = vector(&map.acceleration, "acceleration")?;
    let wind = vector(&map.wind, "wind")?;
    let position = match &map.position {
        None => None,
        Some(PositionColumns::Local {
            columns: c,
            frame,
            unit,
        }) => {
            let f = unit.factor();
            Some((
                [
                    find(&c[0], "position", f)?,
                    find(&c[1], "position", f)?,
                    find(&c[2], "position", f)?,
                ],
                PosKind::Local(*frame),
            ))
        }
        Some(PositionColumns::Geodetic {
            columns: c,
            angle_unit,
            unit,
        }) => Some((
            [
                find(&c[0], "latitude", 1.0)?,
                find(&c[1], "longitude", 1.0)?,
                find(&c[2], "altitude", unit.factor())?,
            ],
            PosKind::Geodetic {
                angle: angle_unit.factor(),
            },
        )),
    };
    let attitude = match &map.attitude {
        None => None,
        Some(AttitudeColumns::Euler { columns: c, unit }) => {
            let f = unit.factor();
            Some((
                vec![
                    find(&c[0], "roll", f)?,
                    find(&c[1], "pitch", f)?,
                    find(&c[2], "yaw", f)?,
                ],
                AttKind::Euler,
            ))
        }
        Some(AttitudeColumns::Quaternion { columns: c, frame }) => Some((
            c.iter()
                .map(|n| find(n, "attitude", 1.0))
                .collect::<Result<Vec<_>>>()?,
            AttKind::Quat(*frame),
        )),
    };
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
        names,
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
                Some(Err(csv_error(&self.path, &e)))
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
        assert!(
            matches!(
                e,
                LogError::Implausible {
                    channel: "time",
                    ..
                }
            ),
            "{e}"
        );
        // KAIST power without the 0.1 scale.
        let mut k = ColumnMap::kaist();
        k.power.as_mut().unwrap().scale = 1.0;
        let text = format!(
            "{KAIST_HEADER}1000000,0.634769,2.223,89.0,0.1,-0.2,0.5,1.0,2.0,-0.5,0,0,0,0,0,0,12150,48.0,25.0,12000\n"
        );
        let e = read(&text, &k).unwrap_err();
        assert!(
            matches!(
                e,
                LogError::Implausible {
                    channel: "power",
                    ..
                }
            ),
            "{e}"
        );
        // Degrees declared as radians.
        let mut m = ColumnMap::new("m", "t", crate::column_map::TimeUnit::S);
        m.attitude = Some(AttitudeColumns::Euler {
            columns: ["r".into(), "p".into(), "y".into()],
            unit: crate::column_map::AngleUnit::Rad,
        });
        let e = read("t,r,p,y\n0,10,5,90\n", &m).unwrap_err();
        assert!(
            matches!(
                e,
                LogError::Implausible {
                    channel: "roll",
                    ..
                }
            ),
            "{e}"
        );
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
    fn wrap_pi_range() {
        // Results of one rem_euclid: 1e-12.
        assert!((wrap_pi(3.0 * std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-12);
        assert!((wrap_pi(-0.5) + 0.5).abs() < 1e-12);
    }
}
