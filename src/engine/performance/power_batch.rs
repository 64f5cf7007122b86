//! Streaming batch evaluation of the power model over CSV: one row in, one row out, so memory
//! does not grow with the file (a 10-million-row file streams in constant memory).
//!
//! Input columns: `airspeed_mps`, `roll_deg`, `pitch_deg` (required), `climb_rate_mps` and
//! `air_direction_deg` (optional; a non-empty direction selects the geometric angle of attack for
//! that row). Other columns are passed through. Output: the input columns followed by
//! [`POWER_KEYS`].

use std::fmt::Write as _;
use std::io::{Read, Write};

use aloft_power::{AoaInput, FlightState, PowerBreakdown, PowerModel};

use crate::engine::basics::files::check_csv_header;
use crate::engine::basics::finite::first_non_finite;
use crate::error::Error;

/// The result columns, in order (the same keys as `aloft power --format json`).
pub const POWER_KEYS: [&str; 10] = [
    "thrust_n",
    "induced_velocity_mps",
    "hover_induced_velocity_mps",
    "induced_w",
    "parasitic_w",
    "profile_w",
    "acceleration_w",
    "climb_w",
    "aero_w",
    "electrical_w",
];

/// The values of a result in [`POWER_KEYS`] order.
pub fn power_values(p: &PowerBreakdown) -> [f64; 10] {
    [
        p.thrust_n,
        p.induced_velocity_mps,
        p.hover_induced_velocity_mps,
        p.induced_w,
        p.parasitic_w,
        p.profile_w,
        p.acceleration_w,
        p.climb_w,
        p.aero_w,
        p.electrical_w,
    ]
}

fn csv_error(origin: &str, row: usize, e: csv::Error) -> Error {
    if let csv::ErrorKind::Io(io) = e.kind() {
        if io.kind() == std::io::ErrorKind::BrokenPipe {
            return Error::Io {
                origin: origin.to_string(),
                source: std::io::Error::from(std::io::ErrorKind::BrokenPipe),
            };
        }
    }
    Error::Csv {
        origin: origin.to_string(),
        row,
        message: e.to_string(),
    }
}

/// Stream `input` (CSV) through `model` into `output` (CSV); returns the number of data rows.
///
/// `origin` names the input in errors. Stops at the first bad row with an error naming the row
/// (1-based, not counting the header), the column and the value.
pub fn power_csv<R: Read, W: Write>(
    model: &PowerModel,
    input: R,
    output: W,
    origin: &str,
) -> Result<u64, Error> {
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(input);
    let headers = reader
        .headers()
        .map_err(|e| csv_error(origin, 0, e))?
        .clone();
    check_csv_header(&headers, origin)?;
    let columns = Columns::find(&headers, origin)?;
    let mut writer = csv::Writer::from_writer(output);
    let mut header: Vec<&str> = headers.iter().collect();
    header.extend(POWER_KEYS);
    writer
        .write_record(&header)
        .map_err(|e| csv_error(origin, 0, e))?;

    let mut record = csv::StringRecord::new();
    let mut text = String::with_capacity(32);
    let mut row = 0usize;
    loop {
        match reader.read_record(&mut record) {
            Ok(true) => {}
            Ok(false) => break,
            Err(e) => return Err(csv_error(origin, row + 1, e)),
        }
        row += 1;
        let state = columns.state(&record, origin, row)?;
        let p = model.evaluate(&state).map_err(|e| Error::BadRow {
            origin: origin.to_string(),
            row,
            source: e,
        })?;
        if let Some((field, value)) = first_non_finite(&p) {
            return Err(Error::NonFinite {
                answer: "power",
                field,
                value,
                request: format!("{origin}: row {row}"),
            });
        }
        write_row(&mut writer, &record, &p, &mut text).map_err(|e| csv_error(origin, row, e))?;
    }
    writer.flush().map_err(|e| Error::Io {
        origin: origin.to_string(),
        source: e,
    })?;
    Ok(row as u64)
}

/// Where the state's fields are in the input.
struct Columns {
    airspeed: usize,
    roll: usize,
    pitch: usize,
    climb: Option<usize>,
    direction: Option<usize>,
}

