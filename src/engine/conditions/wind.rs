//! The wind as a request gives it: a steady `[wind]` table, a gridded field read from a file,
//! and the words that describe them. Which of them a mission flies in is decided by
//! [`crate::engine::missions::day`]. The endurance queries take a steady wind only.

use std::path::Path;

use aloft_planner::{Wind, WindGrid, WindProfileKind, WindSpec};

use crate::engine::basics::files::{check_csv_header, read_text_file};
use crate::error::Error;

/// A `[wind]` table in words: `6.0 m/s from 250 deg at 10 m, power law exponent 0.143`, with
/// its gusts when it has them.
pub fn describe_wind_spec(w: &WindSpec) -> String {
    let profile = match w.profile {
        WindProfileKind::Uniform => String::new(),
        WindProfileKind::PowerLaw => format!(
            " at {:.0} m, power law exponent {:.3}",
            w.reference_height_m.unwrap_or(10.0),
            w.exponent.unwrap_or(1.0 / 7.0)
        ),
        WindProfileKind::Log => format!(
            " at {:.0} m, log profile z0 {} m",
            w.reference_height_m.unwrap_or(10.0),
            w.roughness_m.unwrap_or(0.03)
        ),
    };
    let gusts = match w.gust_std_mps {
        Some(g) => format!(", gusts {g:.1} m/s std"),
        None => String::new(),
    };
    format!(
        "{:.1} m/s from {:.0} deg{profile}{gusts}",
        w.speed_mps, w.from_deg
    )
}

/// A steady wind from a `[wind]` table given in options.
///
/// # Errors
/// [`Error::Wind`] for a speed, direction or profile the planner rejects.
pub(crate) fn steady(w: &WindSpec) -> Result<Wind, Error> {
    w.to_wind().map_err(|e| Error::Wind {
        origin: "wind options".to_string(),
        source: Box::new(e),
    })
}

/// Read the gridded wind field of a CSV file (columns `x_m,y_m,z_m,u_mps,v_mps,w_mps`), checked
/// whole: its description, as a mission flown in it names it.
///
/// # Errors
/// A file that cannot be read or is not a wind field, naming the file, row and column.
pub fn read_wind_field(path: &Path) -> Result<String, Error> {
    field(path).map(|(_, text)| text)
}

/// A gridded wind field from its CSV file, with its extent in words.
pub(crate) fn field(path: &Path) -> Result<(Wind, String), Error> {
    let grid = read_wind_grid(path)?;
    let (lo, hi) = grid.bounds_m();
    Ok((
        Wind::grid(grid),
        format!(
            "gridded field {} (E {:.0}..{:.0} m, N {:.0}..{:.0} m, up {:.0}..{:.0} m)",
            path.display(),
            lo[0],
            hi[0],
            lo[1],
            hi[1],
            lo[2],
            hi[2]
        ),
    ))
}

/// The columns of a wind-field CSV, in the order the planner takes them.
const GRID_COLUMNS: [&str; 6] = ["x_m", "y_m", "z_m", "u_mps", "v_mps", "w_mps"];

/// Read a wind-field CSV (columns [`GRID_COLUMNS`], east-north-up) into the planner's grid.
fn read_wind_grid(path: &Path) -> Result<WindGrid, Error> {
    let origin = path.display().to_string();
    let csv_error = |row: usize, e: csv::Error| Error::Csv {
        origin: origin.clone(),
        row,
        message: e.to_string(),
    };
    let text = read_text_file(path, "wind field")?;
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let headers = reader.headers().map_err(|e| csv_error(0, e))?.clone();
    check_csv_header(&headers, &origin)?;
    let mut cols = [0usize; 6];
    for (c, name) in cols.iter_mut().zip(GRID_COLUMNS) {
        *c = headers
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| Error::ColumnMissing {
                column: name,
                origin: origin.clone(),
                columns: headers.len(),
            })?;
    }
    let mut rows = Vec::new();
    for (k, rec) in reader.records().enumerate() {
        let rec = rec.map_err(|e| csv_error(k + 1, e))?;
        let mut row = [0.0; 6];
        for (slot, (&c, name)) in row.iter_mut().zip(cols.iter().zip(GRID_COLUMNS)) {
            let raw = rec.get(c).unwrap_or("");
            *slot = raw.parse().map_err(|_| Error::BadValue {
                origin: origin.clone(),
                row: k + 1,
                column: name,
                value: raw.to_string(),
            })?;
        }
        rows.push(row);
    }
    WindGrid::from_rows(&rows).map_err(|e| Error::Wind {
        origin: format!("wind field {origin}"),
        source: Box::new(e),
    })
}