impl Columns {
    /// The required and optional columns of a header.
    fn find(headers: &csv::StringRecord, origin: &str) -> Result<Self, Error> {
        let column = |name: &str| headers.iter().position(|h| h == name);
        let required = |name: &'static str| {
            column(name).ok_or_else(|| Error::ColumnMissing {
                column: name,
                origin: origin.to_string(),
                columns: headers.len(),
            })
        };
        Ok(Self {
            airspeed: required("airspeed_mps")?,
            roll: required("roll_deg")?,
            pitch: required("pitch_deg")?,
            climb: column("climb_rate_mps"),
            direction: column("air_direction_deg"),
        })
    }

    /// The flight state of one row (a non-empty direction selects the geometric angle of attack).
    fn state(
        &self,
        record: &csv::StringRecord,
        origin: &str,
        row: usize,
    ) -> Result<FlightState, Error> {
        let field = |idx: usize, name: &'static str| -> Result<f64, Error> {
            let raw = record.get(idx).unwrap_or("");
            raw.parse::<f64>().map_err(|_| Error::BadValue {
                origin: origin.to_string(),
                row,
                column: name,
                value: raw.to_string(),
            })
        };
        let optional = |idx: Option<usize>, name: &'static str| -> Result<Option<f64>, Error> {
            match idx {
                Some(i) if !record.get(i).unwrap_or("").is_empty() => field(i, name).map(Some),
                _ => Ok(None),
            }
        };
        let airspeed = field(self.airspeed, "airspeed_mps")?;
        let roll = field(self.roll, "roll_deg")?;
        let pitch = field(self.pitch, "pitch_deg")?;
        let climb = optional(self.climb, "climb_rate_mps")?.unwrap_or(0.0);
        let aoa = match optional(self.direction, "air_direction_deg")? {
            Some(d) => AoaInput::Geometric {
                air_direction_rad: d.to_radians(),
            },
            None => AoaInput::Paper,
        };
        Ok(FlightState {
            airspeed_mps: airspeed,
            roll_rad: roll.to_radians(),
            pitch_rad: pitch.to_radians(),
            climb_rate_mps: climb,
            aoa,
        })
    }
}

/// The input row followed by the result's values (shortest round-trip formatting).
fn write_row<W: Write>(
    writer: &mut csv::Writer<W>,
    record: &csv::StringRecord,
    p: &PowerBreakdown,
    text: &mut String,
) -> Result<(), csv::Error> {
    for f in record.iter() {
        writer.write_field(f)?;
    }
    for v in power_values(p) {
        text.clear();
        write!(text, "{v}").expect("writing to a String cannot fail");
        writer.write_field(&*text)?;
    }
    writer.write_record(None::<&[u8]>)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vehicle::VehicleFile;

    fn model() -> PowerModel {
        PowerModel::new(
            VehicleFile::builtin("dji-m100")
                .unwrap()
                .power_vehicle()
                .unwrap(),
        )
    }

    #[test]
    fn rows_pass_through_with_results_appended() {
        let input = "airspeed_mps,roll_deg,pitch_deg,note\n0,0,0,hover\n6,0,-8,cruise\n";
        let mut out = Vec::new();
        let n = power_csv(&model(), input.as_bytes(), &mut out, "test").unwrap();
        assert_eq!(n, 2);
        let text = String::from_utf8(out).unwrap();
        let mut lines = text.lines();
        assert!(lines.next().unwrap().ends_with("note,thrust_n,induced_velocity_mps,hover_induced_velocity_mps,induced_w,parasitic_w,profile_w,acceleration_w,climb_w,aero_w,electrical_w"));
        let hover: Vec<&str> = lines.next().unwrap().split(',').collect();
        assert_eq!(hover[3], "hover");
        let single = model()
            .evaluate(&FlightState::new(0.0, 0.0, 0.0, 0.0))
            .unwrap();
        let electrical: f64 = hover[13].parse().unwrap();
        // Shortest round-trip formatting: the value survives CSV exactly.
        assert_eq!(electrical.to_bits(), single.electrical_w.to_bits());
    }

    #[test]
    fn the_columns_are_the_json_keys_in_order() {
        // Regression: acceleration_w was added to PowerBreakdown (and its JSON) but not here.
        let p = model()
            .evaluate(&FlightState::new(6.0, 0.0, -0.1, 0.5))
            .unwrap();
        let json = serde_json::to_value(p).unwrap();
        let keys: Vec<&str> = json
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .collect();
        let mut sorted = POWER_KEYS.to_vec();
        sorted.sort_unstable();
        let mut json_sorted = keys.clone();
        json_sorted.sort_unstable();
        assert_eq!(sorted, json_sorted);
        for (k, v) in POWER_KEYS.iter().zip(power_values(&p)) {
            assert_eq!(json[k].as_f64().unwrap().to_bits(), v.to_bits(), "{k}");
        }
    }

    #[test]
    fn errors_name_row_column_and_value() {
        let cases = [
            ("roll_deg,pitch_deg\n1,2\n", "airspeed_mps"),
            ("airspeed_mps,roll_deg,pitch_deg\n1,2,3\n4,x,6\n", "row 2"),
            (
                "airspeed_mps,roll_deg,pitch_deg\n-1,0,0\n",
                "airspeed_mps must not be negative",
            ),
            ("airspeed_mps,roll_deg,pitch_deg\n1,95,0\n", "tilt"),
            ("airspeed_mps,roll_deg,pitch_deg\n1,0\n", "row 1"),
        ];
        for (input, needle) in cases {
            let e = power_csv(&model(), input.as_bytes(), Vec::new(), "states.csv").unwrap_err();
            let msg = e.to_string();
            assert!(
                msg.contains(needle) && msg.contains("states.csv"),
                "{msg} should contain {needle}"
            );
        }
    }
}
